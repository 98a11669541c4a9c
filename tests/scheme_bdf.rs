//! BDF 1–5 with variable step and order (`mbs-runtime/src/integrators/bdf.rs`) on the
//! canonical models: observed orders, accuracy on the chaotic double pendulum and why it stops
//! short of 1e-6 at t = 10 s at rtol 1e-10, a snapshot of the work, the order history, fixed
//! steps, failures.

mod common;
#[path = "common/quoted.rs"]
mod quoted;
use mbs_models::dpend;
use mbs_models::seed2dof;

use common::*;
use dpend::DoublePendulum;
use mbs::{BdfParams, Options, Output, Scheme, StepControl, simulate};
use seed2dof::Seed2dof;

fn bdf(max_order: usize) -> Scheme {
    Scheme::Bdf(BdfParams { max_order })
}

fn sci(v: &[f64]) -> String {
    let s: Vec<String> = v.iter().map(|x| format!("{x:.2e}")).collect();
    s.join(" ")
}

/// Largest |Δq|, |Δqd| between two states.
fn distance(q: &[f64], qd: &[f64], rq: &[f64], rqd: &[f64]) -> f64 {
    q.iter()
        .zip(rq)
        .chain(qd.iter().zip(rqd))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// Error against the number of steps on seed2dof (max over outputs every 10 ms, so that the
/// two modes' interference at single instants averages out) as rtol tightens: slope ≈ −k.
///
/// Measured (slopes of the fits below): k = 1: 0.97, 2: 2.00, 3: 3.00, 4: 4.01, 5: 5.05.
/// BDF1 and BDF2 need small steps on the 10 Hz mode (their damping is of order hω per step),
/// hence the looser tolerances and the many steps of k = 1 (up to 230,000, still fast). The
/// tolerances are the user's; the error test runs at rtol' = 0.1·rtol^1.25 (1e-5 … 1e-9 here).
#[test]
fn observed_orders_on_seed2dof() {
    let cases: [(usize, &[f64]); 5] = [
        (1, &[6e-4, 1e-4, 1.6e-5]),
        (2, &[1e-4, 1e-5, 1e-6, 1e-7]),
        (3, &[1e-4, 1e-5, 1e-6, 1e-7]),
        (4, &[1e-4, 1e-5, 1e-6, 1e-7]),
        (5, &[1e-4, 1e-5, 1e-6, 1e-7]),
    ];
    for (k, rtols) in cases {
        let mut steps = Vec::new();
        let mut errs = Vec::new();
        for &rtol in rtols {
            let opts = Options {
                output: Output::Every { dt: 0.01 },
                energy: false,
                ..Options::adaptive(1.0, rtol)
            };
            let (tr, st) = simulate(Seed2dof::default(), bdf(k), opts).unwrap();
            steps.push(st.steps as f64);
            errs.push(seed2dof_max_error(&tr));
            // the top order is reached and carries the run
            let top = st.order_steps.get(k - 1).copied().unwrap_or(0);
            assert!(
                top * 10 >= st.steps * 9,
                "BDF{k}: orders {:?}",
                st.order_steps
            );
        }
        let p = -loglog_slope(&steps, &errs);
        println!(
            "BDF{k}: steps {steps:?}, errors {} → order {p:.2}",
            sci(&errs)
        );
        assert!(
            (p - k as f64).abs() <= 0.3,
            "BDF{k}: error–steps slope {p:.2}"
        );
    }
}

/// States (t, q, qd) at output times.
type States = Vec<(f64, Vec<f64>, Vec<f64>)>;

/// dpend at the reference times, adaptive at (rtol, atol), max order 5; q0 shifted by `dq0`.
fn dpend_run(rtol: f64, atol: f64, dq0: f64) -> (States, mbs::Stats) {
    let times = vec![0.5, 1.0, 2.0, 5.0, 10.0];
    let opts = Options {
        t_end: 10.0,
        q0: Some(vec![std::f64::consts::FRAC_PI_2 + dq0, 0.0]),
        step: StepControl::Adaptive {
            rtol,
            atol,
            h0: None,
        },
        output: Output::Times(times.clone()),
        energy: false,
        ..Options::default()
    };
    let (tr, st) = simulate(DoublePendulum::default(), bdf(5), opts).unwrap();
    assert_eq!(tr.len(), times.len());
    let states = (0..tr.len())
        .map(|i| (tr.t[i], tr.q(i).to_vec(), tr.qd(i).to_vec()))
        .collect();
    (states, st)
}

fn dpend_errors(states: &[(f64, Vec<f64>, Vec<f64>)]) -> Vec<f64> {
    states
        .iter()
        .map(|(t, q, qd)| {
            let (rq, rqd) = reference_state("dpend", *t);
            distance(q, qd, &rq, &rqd)
        })
        .collect()
}

/// Every adaptive scheme was asked for dpend within 1e-6 of the reference at t = 10 s at
/// rtol 1e-10. BDF misses it: measured 1.6e-5 (17,142 steps, 277 rejected; 7.3e-4 before its
/// tolerance mapping and other roundings of the generated code: on this motion the figure at
/// 10 s moves by orders of magnitude with the rounding). SciPy's `BDF` (the same formulation)
/// gives 4.6e-4 on the same problem and tolerances, its DOP853 9e-6 (reference file), DOPRI5
/// here 3.7e-5. The cause is the pendulum, not the scheme. Why 1e-6 at t = 10 s is out of
/// reach at rtol 1e-10, measured:
/// - up to 5 s BDF at rtol 1e-10 stays far within 1e-6 (errors 9e-11, 5e-10, 1.4e-9, 1.1e-8
///   at 0.5, 1, 2, 5 s), then the error grows ×1000 in the next 5 s;
/// - a shift of 1e-10 of q0 alone moves the state at 10 s by ~2e-5 (amplification ~2e5):
///   every one of the local errors of ~1e-10 (rtol·|y|, |y| up to 14) is amplified
///   likewise, so rtol 1e-10 cannot be relied on for 1e-6;
/// - tightening rtol reaches it: 4.7e-7 at rtol 1e-14 (30,196 steps).
#[test]
fn dpend_error_is_amplified_by_the_chaos() {
    let (states, st) = dpend_run(1e-10, 1e-12, 0.0);
    let e = dpend_errors(&states);
    println!(
        "rtol 1e-10: errors at 0.5, 1, 2, 5, 10 s: {}\n{st}",
        sci(&e)
    );
    assert!(
        e[0] < 2e-8 && e[1] < 1e-7 && e[2] < 3e-7 && e[3] < 2e-6,
        "{}",
        sci(&e)
    );
    assert!(e[4] < 3e-3, "{}", sci(&e));

    let (tight, st) = dpend_run(1e-14, 1e-16, 0.0);
    let e_tight = dpend_errors(&tight);
    println!("rtol 1e-14: errors {}\n{st}", sci(&e_tight));
    assert!(e_tight[4] < 1e-6, "{}", sci(&e_tight));

    let (shifted, _) = dpend_run(1e-14, 1e-16, 1e-10);
    let (_, q, qd) = &tight[4];
    let (_, sq, sqd) = &shifted[4];
    let moved = distance(q, qd, sq, sqd);
    println!("q0 shifted by 1e-10: the state at 10 s moves by {moved:.2e}");
    assert!(moved > 1e-6, "amplification {:.1e}", moved / 1e-10);
}

/// A snapshot of the work: dpend to 2 s at rtol 1e-6 (atol 1e-8), max order 5, finite
/// difference iteration matrices (dpend has no tangents). Any change that alters the work
/// must update these numbers knowingly.
///
/// - 2 `forward_dynamics` (qdd without M): the consistent qdd(0) and the first-step
///   heuristic's trial evaluation; BDF itself evaluates τ, and M once per accepted step to
///   watch for a singular configuration (its finite-difference iteration matrices do not
///   evaluate M), plus once at the start, the watch's reference.
/// - τ: one per Newton iteration, plus n + 1 = 3 per finite-difference iteration matrix:
///   inverse_dynamics = newton_iterations + 3·factorizations; solves = newton_iterations.
/// - 693 attempts (631 accepted, 62 rejected), 746 Newton iterations (1.1 per attempt),
///   103 iteration matrices (1055 τ = 746 + 3·103): a matrix is rebuilt when c = h/γ_k
///   moves by more than 20 % or convergence slows. 1689 evaluations in all, 2.7 per accepted
///   step (1055 of τ, 632 of M and 2 forward-dynamics solves).
/// - Rejections (~10 % of attempts) are the quasi-constant-step formulation's: h changes only
///   after k + 1 steps at constant h or on a rejection, so when the error grows within those
///   steps (bars swinging through the bottom), the step is rejected instead of shrunk ahead.
/// - Orders: 2 steps at order 1 (h ramps from the driver's first step), the lower orders at
///   the start, then order 5.
#[test]
fn work_counters_snapshot() {
    let opts = Options {
        output: Output::Last,
        energy: false,
        ..Options::adaptive(2.0, 1e-6)
    };
    let (_, st) = simulate(DoublePendulum::default(), bdf(5), opts).unwrap();
    println!("{st}");
    // the start and the initial-step probe solve by forward dynamics, without M; M is
    // evaluated and factorised once at the start (the singularity watch's reference), then
    // once per accepted step
    assert_eq!((st.dynamics, st.forward_dynamics), (0, 2));
    assert_eq!(st.tangents, 0);
    assert_eq!(
        (st.mass_matrix, st.condition_checks),
        (st.steps + 1, st.steps + 1)
    );
    assert_eq!(
        st.inverse_dynamics,
        st.newton_iterations + 3 * st.factorizations
    );
    assert_eq!(st.solves, st.newton_iterations);
    let got = (
        st.steps,
        st.rejected_error,
        st.rejected_newton,
        st.newton_iterations,
        st.factorizations,
        st.evaluations(),
        st.order_steps.clone(),
    );
    // (steps, rejected by the error test, by Newton, Newton iterations, factorisations,
    // evaluations, steps per order)
    assert_eq!(
        got,
        (631, 62, 0, 746, 103, 1689, vec![2, 19, 4, 45, 561]),
        "{st}"
    );
    quoted::says(
        "README.md",
        &[format!(
            "{} beside {} τ for BDF",
            quoted::thousands(st.mass_matrix),
            quoted::thousands(st.inverse_dynamics)
        )],
    );
}

/// The order history is recorded, climbs from 1, and the top order carries the run.
#[test]
fn order_history_is_recorded() {
    let opts = Options {
        output: Output::Last,
        energy: false,
        ..Options::adaptive(5.0, 1e-8)
    };
    let (_, st) = simulate(DoublePendulum::default(), bdf(5), opts).unwrap();
    println!("{st}");
    assert_eq!(st.order_steps.len(), 5, "{:?}", st.order_steps);
    assert_eq!(st.order_steps.iter().sum::<usize>(), st.steps);
    assert!(st.order_steps[0] >= 1, "starts at order 1");
    assert!(
        st.order_steps[4] * 10 >= st.steps * 9,
        "mostly order 5: {:?}",
        st.order_steps
    );
    // max_order caps it
    let opts = Options {
        output: Output::Last,
        energy: false,
        ..Options::adaptive(5.0, 1e-8)
    };
    let (_, st) = simulate(DoublePendulum::default(), bdf(3), opts).unwrap();
    assert_eq!(st.order_steps.len(), 3, "{:?}", st.order_steps);
    assert!(
        st.order_steps[2] * 10 >= st.steps * 9,
        "{:?}",
        st.order_steps
    );
}

/// Fixed steps: the order rises by one per step (step s at order min(s, k)), without error
/// test. The first steps, at orders 1.., leave an O(h²) error that the later ones carry: the
/// observed order of fixed-step BDF3–5 is 2 (measured 2.0), BDF2 2 as well; fixed-step BDF
/// works, but its orders above 2 pay off only with adaptive steps.
#[test]
fn fixed_steps_ramp_the_order() {
    let t2 = 2.0 * std::f64::consts::PI / seed2dof_modes().0[1];
    for k in [2, 5] {
        let hs = [t2 / 40.0, t2 / 80.0, t2 / 160.0, t2 / 320.0];
        let mut errs = Vec::new();
        for &h in &hs {
            let opts = Options {
                output: Output::Every { dt: 0.02 },
                energy: false,
                ..Options::fixed(1.0, h)
            };
            let (tr, st) = simulate(Seed2dof::default(), bdf(k), opts).unwrap();
            let mut ramp = vec![1; k - 1];
            ramp.push(st.steps - (k - 1));
            assert_eq!(st.order_steps, ramp);
            assert_eq!(st.rejected_error + st.rejected_newton, 0);
            errs.push(seed2dof_max_error(&tr));
        }
        let p = loglog_slope(&hs, &errs);
        println!("fixed BDF{k}: errors {} → order {p:.2}", sci(&errs));
        assert!((p - 2.0).abs() <= 0.3, "BDF{k} fixed: order {p:.2}");
    }
}
