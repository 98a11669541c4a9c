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

use mbs::work_precision::{Reference, Setting};
use mbs::{
    ConstraintMethod, ConstraintOptions, Integrator, Model, Options, Output, Scheme, Simulation,
    Stats, Trajectory, simulate,
};
use mbs_models::{pendulum3, slidercrank};
use pendulum3::Pendulum3;
#[path = "common/alloc.rs"]
mod alloc;

const INDEX2: ConstraintMethod = ConstraintMethod::Index2;

fn with_method(base: Options, method: ConstraintMethod) -> Options {
    Options {
        output: Output::Last,
        energy: false,
        constraints: ConstraintOptions {
            method,
            ..Default::default()
        },
        ..base
    }
}

/// Fixed steps of 1/k with Newton converged well below the errors measured.
fn fixed(k: u32) -> Options {
    let mut o = Options::fixed(1.0, 1.0 / k as f64);
    o.newton.atol = 1e-14;
    o.newton.rtol = 1e-14;
    o.newton.max_iterations = 20;
    o
}

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

/// Radau3 at index 2: q and qd of order 2s − 1 = 3, λ of order s = 2.
#[test]
fn radau3_fixed_step_orders_are_three_three_two() {
    let p = orders(Scheme::Radau3, &[20, 40, 80, 160, 320]);
    for o in &p {
        assert!(
            within(o[0], 3.0) && within(o[1], 3.0) && within(o[2], 2.0),
            "{p:?}"
        );
    }
}

/// Radau5 at index 2: q and qd of order 5, λ of order 3; q and qd measured at the larger
/// steps, where their errors stay well above the reference's (~1e-13).
#[test]
fn radau5_fixed_step_orders_are_five_five_three() {
    let p = orders(Scheme::Radau5, &[5, 10, 20]);
    for o in &p {
        assert!(within(o[0], 5.0) && within(o[1], 5.0), "{p:?}");
    }
    let p = orders(Scheme::Radau5, &[20, 40, 80, 160]);
    for o in &p {
        assert!(within(o[2], 3.0), "{p:?}");
    }
}

/// Adaptive runs on the pendulum: q and qd at t = 1 within a few rtol, λ at its attainable
/// accuracy (order s, weighted by h in the error test as RADAU5 weights index-2 components):
/// within √rtol (Radau3's at rtol 1e-8 is 1.2e-5).
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
            assert!(e[0] < 3.0 * rtol && e[1] < 3.0 * rtol, "{e:?}");
            assert!(e[2] < rtol.sqrt(), "{e:?}");
            // projection (the default) for comparison
            let o = with_method(Options::adaptive(1.0, rtol), ConstraintMethod::Projection);
            let (tr, st) = run(Pendulum3::default(), scheme, o);
            let (q, qd, l) = last(&tr);
            let e = [max_diff(&q, &rq), max_diff(&qd, &rv), max_diff(&l, &rl)];
            println!(
                "  projection: q {:.2e} qd {:.2e} λ {:.2e} ({} steps)",
                e[0], e[1], e[2], st.steps
            );
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
    let (rr, l) = (0.1, 0.3);
    let (th, thd) = (y[0], y[1]);
    let (psi, s) = slidercrank::closed_loop(th);
    let psid = -rr * th.cos() * thd / (l * psi.cos());
    let sd = -rr * th.sin() * thd - l * psi.sin() * psid;
    let (rq, rv) = ([th, psi, s], [thd, psid, sd]);
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
                let (n, nc) = (M::NQ, M::NC);
                let (mut phi, mut b, mut phit) = (vec![0.0; nc], vec![0.0; nc * n], vec![0.0; nc]);
                let (mut worst, mut worst_rate) = (0.0f64, 0.0f64);
                for i in 0..tr.len() {
                    let (t, q, qd) = (tr.t[i], tr.q(i), tr.qd(i));
                    model.constraints(t, q, &mut phi);
                    model.constraint_jacobian(t, q, &mut b);
                    model.constraint_rate(t, q, &mut phit);
                    for k in 0..nc {
                        let rate = phit[k] + (0..n).map(|j| b[k + nc * j] * qd[j]).sum::<f64>();
                        worst = worst.max(phi[k].abs());
                        worst_rate = worst_rate.max(rate.abs());
                    }
                }
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
            let mut sim = Simulation::new(Pendulum3::default(), scheme, o)
                .unwrap_or_else(|e| panic!("{}: {e}", scheme.name()));
            for _ in 0..20 {
                sim.step().unwrap();
            }
            let before = alloc::allocations();
            for _ in 0..200 {
                sim.step().unwrap();
            }
            let allocated = alloc::allocations() - before;
            assert_eq!(
                allocated,
                0,
                "{} allocated {allocated} times",
                scheme.name()
            );
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
    // every stage of every iteration, Φ_t, B and Φ_t of the new state, the drift check),
    // factorisations (a complex and a real block at every new h), solves, Newton iterations
    // (5.6 per step, with the 3 rejected attempts)
    assert_eq!(got, [18, 0, 3, 18, 393, 1003, 46, 224, 101]);
    assert_eq!(s.error_test, mbs::ErrorTest::PositionsVelocities);
}
