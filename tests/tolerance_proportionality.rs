//! Tolerance proportionality: what `rtol` buys must not depend on the scheme or the constraint
//! method. For every adaptive scheme and every constraint method the documentation offers it,
//! on the closed loops (slider-crank in both forms, four-bar, Cash's pendulum, the Cartesian
//! double pendulum, the fast linkage `fastlink` against its reference from outside mbs), over rtol = 1e-4 … 1e-10 (atol = rtol/100): the mixed error over (q, qd)
//! (Test Set for IVP Solvers, floor 0.01, the largest over the sampled times) stays within 1.5
//! digits of rtol, and never loses more than 0.2 digits when rtol tightens by a decade.
//!
//! `cargo test --release --test tolerance_proportionality -- --nocapture` prints the digits of
//! every run (−log10 of the mixed error) against those of rtol.

use mbs::work_precision::{Reference, Setting, Study, Sweep, WorkPrecision, decades, mixed_error};
use mbs::{ConstraintMethod, GenAlphaParams, HhtParams, Model, Options, Scheme};
use mbs_models::{dpend, dpend_cartesian, fastlink, fourbar, pendulum3, slidercrank};

mod common;

/// Digits of rtol the mixed error may differ by.
const WITHIN: f64 = 1.5;
/// Digits a run may lose when rtol tightens by a decade.
const LOSS: f64 = 0.2;

fn gen_alpha() -> Scheme {
    Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8))
}

fn hht() -> Scheme {
    Scheme::Hht(HhtParams::default())
}

/// Every adaptive scheme with every constraint method it is documented to take; the ones it
/// refuses (`ConstraintsUnsupported`) are skipped and named in the output.
fn sweeps(constrained: bool) -> Vec<Sweep> {
    let rtols = decades(4, 10);
    let schemes = [
        Scheme::Dopri5,
        Scheme::Bdf(Default::default()),
        Scheme::Radau3,
        Scheme::Radau5,
        gen_alpha(),
        hht(),
    ];
    let methods: &[ConstraintMethod] = if constrained {
        &[
            ConstraintMethod::Auto,
            ConstraintMethod::Projection,
            ConstraintMethod::Index3,
            ConstraintMethod::Index2,
            ConstraintMethod::Partitioning,
        ]
    } else {
        &[ConstraintMethod::Auto]
    };
    let mut out = Vec::new();
    let only = std::env::var("ONLY").ok();
    for scheme in schemes {
        if only.as_deref().is_some_and(|o| o != scheme.name()) {
            continue;
        }
        for &m in methods {
            let label = format!("{} {}", scheme.name(), m.name());
            out.push(
                Sweep::adaptive(scheme, &rtols)
                    .with_constraints(m)
                    .labelled(label),
            );
        }
    }
    out
}

fn samples(t_end: f64, n: usize) -> Vec<f64> {
    (1..=n).map(|k| t_end * k as f64 / n as f64).collect()
}

/// A reference computed by mbs at rtol 1e-13 (DOPRI5, projection when closed), checked by
/// RK4 at h = 2e-5 (whose error is below 1e-12 on these models).
fn computed<M: Model + Clone + 'static>(model: &M, times: Vec<f64>) -> Reference {
    let o = Options::default();
    Reference::compute(
        model,
        times,
        (Scheme::Dopri5, Setting::Rtol(1e-13)),
        Some((Scheme::Rk4, Setting::Step(2e-5))),
        &o,
    )
    .expect("reference run")
}

/// Prints the study's proportionality table; returns what breaks proportionality.
fn judge(wp: &WorkPrecision) -> Vec<String> {
    let offered = |label: &str| {
        !wp.rows.iter().any(|r| {
            r.label == label
                && matches!(&r.outcome, Err(f) if matches!(f.kind, mbs::Failure::ConstraintsUnsupported { .. }))
        })
    };
    let refused: Vec<&str> = wp
        .rows
        .iter()
        .map(|r| r.label.as_str())
        .filter(|l| !offered(l))
        .collect();
    let kept = WorkPrecision {
        rows: wp
            .rows
            .iter()
            .filter(|r| offered(&r.label))
            .cloned()
            .collect(),
        ..wp.clone()
    };
    println!("\n{}", kept.proportionality_table());
    let mut refused = refused;
    refused.dedup();
    println!("not offered: {}", refused.join(", "));
    let mut bad = Vec::new();
    for p in kept.proportionality() {
        let at = |r: f64| format!("{}: {} at rtol {r:e}", wp.title, p.label);
        for (r, d) in p.rtols.iter().zip(&p.digits) {
            if d.is_none() {
                bad.push(format!("{}: failed", at(*r)));
            }
        }
        for (r, off) in p.offsets() {
            if off.abs() > WITHIN {
                bad.push(format!("{}: {off:+.2} digits from rtol", at(r)));
            }
        }
        if p.largest_loss() > LOSS {
            bad.push(format!(
                "{}: {}: loses {:.2} digits as rtol tightens",
                wp.title,
                p.label,
                p.largest_loss()
            ));
        }
    }
    bad
}

fn study(title: &str, reference: Reference, constrained: bool) -> Study {
    Study {
        sweeps: sweeps(constrained),
        repeats: 1,
        ..Study::new(title, reference)
    }
}

/// Runs the study, prints its proportionality table and, at rtol 1e-8, the digits over q
/// alone and qd alone of every offered sweep (where the error sits); returns what breaks
/// proportionality.
fn measure<M: Model + Clone + 'static>(s: Study, model: &M) -> Vec<String> {
    let wp = s.run(model).expect("study");
    let bad = judge(&wp);
    let n = M::NQ;
    println!(
        "digits over q alone and qd alone at rtol 1e-8 (largest mixed error over the samples):"
    );
    for sweep in &s.sweeps {
        let o = s.options_for(sweep, Setting::Rtol(1e-8));
        let Ok((tr, _)) = mbs::simulate(model.clone(), sweep.scheme, o) else {
            continue;
        };
        let (mut eq, mut ev) = (0.0f64, 0.0f64);
        for (i, r) in s.reference.states.iter().enumerate() {
            eq = eq.max(mixed_error(tr.q(i), &r[..n], s.floor));
            ev = ev.max(mixed_error(tr.qd(i), &r[n..], s.floor));
        }
        println!(
            "  {:<28} q {:5.2}  qd {:5.2}",
            sweep.label,
            -eq.log10(),
            -ev.log10()
        );
    }
    bad
}

fn assert_proportional(bad: Vec<String>) {
    assert!(
        bad.is_empty(),
        "not tolerance-proportional:\n{}",
        bad.join("\n")
    );
}

/// Form (a) against form (b) mapped to (θ, ψ, s) and their rates; form (b) (no constraint)
/// against itself at rtol 1e-13.
#[test]
fn slider_crank_both_forms() {
    let closed = slidercrank::SliderCrankClosed::default();
    let times = samples(2.0, 20);
    let rb = computed(&closed, times.clone());
    let mut bad = measure(study("slider-crank (b)", rb, false), &closed);
    let ra = computed(&closed, times).map("form (b) mapped to form (a)", |_, y| {
        let (r, l) = (0.1, 0.3);
        let (th, thd) = (y[0], y[1]);
        let (psi, s) = slidercrank::closed_loop(th);
        let psid = -r * th.cos() * thd / (l * psi.cos());
        let sd = -r * th.sin() * thd - l * psi.sin() * psid;
        vec![th, psi, s, thd, psid, sd]
    });
    let model = slidercrank::SliderCrank::default();
    bad.extend(measure(study("slider-crank (a)", ra, true), &model));
    assert_proportional(bad);
}

#[test]
fn four_bar() {
    let model = fourbar::FourBar::default();
    let r = computed(&model, samples(2.0, 20));
    assert_proportional(measure(study("four-bar", r, true), &model));
}

#[test]
fn cash_pendulum() {
    let model = pendulum3::Pendulum3::default();
    let r = computed(&model, samples(1.0, 10));
    assert_proportional(measure(study("pendulum3", r, true), &model));
}

/// The Cartesian double pendulum against dpend (two relative angles, no constraint) at rtol
/// 1e-13, mapped to the bars' centres and absolute angles.
#[test]
fn cartesian_double_pendulum() {
    let times = samples(1.0, 10);
    let r = computed(&dpend::DoublePendulum::default(), times).map(
        "dpend (relative angles) mapped to Cartesian coordinates",
        |_, y| {
            let (a, b, ad, bd) = (y[0], y[0] + y[1], y[2], y[2] + y[3]);
            let (x1, y1) = (0.5 * a.sin(), -0.5 * a.cos());
            let (x2, y2) = (a.sin() + 0.5 * b.sin(), -a.cos() - 0.5 * b.cos());
            let (x1d, y1d) = (0.5 * a.cos() * ad, 0.5 * a.sin() * ad);
            let (x2d, y2d) = (
                a.cos() * ad + 0.5 * b.cos() * bd,
                a.sin() * ad + 0.5 * b.sin() * bd,
            );
            vec![x1, y1, a, x2, y2, b, x1d, y1d, ad, x2d, y2d, bd]
        },
    );
    let model = dpend_cartesian::DoublePendulumCartesian::default();
    assert_proportional(measure(study("dpend (Cartesian)", r, true), &model));
}

/// fastlink to 30 ms against `tests/reference/fastlink.json` (SymPy in absolute coordinates,
/// SciPy DOP853 at 1e-13), every millisecond.
#[test]
fn fast_linkage() {
    let times: Vec<f64> = (1..=30).map(|k| 1e-3 * k as f64).collect();
    let states = times
        .iter()
        .map(|&t| {
            let (q, qd) = common::reference_state("fastlink", t);
            q.into_iter().chain(qd).collect()
        })
        .collect();
    let r = Reference::data("tests/reference/fastlink.json", times, states);
    let model = fastlink::FastLink::default();
    assert_proportional(measure(study("fastlink", r, true), &model));
}
