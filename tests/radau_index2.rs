//! Radau IIA in the stabilized index-2 form of Gear, Gupta & Leimkuhler (1985)
//! (`ConstraintMethod::Index2`).
//!
//! The form: q̇ = qd + B₀ᵀμ, M qdd = h + Bᵀλ, Φ(q) = 0, B qd + Φ_t = 0, an index-2 DAE in
//! Hessenberg form with (q, qd) differential and (λ, μ) algebraic. Radau IIA with s stages
//! gives, on such systems (Hairer, Lubich & Roche 1989; Hairer & Wanner II, §VII.4), the
//! differential components with order 2s − 1 and the algebraic ones with order s: q and qd of
//! order 3 and λ of order 2 for Radau3, 5, 5 and 3 for Radau5.
//!
//! What is measured (`cargo test --release --test radau_index2 -- --nocapture` prints it):
//! fixed-step orders 3.00, 3.00, 2.00 (Radau3, h = 1/20..1/320) and 5.0, 5.0, 3.0 (Radau5,
//! q and qd at h = 1/5..1/20, λ at 1/20..1/160, above the reference's accuracy); adaptive
//! runs give q and qd within a few rtol on the pendulum (the slider-crank within 10 rtol of
//! its scale), λ within √rtol, and |Φ| below 1e-13, |Φ̇| below 1e-11 at every step.

use mbs::work_precision::{Reference, Setting, mixed_error};
use mbs::{
    ConstraintMethod, ConstraintOptions, Model, Options, Output, Scheme, Simulation, Stats,
    StepControl, Trajectory, simulate,
};
use mbs_models::{dpend, fourbar, pendulum3, slidercrank};
use pendulum3::Pendulum3;
#[path = "common/alloc.rs"]
mod alloc;
mod common;
#[path = "common/quoted.rs"]
mod quoted;
use common::{fixed, with_method};

const INDEX2: ConstraintMethod = ConstraintMethod::Index2;

fn run<M: Model + 'static>(model: M, scheme: Scheme, o: Options) -> (Trajectory, Stats) {
    match simulate(model, scheme, o) {
        Ok(r) => r,
        Err(e) => panic!("{}: {e}", scheme.name()),
    }
}

/// (q, qd, λ) of the last output.
fn last(tr: &Trajectory) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let i = tr.len() - 1;
    (tr.q(i).to_vec(), tr.qd(i).to_vec(), tr.lambda(i).to_vec())
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The pendulum at t = 1: (q, qd, λ) of Radau5 by projection at rtol 1e-12 (λ of the index-1
/// form at the projected state), checked against `tests/reference/pendulum3.json` (given to
/// about 1e-10).
fn pendulum_reference() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let path = format!(
        "{}/tests/reference/pendulum3.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    assert_eq!(json["t"].as_f64(), Some(1.0));
    let s = &json["state"];
    let v = |k: &str| s[k].as_f64().unwrap_or_else(|| panic!("state.{k}"));
    let o = with_method(Options::adaptive(1.0, 1e-12), ConstraintMethod::Projection);
    let (tr, _) = run(Pendulum3::default(), Scheme::Radau5, o);
    let (q, qd, l) = last(&tr);
    let d = max_diff(
        &[q[0], q[1], qd[0], qd[1], l[0]],
        &[v("x"), v("y"), v("xd"), v("yd"), v("lam")],
    );
    assert!(d < 2e-10, "reference run against pendulum3.json: {d:e}");
    (q, qd, l)
}

/// Fixed-step orders of q, qd and λ on the pendulum, h = 1/k, k doubling.
fn orders(scheme: Scheme, ks: &[u32]) -> Vec<[f64; 3]> {
    let (rq, rv, rl) = pendulum_reference();
    let mut prev: Option<[f64; 3]> = None;
    let mut out = Vec::new();
    println!(
        "{:<7} {:>6} {:>10} {:>10} {:>10} | {:>5} {:>5} {:>5}",
        "scheme", "h", "err q", "err qd", "err λ", "p q", "p qd", "p λ"
    );
    for &k in ks {
        let (tr, _) = run(Pendulum3::default(), scheme, with_method(fixed(k), INDEX2));
        let (q, qd, l) = last(&tr);
        let e = [max_diff(&q, &rq), max_diff(&qd, &rv), max_diff(&l, &rl)];
        let p = prev.map(|pe| [0, 1, 2].map(|i| (pe[i] / e[i]).log2()));
        let f = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2}"));
        println!(
            "{:<7} {:>6} {:>10.3e} {:>10.3e} {:>10.3e} | {:>5} {:>5} {:>5}",
            scheme.name(),
            format!("1/{k}"),
            e[0],
            e[1],
            e[2],
            f(p.map(|p| p[0])),
            f(p.map(|p| p[1])),
            f(p.map(|p| p[2]))
        );
        if let Some(p) = p {
            out.push(p);
        }
        prev = Some(e);
    }
    out
}

fn within(p: f64, theory: f64) -> bool {
    (p - theory).abs() <= 0.3
}

/// Radau3 at index 2: q and qd of order 2s − 1 = 3, and λ too: the state's λ comes from the
/// index-1 equations at (q, qd) (the last stage's Λ is of order s = 2).
#[test]
fn radau3_fixed_step_orders_are_three() {
    let p = orders(Scheme::Radau3, &[20, 40, 80, 160, 320]);
    for o in &p {
        assert!(
            within(o[0], 3.0) && within(o[1], 3.0) && within(o[2], 3.0),
            "{p:?}"
        );
    }
}

/// Radau5 at index 2: q, qd and λ of order 5 (the stage Λ of order 3), measured at the larger
/// steps, where their errors stay well above the reference's (~1e-13).
#[test]
fn radau5_fixed_step_orders_are_five() {
    let p = orders(Scheme::Radau5, &[5, 10, 20, 40]);
    for o in &p {
        assert!(
            within(o[0], 5.0) && within(o[1], 5.0) && within(o[2], 5.0),
            "{p:?}"
        );
    }
}

/// Adaptive runs on the pendulum: q, qd and λ at t = 1 within a few rtol (λ from the index-1
/// equations at the step's (q, qd); the last stage's Λ, of order s, was only within √rtol:
/// Radau3's at rtol 1e-8 was 1.2e-5).
#[test]
fn adaptive_runs_reach_the_pendulum_reference() {
    let (rq, rv, rl) = pendulum_reference();
    for scheme in [Scheme::Radau3, Scheme::Radau5] {
        for rtol in [1e-4, 1e-6, 1e-8] {
            let o = with_method(Options::adaptive(1.0, rtol), INDEX2);
            let (tr, st) = run(Pendulum3::default(), scheme, o);
            let (q, qd, l) = last(&tr);
            let e = [max_diff(&q, &rq), max_diff(&qd, &rv), max_diff(&l, &rl)];
            println!(
                "{} rtol {rtol:e}: q {:.2e} qd {:.2e} λ {:.2e} ({} steps)",
                scheme.name(),
                e[0],
                e[1],
                e[2],
                st.steps
            );
            assert!(e.iter().all(|&x| x < 3.0 * rtol), "{e:?}");
            // projection (the default) for comparison
            let o = with_method(Options::adaptive(1.0, rtol), ConstraintMethod::Projection);
            let (tr, sp) = run(Pendulum3::default(), scheme, o);
            let (q, qd, l) = last(&tr);
            let ep = [max_diff(&q, &rq), max_diff(&qd, &rv), max_diff(&l, &rl)];
            println!(
                "  projection: q {:.2e} qd {:.2e} λ {:.2e} ({} steps)",
                ep[0], ep[1], ep[2], sp.steps
            );
            if scheme == Scheme::Radau5 && rtol == 1e-6 {
                quoted::says(
                    "README.md",
                    &[format!(
                        "pendulum3 at rtol 1e-6 (Radau5) {} steps, q, qd, λ within {:.1e}, {:.1e}, {:.1e}, where projection takes {} steps for {:.1e}, {:.1e}, {:.1e}",
                        st.steps, e[0], e[1], e[2], sp.steps, ep[0], ep[1], ep[2]
                    )],
                );
            }
        }
    }
}

/// Slider-crank form (a) against form (b) (θ alone, the loop in closed form, DOPRI5 at rtol
/// 1e-13) at t = 2 s, mapped to (θ, ψ, s); λ against Radau5 by projection at rtol 1e-11.
#[test]
fn adaptive_runs_reach_the_slider_crank_reference() {
    let r = Reference::compute(
        &slidercrank::SliderCrankClosed::default(),
        vec![2.0],
        (Scheme::Dopri5, Setting::Rtol(1e-13)),
        None,
        &Options::default(),
    )
    .expect("form (b)");
    let y = &r.states[0];
    let a = slidercrank::form_a_state(y[0], y[1]);
    let (rq, rv) = ([a[0], a[1], a[2]], [a[3], a[4], a[5]]);
    let o = with_method(Options::adaptive(2.0, 1e-11), ConstraintMethod::Projection);
    let (tr, _) = run(slidercrank::SliderCrank::default(), Scheme::Radau5, o);
    let (_, _, rl) = last(&tr);
    for scheme in [Scheme::Radau3, Scheme::Radau5] {
        for rtol in [1e-4, 1e-6, 1e-8] {
            let o = with_method(Options::adaptive(2.0, rtol), INDEX2);
            let (tr, st) = run(slidercrank::SliderCrank::default(), scheme, o);
            let (q, qd, lam) = last(&tr);
            // relative to the scale of each: θ ~ 20 rad, θ̇ ~ 10 rad/s, λ ~ 10 N
            let e = [
                max_diff(&q, &rq) / 20.0,
                max_diff(&qd, &rv) / 10.0,
                max_diff(&lam, &rl) / 10.0,
            ];
            println!(
                "{} rtol {rtol:e}: q {:.2e} qd {:.2e} λ {:.2e} (relative; {} steps)",
                scheme.name(),
                e[0],
                e[1],
                e[2],
                st.steps
            );
            assert!(e[0] < 10.0 * rtol && e[1] < 10.0 * rtol, "{e:?}");
            assert!(e[2] < 300.0 * rtol, "{e:?}");
        }
    }
}

/// |Φ| and |Φ̇| = |B qd + Φ_t| at every step within the constraint tolerance (1e-11), on the
/// pendulum and the slider-crank.
#[test]
fn constraints_and_their_rates_hold_at_every_step() {
    fn check<M: Model + Clone + 'static>(model: M, t_end: f64) {
        let tol = ConstraintOptions::default().tolerance;
        for scheme in [Scheme::Radau3, Scheme::Radau5] {
            for rtol in [1e-4, 1e-8] {
                let o = Options {
                    output: Output::Steps,
                    ..with_method(Options::adaptive(t_end, rtol), INDEX2)
                };
                let (tr, _) = run(model.clone(), scheme, o);
                let (worst, worst_rate) = common::constraint_residuals(&model, &tr);
                println!(
                    "{} {} rtol {rtol:e}: max |Φ| {worst:.1e}, max |Φ̇| {worst_rate:.1e} over {} steps",
                    model.info().name,
                    scheme.name(),
                    tr.len()
                );
                assert!(
                    worst <= tol && worst_rate <= tol,
                    "{worst:e} {worst_rate:e}"
                );
            }
        }
    }
    check(Pendulum3::default(), 1.0);
    check(slidercrank::SliderCrank::default(), 2.0);
}

/// No allocation per step at index 2: the augmented buffers are made in `start`.
#[test]
fn index2_steps_allocate_nothing_after_warm_up() {
    for scheme in [Scheme::Radau3, Scheme::Radau5] {
        for base in [Options::fixed(100.0, 1e-2), Options::adaptive(100.0, 1e-8)] {
            let o = Options {
                output: Output::Every { dt: 0.01 },
                ..with_method(base, INDEX2)
            };
            let sim = Simulation::new(Pendulum3::default(), scheme, o)
                .unwrap_or_else(|e| panic!("{}: {e}", scheme.name()));
            alloc::assert_no_allocation(sim, scheme.name());
        }
    }
}

/// Work counters of one run (Radau5, index 2, the pendulum to t = 1 at rtol 1e-6), and what
/// the statistics say the error test controls.
#[test]
fn work_counters_of_an_index2_run() {
    let o = with_method(Options::adaptive(1.0, 1e-6), INDEX2);
    let (_, s) = run(Pendulum3::default(), Scheme::Radau5, o);
    let got = [
        s.steps,
        s.rejected_error,
        s.rejected_newton,
        s.mass_matrix,
        s.inverse_dynamics,
        s.constraints,
        s.factorizations,
        s.solves,
        s.newton_iterations,
    ];
    println!("{got:?}");
    // steps, rejected by the error test, by Newton, M, τ, constraint evaluations (B and Φ at
    // every stage of every iteration, Φ_t, B and Φ_t of the new state, the drift check, B
    // for the loops' watch, n evaluations of B and n + 1 of Φ_t for ∂(B qd + Φ_t)/∂q with
    // each new Jacobian, B and γ for the state's qdd and λ), factorisations (a complex and a real block at every new h;
    // M and the bordered system for the state's qdd and λ at every step), solves, Newton
    // iterations (4.6 per attempt, with the 2 rejected ones); 16 steps and 89 iterations
    // when λ's error was weighed by h rather than by the velocities it moves
    assert_eq!(got, [19, 0, 2, 19, 386, 1126, 84, 255, 97]);
    assert_eq!(s.error_test, mbs::ErrorTest::PositionsVelocities);
}

/// The mixed error over (q, qd) (Test Set for IVP Solvers, floor 0.01, the largest over the
/// sampled times) of a run at rtol (atol = rtol/100), as log10(error/rtol).
fn excess<M: Model + Clone + 'static>(
    model: &M,
    scheme: Scheme,
    method: Option<ConstraintMethod>,
    rtol: f64,
    times: &[f64],
    refs: &[Vec<f64>],
) -> f64 {
    let mut o = Options {
        t_end: *times.last().expect("times"),
        step: StepControl::Adaptive {
            rtol,
            atol: rtol * 1e-2,
            h0: None,
        },
        output: Output::Times(times.to_vec()),
        energy: false,
        ..Options::default()
    };
    if let Some(m) = method {
        o.constraints.method = m;
    }
    let (tr, _) = run(model.clone(), scheme, o);
    let e = (0..tr.len())
        .map(|i| {
            let y: Vec<f64> = tr.q(i).iter().chain(tr.qd(i)).copied().collect();
            mixed_error(&y, &refs[i], 1e-2)
        })
        .fold(0.0, f64::max);
    (e / rtol).log10()
}

fn samples(t_end: f64, n: usize) -> Vec<f64> {
    (1..=n).map(|k| t_end * k as f64 / n as f64).collect()
}

/// What rtol means for Radau today: for rtol = 1e-4 … 1e-10 the mixed error over (q, qd)
/// of radau3 and radau5 by projection, at index 2 and at index 3 on pendulum3, the
/// slider-crank (a) and the four-bar, and of the open-loop double pendulum, printed as
/// log10(error/rtol). With RADAU5's tolerance transformation for Radau5 and the linear
/// mapping for Radau3 (`Tol::new` in `mbs-runtime/src/integrators/radau/mod.rs`) the target
/// of 1 digit is not met everywhere (the module doc, "What rtol means", and
/// `tests/tolerance_proportionality.rs`): what is asserted is within 4.5 digits of
/// rtol by projection and at index 2, and at most 0.5 digits lost when rtol tightens by a
/// decade (the four-bar, radau5 at index 2, from 1e-5 to 1e-6: −0.54 → 0.94); index 3 is
/// printed only.
#[test]
fn the_mixed_error_against_rtol() {
    let rtols: Vec<f64> = (4..=10).map(|k| 10f64.powi(-k)).collect();
    let mut worst = f64::NEG_INFINITY;
    let mut study = |name: &str,
                     table: &mut Vec<(String, Vec<f64>, bool)>,
                     f: &dyn Fn(Scheme, Option<ConstraintMethod>, f64) -> f64,
                     methods: &[Option<ConstraintMethod>]| {
        for scheme in [Scheme::Radau3, Scheme::Radau5] {
            for &m in methods {
                let row: Vec<f64> = rtols.iter().map(|&r| f(scheme, m, r)).collect();
                let label = format!(
                    "{name:<12} {:<7} {:<10}",
                    scheme.name(),
                    m.map_or("-", |m| m.name())
                );
                let asserted = m != Some(ConstraintMethod::Index3);
                if asserted {
                    worst = row.iter().copied().fold(worst, f64::max);
                }
                table.push((label, row, asserted));
            }
        }
    };
    let closed = [
        Some(ConstraintMethod::Projection),
        Some(INDEX2),
        Some(ConstraintMethod::Index3),
    ];
    let mut projection = Options::default();
    projection.constraints.method = ConstraintMethod::Projection;
    let mut table = Vec::new();
    // the pendulum: reference by DOPRI5 at rtol 1e-13, checked by Radau5 at 1e-12
    let times = samples(1.0, 10);
    let pend = Pendulum3::default();
    let r = Reference::compute(
        &pend,
        times.clone(),
        (Scheme::Dopri5, Setting::Rtol(1e-13)),
        Some((Scheme::Radau5, Setting::Rtol(1e-12))),
        &projection,
    )
    .expect("pendulum3 reference");
    let check = r.estimated_error(1e-2).expect("check").1;
    println!("reference against its check: {check:.1e}");
    assert!(check < 1e-9);
    let f = |s, m, rtol| excess(&pend, s, m, rtol, &times, &r.states);
    study("pendulum3", &mut table, &f, &closed);
    // the slider-crank: form (b) mapped to form (a)
    let times = samples(2.0, 10);
    let r = Reference::compute(
        &slidercrank::SliderCrankClosed::default(),
        times.clone(),
        (Scheme::Dopri5, Setting::Rtol(1e-13)),
        None,
        &Options::default(),
    )
    .expect("slider-crank reference")
    .map("form (b) mapped to form (a)", |_, y| {
        slidercrank::form_a_state(y[0], y[1]).to_vec()
    });
    let sc = slidercrank::SliderCrank::default();
    let f = |s, m, rtol| excess(&sc, s, m, rtol, &times, &r.states);
    study("slidercrank", &mut table, &f, &closed);
    // the four-bar: DOPRI5 by projection at rtol 1e-13, checked by Radau5 at 1e-12
    let fb = fourbar::FourBar::default();
    let r = Reference::compute(
        &fb,
        times.clone(),
        (Scheme::Dopri5, Setting::Rtol(1e-13)),
        Some((Scheme::Radau5, Setting::Rtol(1e-12))),
        &projection,
    )
    .expect("four-bar reference");
    let check = r.estimated_error(1e-2).expect("check").1;
    println!("reference against its check: {check:.1e}");
    assert!(check < 1e-9);
    let f = |s, m, rtol| excess(&fb, s, m, rtol, &times, &r.states);
    study("fourbar", &mut table, &f, &closed);
    // the double pendulum (no loop): tests/reference/dpend.json at 0.5, 1 and 2 s
    let path = format!("{}/tests/reference/dpend.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let states = json["states"].as_array().expect("states");
    let times = [0.5, 1.0, 2.0];
    let refs: Vec<Vec<f64>> = times
        .iter()
        .map(|&t| {
            let s = states
                .iter()
                .find(|s| s["t"].as_f64() == Some(t))
                .unwrap_or_else(|| panic!("dpend.json: no state at {t}"));
            ["q", "qd"]
                .iter()
                .flat_map(|k| s[*k].as_array().expect("array").iter())
                .map(|x| x.as_f64().expect("number"))
                .collect()
        })
        .collect();
    let dp = dpend::DoublePendulum::default();
    let f = |s, m, rtol| excess(&dp, s, m, rtol, &times, &refs);
    study("dpend", &mut table, &f, &[None]);
    println!("log10(mixed error / rtol), rtol = 1e-4 … 1e-10");
    for (label, row, _) in &table {
        let cells: Vec<String> = row.iter().map(|x| format!("{x:>6.2}")).collect();
        println!("{label} {}", cells.join(""));
    }
    println!("worst asserted: {worst:.2}");
    for (label, row, asserted) in &table {
        if !asserted {
            continue;
        }
        assert!(row.iter().all(|&x| x <= 4.5), "{label}: {row:?}");
        // a decade tighter: at most 0.5 correct digits lost
        assert!(
            row.windows(2).all(|w| w[1] - w[0] <= 1.5),
            "{label}: {row:?}"
        );
    }
}
