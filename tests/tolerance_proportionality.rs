//! Tolerance proportionality: what `rtol` buys, for every adaptive scheme and every constraint
//! method the documentation offers it, on the closed loops (slider-crank in both forms,
//! four-bar, Cash's pendulum, the Cartesian double pendulum, the fast linkage `fastlink`
//! against its reference from outside mbs), over rtol = 1e-4 … 1e-10 (atol = rtol/100). The
//! measure is the largest mixed error over (q, qd) at the sampled times (Test Set for IVP
//! Solvers, floor 0.01); digits = −log10 of it.
//!
//! Asserted for every scheme and constraint method offered, each over the range where its
//! tolerance is mapped so that the error follows rtol (DOPRI5 and BDF with projection or
//! partitioning, Radau5 and Radau3 with projection, partitioning or at index 2, Radau5 and
//! Radau3 at index 3 from rtol 1e-4 to 1e-8, the Newmark family in
//! every form from rtol 1e-4 to 1e-8 but gen-α with projection to 1e-7 — below these their
//! local tolerance reaches its floor; DOPRI5 from 1e-6):
//!
//! - every run reaches t_end;
//! - no run loses more than 0.2 digits when rtol tightens by a decade;
//! - no more than a digit below the median of the asserted sweeps at the same rtol, or
//!   below rtol's digits when the median is above them (RKC's sweeps, up to 0.5 digits above
//!   rtol on Cash's pendulum, raise the median there), on every model: a user who trusts rtol
//!   is not misled by the choice of scheme or method by more than that. (Above it is not an
//!   error: BDF with partitioning gets 6.1 digits on fastlink at rtol 1e-7, where the median
//!   is 4.9.) Five sweeps are held to 1.5 digits, as measured: DOPRI5 with partitioning on
//!   fastlink (1.01–1.26 digits below the median from rtol 1e-6 to 1e-8; with projection it is
//!   within 0.3 of it), on the four-bar and on the Cartesian double pendulum (up to 0.92 and
//!   1.04 below from rtol 1e-6 to 1e-8, where Radau5's runs at index 3, asserted since their
//!   tolerance was mapped, lift the median; within a digit before; on the four-bar up to 1.27
//!   until Radau3's runs at index 3 were asserted to 1e-8 too); neither its error
//!   estimate's dependent part mapped through the completion, −B_d⁻¹B_i e_i, nor
//!   interpolated samples completed brought it closer: the first made it
//!   0.1–0.4 digits worse, the second changed nothing; at rtol 1e-7, atol 1e-9 it takes 438
//!   steps where projection takes 456, and ends 12 times further from the reference in every
//!   coordinate alike, where BDF with partitioning ends 29 times closer than with projection),
//!   Radau5 on slider-crank (b) at rtol 1e-7 (5.93 digits against the median's 6.93: its
//!   digits stall from 1e-6 to 1e-7) and BDF with projection on Cash's pendulum at rtol 1e-10
//!   (8.98 digits, 1.02 short of rtol's 10).
//!
//! Not asserted, because not true: within 1.5 digits of rtol itself. On the Cartesian double
//! pendulum, Cash's pendulum and slider-crank (b) the asserted runs land from 1.8 digits better
//! to 1.7 short, on the four-bar, slider-crank (a) and fastlink from 0.2 better to 3.4 short
//! (per-sweep averages 0.4–3.2 short): these motions amplify local errors, which no local
//! error test sees.
//!
//! Radau3 at index 3 (rtol' = 3·rtol^1.5, floor 10⁵ε, reached from rtol ≈ 3.8e-8) is
//! asserted to rtol 1e-8 (where it holds the floor; a floor of 10⁴ε lost 0.63 digits from
//! 1e-7 to 1e-8 on the four-bar, its λ's rounding growing as ε/h²); below, its digits stay at
//! 5.2–7.3. Under a floor of 2e-9 it was
//! asserted to 1e-6 (fastlink lost 0.26 digits from 1e-6 to 1e-7): without that floor it had
//! failed on fastlink from rtol 1e-7 on, until Newton weighed the stage positions no finer than
//! their rounding. Unmapped (0.1·rtol, the positions alone bounded) it fell 1.6–2.6
//! digits short of rtol on average, 4.71 digits at rtol 1e-6 on Cash's pendulum against the
//! median's 6.14.
//!
//! Global error control (`mbs::simulate_global`) is what makes rtol a bound on these errors:
//! every sweep runs again under it at rtol 1e-4, 1e-6 and 1e-8 (the schemes of order 2 and 3
//! to 1e-6), and it is asserted that
//! no run it returns is more than 0.2 digits short of rtol (half a digit while a checking run
//! below a scheme's floor counted as one ten times tighter: 0.26 short at worst), that every run it does not return ends in the typed
//! `GlobalToleranceNotMet`, and that DOPRI5 and Radau5 with their default constraint method
//! return a run at each of these tolerances on every model (BDF does too at 1e-4 and 1e-6;
//! at 1e-8 the local rtol it needs lies near the edge of its floor of 100ε, 7.5e-11, below
//! which no run can check it).
//!
//! `cargo test --release --test tolerance_proportionality -- --nocapture` prints the tables,
//! the digits of q and qd apart at rtol 1e-8, and the global-control runs.

use mbs::work_precision::{
    Proportionality, Reference, Row, Setting, Study, Sweep, WorkPrecision, decades, mixed_error,
};
use mbs::{ConstraintMethod, GenAlphaParams, HhtParams, Model, Options, Scheme};
use mbs_models::{dpend, dpend_cartesian, fastlink, fourbar, pendulum3, slidercrank};

mod common;
#[path = "common/quoted.rs"]
mod quoted;

/// Digits a sweep may fall below the median of the others at the same rtol.
const WITHIN: f64 = 1.0;
/// The sweeps held to 1.5 digits instead, (model, sweep), as measured (see the module notes).
const EXCEPTIONS: [(&str, &str); 6] = [
    ("fastlink", "dopri5 partitioning"),
    ("four-bar", "dopri5 partitioning"),
    ("dpend (Cartesian)", "dopri5 partitioning"),
    ("slider-crank (b)", "radau5 auto"),
    ("pendulum3", "bdf auto"),
    ("pendulum3", "bdf projection"),
];

/// The digits the sweep `label` may fall below the median on the model `title`.
fn within(title: &str, label: &str) -> f64 {
    if EXCEPTIONS.contains(&(title, label)) {
        1.5
    } else {
        WITHIN
    }
}
/// Digits a run may lose when rtol tightens by a decade.
const LOSS: f64 = 0.2;

/// The loosest and tightest rtol at which a sweep is asserted. DOPRI5 from 1e-6: at 1e-4 and
/// 1e-5 it falls 1.1–2.1 digits below the median of the others on three loops (the four-bar
/// at 1e-4, 0.43 digits against 2.51: it loses the phase of the fast crank turns; the
/// Cartesian double pendulum at 1e-4 and 1e-5, 1.06–1.28 below; slider-crank (b) at 1e-5,
/// 3.20 against 5.20). Measured, not kept: a
/// map of DOPRI5's loose tolerances alone, rtol' = 1e-6·(rtol/1e-6)^e above 1e-6. At e = 0.5
/// it brought rtol 1e-4 within a digit of the median on every loop, slider-crank (b) by 0.05
/// digits only (measured again on a later build, whose other schemes' median had moved, it
/// failed there: 2.86 digits against the median's 3.96 at rtol 1e-4, 3.75 against 4.95 at
/// 1e-5), and global control, which estimates the error by a run at rtol/10, then
/// compares runs only 10^0.5 apart at the loose end: its runs at 1e-4 fell to 0.47 digits
/// short of rtol (fastlink, partitioning; 0.30 above before) and −0.06 on the Cartesian
/// double pendulum (+0.87 before). At e = 0.4 the four-bar and fastlink lose 0.43–0.85
/// digits from 1e-4 to 1e-5: DOPRI5's loose end is where it loses the phase of fast turns, a
/// threshold that no smooth map follows. Also measured, not kept: the projection's (or the
/// completion's) move of q and qd, in the error test's norm, rejecting a step above 1 (the
/// drift off the constraints is the part of the local error that the embedded estimate
/// misses at large steps). DOPRI5 with projection at rtol 1e-4 / 1e-5: four-bar 0.43 → 1.29
/// and 2.41 → 3.67 digits, fastlink 1.01 → 1.44 and 3.09 → 3.66, the Cartesian double
/// pendulum 2.20 → 2.45 at 1e-4, unchanged from 1e-6 on; with partitioning on the four-bar
/// 1.01 → 0.86 at 1e-4; short of the 2.5 digits that asserting rtol 1e-4 needs, and applied to
/// every scheme HHT with projection on fastlink failed at rtol 1e-7.
///
/// Where the gap comes from (a probe, not kept): each accepted step of the four-bar run again
/// from its start by DOPRI5 at rtol 1e-13 over the same step, its true local error in the
/// error test's norm, as a fraction of the tolerance. DOPRI5's median is 0.091, 0.028 and
/// 0.011 at rtol 1e-4, 1e-6 and 1e-8 (largest 2.14, 0.38, 0.063: at 1e-4 it makes the errors
/// its rtol allows, its estimate, the 4th-order companion's error, realistic at large
/// steps), where Radau5's stays at 0.001–0.003, BDF's at 0.001–0.002 and Radau3's at 0.001 or
/// less at every rtol: at 1e-4 DOPRI5's median is 45–90 times theirs, and the median it is
/// compared with is the caution of the implicit schemes' estimates. Maps that tighten
/// DOPRI5's loose end smoothly, rtol' = min(rtol, c·rtol^e) (builds not kept): from 1e-8 on
/// with e = 0.75 (a decade tighter at 1e-4, half a decade at the default 1e-6) slider-crank
/// (b) at 1e-4 gives 2.86 digits against the median's 3.96, and nine other tests' figures
/// moved (a run at rtol 0.2 no longer runs away, since rtol' stays below 0.01 for every
/// rtol < 1); with e = 0.7 slider-crank (b) gives 3.22, but fastlink loses 0.43 digits from
/// 1e-4 to 1e-5 (3.88, then 3.45); from 1e-10 on with e = ⅚ DOPRI5 lifts the median at tight
/// rtol, and HHT at index 3 on the four-bar falls 1.01 digits below it at 1e-7; c = 0.1 at
/// every rtol lifts it more, and BDF on slider-crank (a) falls 1.2 digits below it from 1e-8.
/// Nor is it the steps' length (a probe, not kept: DOPRI5 with `h_max` a fraction of the
/// span): on the four-bar at rtol 1e-4, 0.43 digits in 61 steps with no bound, 1.73 in 65
/// with h_max = span/50, 0.46 in 102 with span/100; on fastlink 1.01, 1.01 and 0.72; on the
/// Cartesian double pendulum a bound of span/100 gives 6.57 digits at every rtol from 1e-4
/// to 1e-6 (101 steps): the bound, not rtol, then sets the step.
fn claimed(label: &str) -> (f64, f64) {
    let (scheme, method) = label.split_once(' ').unwrap_or((label, ""));
    match (scheme, method) {
        ("gen-alpha", "projection") => (1e-4, 1e-7),
        ("gen-alpha" | "hht", _) => (1e-4, 1e-8),
        ("radau5", "index3") => (1e-4, 1e-8),
        ("radau3", "index3") => (1e-4, 1e-8),
        ("dopri5", _) => (1e-6, 1e-10),
        ("rkc", _) => (1e-4, 1e-8),
        _ => (1e-4, 1e-10),
    }
}

/// The README's table "What rtol means, at a glance" gives each scheme's asserted range as
/// `claimed` holds it, and says where index 3 or projection is left out (naming the scheme
/// in a row of two).
#[test]
fn the_readme_table_gives_the_asserted_ranges() {
    let rows: [(&str, &[(&str, &str)]); 6] = [
        ("DOPRI5", &[("dopri5", "DOPRI5")]),
        ("BDF", &[("bdf", "BDF")]),
        ("Radau5", &[("radau5", "Radau5")]),
        ("Radau3", &[("radau3", "Radau3")]),
        ("RKC", &[("rkc", "RKC")]),
        ("gen-α, HHT", &[("gen-alpha", "gen-α"), ("hht", "HHT")]),
    ];
    for (first, schemes) in rows {
        let range = claimed(&format!("{} index2", schemes[0].0));
        let mut but = String::new();
        for &(scheme, name) in schemes {
            assert_eq!(claimed(&format!("{scheme} index2")), range, "{first}");
            let solves_index3 = !matches!(scheme, "dopri5" | "bdf" | "rkc");
            for (method, words) in [("index3", "at index 3"), ("projection", "with projection")] {
                let (l, t) = claimed(&format!("{scheme} {method}"));
                if (l, t) == range || method == "index3" && !solves_index3 {
                    continue;
                }
                let who = if schemes.len() > 1 {
                    format!("{name} ")
                } else {
                    String::new()
                };
                but += &format!(", {who}{words} {l:e} … {t:e}");
            }
        }
        let (loose, tight) = range;
        let range = format!("| {loose:e} … {tight:e}{but} |");
        let row = quoted::row("README.md", first);
        assert!(
            row.ends_with(&range),
            "README's row `{row}` should end `{range}`"
        );
    }
}

/// Whether `rtol` lies in the asserted range of the sweep `label`.
fn asserted(label: &str, rtol: f64) -> bool {
    let (loose, tight) = claimed(label);
    rtol <= loose * 1.001 && rtol >= tight * 0.999
}

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
        Scheme::Rkc,
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
    for scheme in schemes {
        for &m in methods {
            let label = format!("{} {}", scheme.name(), m.name());
            // RKC, of order 2, to 1e-8 (at 1e-8 dpend takes it 204,000 steps)
            let rtols = if scheme == Scheme::Rkc {
                &rtols[..5]
            } else {
                &rtols[..]
            };
            out.push(
                Sweep::adaptive(scheme, rtols)
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

/// The median digits of the asserted sweeps of `props` at `r`: the yardstick between schemes.
fn median(props: &[Proportionality], r: f64) -> Option<f64> {
    let mut d: Vec<f64> = props
        .iter()
        .filter(|p| asserted(&p.label, r))
        .filter_map(|p| digits_at(p, r))
        .collect();
    d.sort_by(f64::total_cmp);
    d.get(d.len() / 2).copied()
}

/// Prints the study's proportionality table; returns what breaks proportionality, and the
/// proportionality of the sweeps judged (those offered, and on a model without constraints
/// not the Newmark family).
fn judge(wp: &WorkPrecision, constrained: bool) -> (Vec<String>, Vec<Proportionality>) {
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
    let props: Vec<_> = kept
        .proportionality()
        .into_iter()
        .filter(|p| constrained || !p.label.starts_with("gen-alpha") && !p.label.starts_with("hht"))
        .collect();
    let median = |r: f64| median(&props, r);
    for p in &props {
        let at = |r: f64| format!("{}: {} at rtol {r:e}", wp.title, p.label);
        let mut last: Option<f64> = None;
        for (&r, d) in p.rtols.iter().zip(&p.digits) {
            if !asserted(&p.label, r) {
                continue;
            }
            let Some(d) = *d else {
                bad.push(format!("{}: failed", at(r)));
                continue;
            };
            // below the median, and below rtol itself: a sweep that reaches rtol is not
            // made wrong by others that do better
            if let Some(m) = median(r)
                && d < m.min(-r.log10()) - within(&wp.title, &p.label)
            {
                bad.push(format!("{}: {d:.2} digits, the median {m:.2}", at(r)));
            }
            if let Some(prev) = last
                && d < prev - LOSS
            {
                bad.push(format!(
                    "{}: {d:.2} digits, {prev:.2} at the decade before",
                    at(r)
                ));
            }
            last = Some(d);
        }
    }
    (bad, props)
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
/// proportionality. The sweeps under local control and those under global control run on two
/// threads; an `auto` sweep whose run at the loosest rtol equals, to the bit in its work
/// counters and errors, that of the method it resolves to is that method's sweep again (the
/// choice is made once per run from the scheme, not from the motion) and takes its rows.
fn measure<M: Model + Clone + Sync + 'static>(s: Study, model: &M) -> Vec<String> {
    let twins = auto_twins(&s, model);
    let run = Study {
        sweeps: s
            .sweeps
            .iter()
            .filter(|w| twin_of(&twins, &w.label).is_none())
            .cloned()
            .collect(),
        ..s.clone()
    };
    let global = global_study(&run);
    let ((wp, split), global) = std::thread::scope(|scope| {
        let global = scope.spawn(|| global.run(model).expect("study"));
        let local = run.run(model).expect("study");
        let split = digits_apart(&run, model);
        (
            (local, split),
            global.join().expect("the global-control sweeps"),
        )
    });
    let wp = with_twins(wp, &s.sweeps, &twins, |w| w.clone());
    let global = with_twins(global, &s.sweeps, &twins, |w| w.clone().global());
    for (auto, of) in &twins {
        println!("{auto}: the runs of {of}, equal to the bit at the loosest rtol");
    }
    let (mut bad, props) = judge(&wp, M::NC > 0);
    let (global_bad, global) = judge_global(&global);
    bad.extend(global_bad);
    record(Measured {
        title: wp.title.clone(),
        props,
        global,
    });
    println!(
        "digits over q alone and qd alone at rtol 1e-8 (largest mixed error over the samples):"
    );
    for sweep in &s.sweeps {
        let label = twin_of(&twins, &sweep.label).unwrap_or(&sweep.label);
        if let Some((_, q, qd)) = split.iter().find(|(l, _, _)| l == label) {
            println!("  {:<28} q {q:5.2}  qd {qd:5.2}", sweep.label);
        }
    }
    bad
}

/// The `auto` sweeps of `s` that are another sweep of the same scheme again, (auto's label,
/// the other's): their runs at the loosest rtol have equal work counters and outcomes.
fn auto_twins<M: Model + Clone + 'static>(s: &Study, model: &M) -> Vec<(String, String)> {
    let auto = |w: &Sweep| w.constraints == Some(ConstraintMethod::Auto);
    // the sweeps of the schemes that have an `auto` sweep and another (none on a model
    // without constraints), at their loosest rtol
    let paired: Vec<Sweep> = s
        .sweeps
        .iter()
        .filter(|w| {
            s.sweeps
                .iter()
                .any(|o| o.scheme == w.scheme && auto(o) != auto(w))
        })
        .map(|w| Sweep {
            settings: w.settings[..1].to_vec(),
            ..w.clone()
        })
        .collect();
    if paired.is_empty() {
        return Vec::new();
    }
    let loosest = Study {
        sweeps: paired.clone(),
        ..s.clone()
    }
    .run(model)
    .expect("study");
    let same = |a: &Row, b: &Row| a.stats == b.stats && a.outcome == b.outcome;
    let mut twins = Vec::new();
    for (w, row) in paired.iter().zip(&loosest.rows) {
        if !auto(w) {
            continue;
        }
        let of = paired
            .iter()
            .zip(&loosest.rows)
            .find(|(o, r)| o.scheme == w.scheme && !auto(o) && same(row, r));
        if let Some((o, _)) = of {
            twins.push((w.label.clone(), o.label.clone()));
        }
    }
    twins
}

/// The sweep whose rows the `auto` sweep `label` takes, if it is a twin.
fn twin_of<'a>(twins: &'a [(String, String)], label: &str) -> Option<&'a str> {
    twins
        .iter()
        .find(|(auto, _)| auto == label)
        .map(|(_, of)| of.as_str())
}

/// `wp`'s rows in the order of `sweeps`, each twin taking its sweep's rows under its own
/// label; `as_run` gives the label a sweep's rows carry in `wp`.
fn with_twins(
    wp: WorkPrecision,
    sweeps: &[Sweep],
    twins: &[(String, String)],
    as_run: impl Fn(&Sweep) -> Sweep,
) -> WorkPrecision {
    let mut rows = Vec::new();
    for w in sweeps {
        let label = as_run(w).label;
        let source = match twin_of(twins, &w.label) {
            Some(of) => as_run(sweeps.iter().find(|o| o.label == of).expect("a sweep")).label,
            None => label.clone(),
        };
        rows.extend(wp.rows.iter().filter(|r| r.label == source).map(|r| Row {
            label: label.clone(),
            constraints: w.constraints.or(r.constraints),
            ..r.clone()
        }));
    }
    WorkPrecision { rows, ..wp }
}

/// The digits over q alone and over qd alone (largest mixed error over the samples) of every
/// sweep of `s` at rtol 1e-8, (label, q, qd); a run that fails is left out.
fn digits_apart<M: Model + Clone + 'static>(s: &Study, model: &M) -> Vec<(String, f64, f64)> {
    let n = M::NQ;
    let mut out = Vec::new();
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
        out.push((sweep.label.clone(), -eq.log10(), -ev.log10()));
    }
    out
}

/// The tolerances of the global-control sweeps; the schemes of order 2 and 3 stop at 1e-6
/// (Radau3 takes up to 1.1 million steps in all at 1e-8 on fastlink, the Newmark family fails
/// there after runs down to its floor).
const GLOBAL_RTOLS: [f64; 3] = [1e-4, 1e-6, 1e-8];

/// The global-control tolerances of the sweep `label`.
fn global_rtols(label: &str) -> &'static [f64] {
    let low_order = ["radau3", "gen-alpha", "hht", "rkc"];
    if low_order.iter().any(|s| label.starts_with(s)) {
        &GLOBAL_RTOLS[..2]
    } else {
        &GLOBAL_RTOLS
    }
}
/// Digits a run under global control may fall short of rtol: the slack of an estimate made
/// against a run at most ten times tighter (0.05 short at worst as measured).
const GLOBAL_SLACK: f64 = 0.2;

/// The study's sweeps again under global error control (`mbs::simulate_global`) at
/// [`GLOBAL_RTOLS`].
fn global_study(s: &Study) -> Study {
    Study {
        sweeps: s
            .sweeps
            .iter()
            .map(|w| {
                Sweep {
                    settings: global_rtols(&w.label)
                        .iter()
                        .map(|&r| Setting::Rtol(r))
                        .collect(),
                    ..w.clone()
                }
                .global()
            })
            .collect(),
        ..s.clone()
    }
}

/// The global-control sweeps' results: prints, per run, the digits beyond −log10 rtol (or
/// the failure) and the steps of all its runs; returns the runs that mislead: a result more
/// than [`GLOBAL_SLACK`] digits short of rtol, or a failure other than the typed
/// `GlobalToleranceNotMet` (and `ConstraintsUnsupported`, a method not offered), or a
/// failure of DOPRI5 or Radau5 with the default constraint method.
fn judge_global(wp: &WorkPrecision) -> (Vec<String>, Vec<GlobalOutcome>) {
    println!(
        "\nglobal error control: {} (digits − (−log10 rtol), steps of all runs)",
        wp.title
    );
    let mut bad = Vec::new();
    let mut outcomes = Vec::new();
    let mut line = String::new();
    for (k, row) in wp.rows.iter().enumerate() {
        let Setting::Rtol(rtol) = row.setting else {
            continue;
        };
        if k == 0 || wp.rows[k - 1].label != row.label {
            println!("{line}");
            line = format!("{:<32}", row.label);
        }
        let at = format!("{}: {} at rtol {rtol:e}", wp.title, row.label);
        match &row.outcome {
            Ok(a) => {
                let over = -a.error_max.log10() + rtol.log10();
                line += &format!("  {over:+6.2} {:>7}", row.stats.steps);
                outcomes.push(GlobalOutcome::Returned { over });
                if over < -GLOBAL_SLACK {
                    bad.push(format!("{at}: {over:.2} digits beyond rtol"));
                }
            }
            Err(f) => {
                line += &format!("  {:>14}", f.name());
                if matches!(f.kind, mbs::Failure::GlobalToleranceNotMet { .. }) {
                    outcomes.push(GlobalOutcome::NotMet);
                }
                let typed = matches!(
                    f.kind,
                    mbs::Failure::GlobalToleranceNotMet { .. }
                        | mbs::Failure::ConstraintsUnsupported { .. }
                );
                // BDF's runs at rtol 1e-8 reach its floor's edge (local rtol' 100ε)
                let expected = ["dopri5 auto", "radau5 auto"]
                    .iter()
                    .any(|l| row.label.starts_with(l));
                if !typed || expected {
                    bad.push(format!("{at}: {}", f.kind));
                }
            }
        }
    }
    println!("{line}");
    (bad, outcomes)
}

/// A run under global control: its digits beyond −log10 rtol, or the typed
/// `GlobalToleranceNotMet`.
enum GlobalOutcome {
    Returned { over: f64 },
    NotMet,
}

/// What one study measured that the README and `docs/accuracy.md` quote across the studies.
struct Measured {
    title: String,
    props: Vec<Proportionality>,
    global: Vec<GlobalOutcome>,
}

/// The studies of this file: slider-crank in both forms, the four-bar, Cash's pendulum, the
/// Cartesian double pendulum and fastlink.
const STUDIES: usize = 6;

/// The studies measured so far, in the order they ended (the tests run in parallel).
static MEASURED: std::sync::Mutex<Vec<Measured>> = std::sync::Mutex::new(Vec::new());

/// Keeps what a study measured; the study that completes the set checks the figures of the README and `docs/accuracy.md`
/// against all of them (a run of some of the tests checks nothing).
fn record(m: Measured) {
    let mut all = MEASURED.lock().unwrap_or_else(|e| e.into_inner());
    all.push(m);
    if all.len() == STUDIES {
        let phrases = quoted_phrases(&all);
        for file in [README, ACCURACY] {
            println!("\nthe figures of {file}, as measured here:");
            let of_file: Vec<String> = phrases
                .iter()
                .filter(|(f, _)| *f == file)
                .map(|(_, p)| p.clone())
                .collect();
            for p in &of_file {
                println!("  {p}");
            }
            quoted::says(file, &of_file);
        }
    }
}

/// The studies' titles as the README names them.
fn prose(title: &str) -> &str {
    match title {
        "pendulum3" => "Cash's pendulum",
        "dpend (Cartesian)" => "the Cartesian double pendulum",
        "four-bar" => "the four-bar",
        other => other,
    }
}

/// The motions that do not amplify local errors, and those that do (as the README groups them).
const SMOOTH: [&str; 3] = ["pendulum3", "dpend (Cartesian)", "slider-crank (b)"];
const AMPLIFYING: [&str; 3] = ["four-bar", "slider-crank (a)", "fastlink"];

/// `lo` and `hi` rounded outwards to a tenth: a range that holds them.
fn bracket(lo: f64, hi: f64) -> String {
    format!(
        "{:.1}–{:.1}",
        (lo * 10.0).floor() / 10.0,
        (hi * 10.0).ceil() / 10.0
    )
}

/// The least-squares slope of digits against −log10 rtol over the rtols `keep` accepts.
fn slope_where(p: &Proportionality, keep: impl Fn(f64) -> bool) -> f64 {
    let (rtols, digits) = (p.rtols.iter().zip(&p.digits))
        .filter(|(r, _)| keep(**r))
        .unzip();
    let kept = Proportionality {
        label: p.label.clone(),
        rtols,
        digits,
    };
    kept.slope().expect("a slope over two rtols or more")
}

/// The digits of `p` at `r`, where that run succeeded.
fn digits_at(p: &Proportionality, r: f64) -> Option<f64> {
    let k = p.rtols.iter().position(|&x| (x / r - 1.0).abs() < 1e-9)?;
    p.digits[k]
}

/// The smallest and largest of `v`.
fn min_max(v: impl IntoIterator<Item = f64>) -> (f64, f64) {
    v.into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        })
}

/// The mean of `v`.
fn mean(v: impl IntoIterator<Item = f64>) -> f64 {
    let (n, s) = v
        .into_iter()
        .fold((0usize, 0.0), |(n, s), x| (n + 1, s + x));
    s / n as f64
}

/// The README, whose section "What accuracy costs" sums up what rtol means and says what global
/// control did.
const README: &str = "README.md";
/// The page that gives the figures of what rtol means scheme by scheme.
const ACCURACY: &str = "docs/accuracy.md";

/// The figures of "What rtol means" and "Global error control", computed from the six studies
/// and written as the file that quotes each of them writes it: (file, phrase).
fn quoted_phrases(all: &[Measured]) -> Vec<(&'static str, String)> {
    let study = |title: &str| {
        all.iter()
            .find(|m| m.title == title)
            .unwrap_or_else(|| panic!("no study `{title}`"))
    };
    let sweep = |title: &str, label: &str| {
        study(title)
            .props
            .iter()
            .find(|p| p.label == label)
            .unwrap_or_else(|| panic!("no sweep `{label}` on {title}"))
    };
    let sweeps = |pick: &dyn Fn(&str) -> bool| -> Vec<(&Measured, &Proportionality)> {
        all.iter()
            .flat_map(|m| m.props.iter().map(move |p| (m, p)))
            .filter(|(_, p)| pick(&p.label))
            .collect()
    };
    let starts = |prefixes: &'static [&'static str]| {
        move |l: &str| prefixes.iter().any(|s| l.starts_with(s))
    };
    let mut out = Vec::new();

    // the asserted sweeps' slopes over their asserted range
    let (lo, hi) = min_max(
        sweeps(&|_| true)
            .into_iter()
            .map(|(_, p)| slope_where(p, |r| asserted(&p.label, r))),
    );
    out.push((
        README,
        format!(
            "gain {} digits per decade of rtol (least squares over their range)",
            bracket(lo, hi)
        ),
    ));

    // the sweeps held to 1.5 digits
    let below = |title: &str| {
        let p = sweep(title, "dopri5 partitioning");
        let median = |r: f64| median(&study(title).props, r).expect("median");
        min_max([1e-6, 1e-7, 1e-8].map(|r| median(r) - digits_at(p, r).expect("a run")))
    };
    let (lo, hi) = below("fastlink");
    out.push((ACCURACY, format!(
        "DOPRI5 with partitioning on fastlink, {lo:.2}–{hi:.2} digits below from rtol 1e-6 to 1e-8"
    )));
    let ((flo, fhi), (dlo, dhi)) = (below("four-bar"), below("dpend (Cartesian)"));
    out.push((ACCURACY, format!(
        "on the four-bar {flo:.2}–{fhi:.2} and on the Cartesian double pendulum {dlo:.2}–{dhi:.2}"
    )));
    let d = digits_at(sweep("slider-crank (b)", "radau5 auto"), 1e-7).expect("a run");
    let m = median(&study("slider-crank (b)").props, 1e-7).expect("median");
    out.push((
        ACCURACY,
        format!("Radau5 on slider-crank (b) at rtol 1e-7, {d:.2} digits against {m:.2}"),
    ));
    let d = digits_at(sweep("pendulum3", "bdf projection"), 1e-10).expect("a run");
    out.push((ACCURACY, format!(
        "BDF with projection on Cash's pendulum at rtol 1e-10, {d:.2} digits, {:.2} short of rtol's 10",
        10.0 - d
    )));

    // DOPRI5's loose end: where it falls more than its allowance below the median
    let mut loose = Vec::new();
    for m in all {
        let gaps: Vec<f64> = m
            .props
            .iter()
            .filter(|p| p.label.starts_with("dopri5"))
            .flat_map(|p| {
                [1e-4, 1e-5].into_iter().filter_map(move |r| {
                    let (median, d) = (median(&m.props, r)?, digits_at(p, r)?);
                    // judged as the asserted runs are, quoted against the median
                    let short = median.min(-r.log10()) - d > within(&m.title, &p.label);
                    short.then_some(median - d)
                })
            })
            .collect();
        if !gaps.is_empty() {
            loose.push((m.title.as_str(), min_max(gaps)));
        }
    }
    loose.sort_by_key(|(t, _)| SMOOTH.iter().chain(&AMPLIFYING).position(|s| s == t));
    let (lo, hi) = min_max(loose.iter().flat_map(|(_, (a, b))| [*a, *b]));
    let each: Vec<String> = loose
        .iter()
        .map(|(t, (a, b))| format!("{} ({a:.2}–{b:.2})", prose(t)))
        .collect();
    let listed = match each.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
        None => "no loop".into(),
    };
    out.push((
        ACCURACY,
        format!(
            "at 1e-4 and 1e-5 it falls {lo:.1}–{hi:.1} digits below the others' median on {listed}"
        ),
    ));

    // BDF's and DOPRI5's mean offsets over every run on the loops
    let offset = |prefix: &'static [&'static str]| {
        mean(
            sweeps(&starts(prefix))
                .into_iter()
                .flat_map(|(_, p)| p.offsets().map(|(_, o)| o).collect::<Vec<_>>()),
        )
    };
    out.push((
        ACCURACY,
        format!(
            "now {:.1} short, DOPRI5's {:.1}",
            -offset(&["bdf"]),
            -offset(&["dopri5"])
        ),
    ));

    // Radau3 with projection, partitioning or at index 2
    let radau3 = ["radau3 projection", "radau3 partitioning", "radau3 index2"];
    let (lo, hi) = min_max(
        sweeps(&|l| radau3.contains(&l))
            .into_iter()
            .map(|(_, p)| mean(p.offsets().map(|(_, o)| o))),
    );
    let (slo, shi) = min_max(
        sweeps(&|l| radau3.contains(&l))
            .into_iter()
            .map(|(_, p)| slope_where(p, |_| true)),
    );
    out.push((ACCURACY, format!(
        "now from {:.1} short to {hi:.1} better on average at {slo:.2}–{shi:.2} digits per decade",
        -lo
    )));

    // the Newmark family at index 3, its default, over its asserted range; and where it stalls
    let newmark3 = ["gen-alpha index3", "hht index3"];
    let (lo, hi) = min_max(
        sweeps(&|l| newmark3.contains(&l))
            .into_iter()
            .flat_map(|(_, p)| {
                p.offsets()
                    .filter(|(r, _)| asserted(&p.label, *r))
                    .map(|(_, o)| o)
                    .collect::<Vec<_>>()
            }),
    );
    let hht = digits_at(sweep("pendulum3", "hht index3"), 1e-4).expect("a run");
    out.push((ACCURACY, format!(
        "HHT on Cash's pendulum at rtol 1e-4 2.58 digits against 4.07, now {hht:.2}, and 0.9–3.1 digits short of rtol, now {:.1}–{:.1}",
        -hi, -lo
    )));
    let (lo, hi) = min_max(sweeps(&starts(&["gen-alpha", "hht"])).into_iter().flat_map(
        |(_, p)| {
            p.rtols
                .iter()
                .zip(&p.digits)
                .filter(|(r, _)| **r < 0.999e-8)
                .filter_map(|(_, d)| *d)
                .collect::<Vec<_>>()
        },
    ));
    out.push((
        ACCURACY,
        format!("below rtol 1e-8, the digits stall at {lo:.1}–{hi:.1}"),
    ));

    // local control: how far from rtol, on the motions that do and do not amplify errors
    let spread = |group: &[&str]| {
        min_max(
            sweeps(&|_| true)
                .into_iter()
                .filter(|(m, _)| group.contains(&m.title.as_str()))
                .flat_map(|(_, p)| {
                    p.offsets()
                        .filter(|(r, _)| asserted(&p.label, *r))
                        .map(|(_, o)| o)
                        .collect::<Vec<_>>()
                }),
        )
    };
    let ((slo, shi), (alo, ahi)) = (spread(&SMOOTH), spread(&AMPLIFYING));
    out.push((README, format!(
        "from {shi:.1} digits better to {:.1} short on Cash's pendulum, the Cartesian double pendulum and slider-crank (b), from {ahi:.1} better to {:.1} short on the four-bar, slider-crank (a) and fastlink",
        -slo, -alo
    )));

    // Radau5 at index 2 against projection; Radau3 at index 3
    let (slo, shi) = min_max(
        sweeps(&|l| l == "radau5 index2")
            .into_iter()
            .map(|(_, p)| slope_where(p, |_| true)),
    );
    let (alo, ahi) = min_max(
        sweeps(&|l| l == "radau5 index2")
            .into_iter()
            .flat_map(|(m, p)| {
                let projection = m
                    .props
                    .iter()
                    .find(|q| q.label == "radau5 projection")
                    .expect("projection");
                p.rtols
                    .iter()
                    .filter_map(|&r| Some(digits_at(p, r)? - digits_at(projection, r)?))
                    .collect::<Vec<_>>()
            }),
    );
    out.push((ACCURACY, format!(
        "Radau5 at index 2 is asserted too ({slo:.2}–{shi:.2} digits per decade, {alo:.1} to {ahi:.1} digits above projection"
    )));
    // Radau3 at index 3 over its asserted range
    let radau3_index3 = sweeps(&starts(&["radau3 index3"]));
    let (lo, hi) = min_max(radau3_index3.iter().map(|(_, p)| {
        mean(
            p.offsets()
                .filter(|(r, _)| asserted(&p.label, *r))
                .map(|(_, o)| o),
        )
    }));
    let (slo, shi) =
        min_max((radau3_index3.iter()).map(|(_, p)| slope_where(p, |r| asserted(&p.label, r))));
    out.push((
        ACCURACY,
        format!(
            "{slo:.2}–{shi:.2} digits per decade, {:.1}–{:.1} digits short on average",
            -hi, -lo
        ),
    ));

    // global control over every study
    let returned: Vec<f64> = all
        .iter()
        .flat_map(|m| &m.global)
        .filter_map(|g| match g {
            GlobalOutcome::Returned { over } => Some(*over),
            GlobalOutcome::NotMet => None,
        })
        .collect();
    let not_met = all
        .iter()
        .flat_map(|m| &m.global)
        .filter(|g| matches!(g, GlobalOutcome::NotMet))
        .count();
    let (lo, hi) = min_max(returned.iter().copied());
    out.push((
        README,
        format!(
            "the {} runs it returned were from {:.2} digits short of rtol to {hi:.1} better",
            returned.len(),
            -lo
        ),
    ));
    out.push((
        README,
        format!("and the {not_met} others ended in `GlobalToleranceNotMet`"),
    ));
    out
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
        slidercrank::form_a_state(y[0], y[1]).to_vec()
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
        |_, y| dpend_cartesian::from_relative(y),
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
