//! BDF on an undamped stiff oscillation (`mbs-runtime/src/integrators/bdf.rs`, its module notes
//! on stability limits): chain30_stiff, 30 bars of 10 g joined by torsional springs of
//! 5000 N·m/rad without damping, swinging for 2 s. Its undamped modes run from the swing's
//! 4 rad/s to 1.6e5 rad/s; orders 3–5 of BDF are unstable on part of the imaginary axis, and
//! took 45 / 586,920 / 635,988 steps at rtol 1e-4 / 1e-6 / 1e-8 before BDF learnt to keep to
//! order 2 when the fastest undamped mode leaves them no stable step.
//!
//! Measured (`cargo test --release --test bdf_stiff_oscillation -- --nocapture`), mixed error
//! max |y − y_ref| / (1 + |y_ref|) over q and qd at t = 2 s against Radau5 at rtol 1e-11:
//!
//! | rtol | BDF (max order 5) | BDF max order 2 | Radau5 |
//! |---|---|---|---|
//! | 1e-4 | 305 steps, 4.4e-3 | 305, 4.4e-3 | 16, 1.4e-4 |
//! | 1e-6 | 1,622 steps, 1.6e-4 | 1,622, 1.6e-4 | 32, 1.1e-6 |
//! | 1e-8 | 8,114 steps, 6.0e-6 | 8,110, 6.0e-6 | 78, 2.3e-7 |
//!
//! (BDF's error test runs at rtol' = 0.1·rtol^1.25, which makes its error follow rtol like the
//! other schemes'; at the user's rtol itself it took 105 / 472 / 2,437 steps for errors of
//! 4.5e-2 / 2.2e-3 / 8.5e-5.)

use mbs::{BdfParams, Model, Options, Output, Scheme, Stats, simulate};
use mbs_models::chain30_stiff::Chain30Stiff;

#[path = "common/quoted.rs"]
mod quoted;

const T_END: f64 = 2.0;

fn bdf(max_order: usize) -> Scheme {
    Scheme::Bdf(BdfParams { max_order })
}

/// (q, qd) at t_end, and the statistics.
fn run(scheme: Scheme, rtol: f64) -> (Vec<f64>, Stats) {
    let opts = Options {
        output: Output::Last,
        energy: false,
        ..Options::adaptive(T_END, rtol)
    };
    let (tr, st) = simulate(Chain30Stiff::default(), scheme, opts)
        .unwrap_or_else(|e| panic!("{} at rtol {rtol:e}: {e}", scheme.name()));
    let i = tr.len() - 1;
    assert_eq!(tr.t[i], T_END);
    (tr.q(i).iter().chain(tr.qd(i)).copied().collect(), st)
}

/// max |y − y_ref| / (1 + |y_ref|)
fn mixed_error(y: &[f64], reference: &[f64]) -> f64 {
    y.iter()
        .zip(reference)
        .map(|(a, b)| (a - b).abs() / (1.0 + b.abs()))
        .fold(0.0, f64::max)
}

#[test]
fn bdf_keeps_to_order_2_on_an_undamped_stiff_chain() {
    let model = Chain30Stiff::default();
    let (mut q0, mut qd0) = ([0.0; 30], [0.0; 30]);
    model.initial_state(&mut q0, &mut qd0);
    let lin = mbs::linearize(&model, 0.0, &q0, &qd0, &[], mbs::IterationMatrix::Exact).unwrap();
    let modes = mbs::modes(&lin, None).unwrap();
    let w: Vec<f64> = modes
        .modes
        .iter()
        .map(|m| m.frequency_hz * std::f64::consts::TAU)
        .collect();
    let (w_min, w_max) = (
        w.iter().copied().fold(f64::INFINITY, f64::min),
        w.iter().copied().fold(0.0, f64::max),
    );
    println!("chain30_stiff: undamped modes {w_min:.2} … {w_max:.3e} rad/s");
    assert!(w_max > 1e5 && w_min < 5.0);

    let (reference, st) = run(Scheme::Radau5, 1e-11);
    println!("reference: Radau5 at rtol 1e-11, {} steps", st.steps);
    println!(
        "{:>6} {:<8} {:>7} {:>9} {:>22} {:>9}",
        "rtol", "scheme", "steps", "rejected", "steps per order", "error"
    );
    let mut table = Vec::new();
    for rtol in [1e-4, 1e-6, 1e-8] {
        let mut row = Vec::new();
        for (name, scheme) in [
            ("bdf", bdf(5)),
            ("bdf2", bdf(2)),
            ("radau5", Scheme::Radau5),
        ] {
            let (y, st) = run(scheme, rtol);
            let e = mixed_error(&y, &reference);
            println!(
                "{rtol:>6.0e} {name:<8} {:>7} {:>9} {:>22} {e:>9.2e}",
                st.steps,
                st.rejected_error + st.rejected_newton,
                format!("{:?}", st.order_steps),
            );
            row.push((st, e));
        }
        table.push(row);
    }
    // the fastest mode leaves orders 3–5 no stable step: BDF keeps to order 2, and does what
    // BDF capped at order 2 does, within a few steps
    for row in &table {
        let (st, _) = &row[0];
        assert_eq!(st.order_steps.len(), 5, "{:?}", st.order_steps);
        assert_eq!(st.order_steps[2..], [0, 0, 0], "{:?}", st.order_steps);
    }
    // the goals: at rtol 1e-6 at most 2,000 steps, at 1e-8 at most 10,000, with at least
    // order 2's accuracy
    let ((s6, e6), (_, e6_2)) = (&table[1][0], &table[1][1]);
    let ((s8, e8), (_, e8_2)) = (&table[2][0], &table[2][1]);
    assert!(
        s6.steps <= 2_000 && e6 <= e6_2,
        "{} steps, {e6:e}",
        s6.steps
    );
    assert!(
        s8.steps <= 10_000 && e8 <= e8_2,
        "{} steps, {e8:e}",
        s8.steps
    );
    let bdf: Vec<&(Stats, f64)> = table.iter().map(|row| &row[0]).collect();
    quoted::says(
        "README.md",
        &[format!(
            "{} / {} / {} steps (errors {:.1e} / {:.1e} / {:.1e}), no step above order 2",
            quoted::thousands(bdf[0].0.steps),
            quoted::thousands(bdf[1].0.steps),
            quoted::thousands(bdf[2].0.steps),
            bdf[0].1,
            bdf[1].1,
            bdf[2].1
        )],
    );
    // the error falls with the tolerance (order 2 at rtol' = 0.1·rtol^1.25: ×1/27 per 100 in rtol)
    assert!(table[0][0].1 > 10.0 * e6 && *e6 > 10.0 * e8);

    // a snapshot of the work at rtol 1e-6: (steps, rejected by the error test, by Newton,
    // Newton iterations, tangents, steps per order); each of the 25 fresh iteration matrices
    // (one evaluation of the tangents each) gives one estimate of ω_max, at no evaluation
    let st = &table[1][0].0;
    let got = (
        st.steps,
        st.rejected_error,
        st.rejected_newton,
        st.newton_iterations,
        st.tangents,
        st.order_steps.clone(),
    );
    println!("{st}");
    assert_eq!(got, (1622, 6, 0, 1749, 25, vec![2, 1620, 0, 0, 0]), "{st}");
}

/// Where an undamped stiff mode is resolved within BDF5's stable hω ≤ 0.7, the high order
/// stays: springpend at k = 1e8 N/m (ω = 1e4 rad/s) from r = 1 + 9.81/k, whose radial
/// oscillation (1.2e-4 m/s) is far above atol and must be followed, runs at order 5 with h·ω
/// held at 0.7 (20,962 steps; unlimited BDF5 was rejected past it: 23,901) and ends within
/// 6e-9 of the rigid pendulum's θ(1), as before.
#[test]
fn high_orders_stay_where_the_oscillation_is_resolved() {
    use mbs_models::springpend::SpringPend;
    let k = 1e8;
    let mut model = SpringPend::default();
    let mut p = model.params().clone();
    p.k = k;
    model.set_params(p).unwrap();
    let o = Options {
        q0: Some(vec![0.5, 1.0 + 9.81 / k]),
        qd0: Some(vec![0.0, 0.0]),
        output: Output::Last,
        energy: false,
        ..Options::adaptive(1.0, 1e-6)
    };
    let (_, st) = simulate(model, bdf(5), o).unwrap();
    println!("{st}");
    assert!(
        st.order_steps[4] * 10 >= st.steps * 9,
        "{:?}",
        st.order_steps
    );
    // h·ω ≤ 0.7 at order 5 over 90 % of the steps: no fewer than ≈ 0.9·1 s·1e4/0.7 steps;
    // fewer than the 23,901 of unlimited BDF5
    assert!((12_000..23_901).contains(&st.steps), "{}", st.steps);
}

mbs::multibody! {
    /// A pendulum (1 kg at 1 m, from 0.5 rad) beside a 1 kg slider at rest at x = 0 on a spring
    /// of k(t) = 1 + 1e8·exp(−25(t − 1)²) N/m, no damping: the slider stays at 0 exactly, so
    /// accuracy is the pendulum's alone, while the spectrum holds ω = √k(t), 1 rad/s at t = 0
    /// and 2, 1e4 rad/s at t = 1.
    model PendulumBesideStiffening {
        dof theta = 0.5;
        dof x = 0.0;
        option tangents;
        body bob { mass = 1.0; }
        body slider { mass = 1.0; }
        TOG[bob] = Trotz(theta) * Tdisp(0, -1, 0);
        TOG[slider] = Tdisp(x, 0, 0);
        generalized_force(x, -(1.0 + 1e8 * exp(-25.0 * (t - 1.0) * (t - 1.0))) * x);
        gravity(0, -9.81, 0);
    }
}

/// θ(t_end) of the rigid pendulum θ'' = −9.81 sin θ from 0.5 at rest, RK4 at h = 1e-4.
fn pendulum_theta(t_end: f64) -> f64 {
    let f = |th: f64| -9.81 * th.sin();
    let (mut th, mut om, h) = (0.5f64, 0.0f64, 1e-4);
    for _ in 0..(t_end / h).round() as usize {
        let (k1t, k1o) = (om, f(th));
        let (k2t, k2o) = (om + 0.5 * h * k1o, f(th + 0.5 * h * k1t));
        let (k3t, k3o) = (om + 0.5 * h * k2o, f(th + 0.5 * h * k2t));
        let (k4t, k4o) = (om + h * k3o, f(th + h * k3t));
        th += h / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t);
        om += h / 6.0 * (k1o + 2.0 * k2o + 2.0 * k3o + k4o);
    }
    th
}

/// The order follows the spectrum both ways: BDF climbs to order 5 on the pendulum, drops to
/// order 2 when a fresh iteration matrix finds h·ω of the stiffening spring far past BDF5's
/// 0.7, and climbs back to 5 once the spring has softened. Measured: orders
/// [2, 6, 8, 10, 20] to t = 0.5, [4, 816, 12, 15, 51] to t = 2 (the order-2 steps while the
/// spring is stiff, most of the order-5 steps after it); θ is within 1.1e-7 of the rigid
/// pendulum's at t = 0.5 and 1.0e-6 at t = 2. The estimate follows fresh matrices only: the
/// slider holds no motion, so Newton converges with an old matrix and the spectrum is seen
/// stiff late, where k has long been large.
#[test]
fn order_drops_while_a_mode_is_stiff_and_returns() {
    let run = |t_end: f64| {
        let o = Options {
            output: Output::Last,
            energy: false,
            ..Options::adaptive(t_end, 1e-6)
        };
        let (tr, st) = simulate(PendulumBesideStiffening::default(), bdf(5), o).unwrap();
        let q = tr.q(tr.len() - 1);
        assert_eq!(q[1], 0.0);
        let e = (q[0] - pendulum_theta(t_end)).abs();
        println!("to t = {t_end}: {st}\n|θ − θ_ref| = {e:.2e}");
        (st, e)
    };
    let ((b, _), (c, e)) = (run(0.5), run(2.0));
    assert!(b.order_steps[1] <= 10, "{:?}", b.order_steps);
    assert!(c.order_steps[1] >= 100, "{:?}", c.order_steps);
    assert!(
        c.order_steps[4] >= b.order_steps[4] + 10,
        "{:?} {:?}",
        b.order_steps,
        c.order_steps
    );
    assert!(e < 2e-5, "{e:e}");
}
