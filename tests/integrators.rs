//! Integrators on the canonical models: observed orders, failures as values, outputs.

mod common;
#[path = "common/quoted.rs"]
mod quoted;
#[path = "common/sweeps.rs"]
mod sweeps;
use mbs::analysis::{StaticsOptions, static_equilibrium};
use mbs_models::chain8::Chain8;
use mbs_models::seed2dof;
use mbs_models::sprung_arm::SprungArm;

use common::*;
use mbs::{GenAlphaParams, HhtParams, NewmarkParams, Options, Output, Scheme, simulate};
use seed2dof::Seed2dof;

/// Period of the 10 Hz mode.
fn t2() -> f64 {
    2.0 * std::f64::consts::PI / seed2dof_modes().0[1]
}

fn fixed_run(scheme: Scheme, h: f64, t_end: f64) -> f64 {
    let opts = Options {
        output: Output::Every { dt: t_end / 50.0 },
        energy: false,
        ..Options::fixed(t_end, h)
    };
    let (tr, _) = simulate(Seed2dof::default(), scheme, opts).unwrap();
    seed2dof_max_error(&tr)
}

/// Observed order by halving h three times: the log–log slope of error against h.
fn observed_order(scheme: Scheme, h0: f64, t_end: f64) -> f64 {
    let hs: Vec<f64> = (0..4).map(|k| h0 / 2f64.powi(k)).collect();
    let errs: Vec<f64> = hs.iter().map(|&h| fixed_run(scheme, h, t_end)).collect();
    let p = loglog_slope(&hs, &errs);
    println!("{:<10} errors {errs:.3?} → order {p:.2}", scheme.name());
    p
}

#[test]
fn fixed_step_orders_on_seed2dof() {
    let t2 = t2();
    let cases = [
        (Scheme::ExplicitEuler, t2 / 2000.0, 0.2),
        (Scheme::Rk4, t2 / 40.0, 1.0),
        (Scheme::Rkc, t2 / 40.0, 1.0),
        (Scheme::Dopri5, t2 / 20.0, 1.0),
        (Scheme::Newmark(NewmarkParams::default()), t2 / 40.0, 1.0),
        (Scheme::Hht(HhtParams { alpha: -0.1 }), t2 / 40.0, 1.0),
        (
            Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8)),
            t2 / 40.0,
            1.0,
        ),
        (Scheme::ImplicitMidpoint, t2 / 40.0, 1.0),
    ];
    for (scheme, h0, t_end) in cases {
        let p = observed_order(scheme, h0, t_end);
        let theory = scheme.order() as f64;
        assert!(
            (p - theory).abs() <= 0.3,
            "{}: observed order {p:.2}, theory {theory}",
            scheme.name()
        );
    }
}

/// Error against the number of steps when tightening rtol: slope ≈ −order.
fn adaptive_slope(scheme: Scheme, rtols: &[f64]) -> f64 {
    let mut steps = Vec::new();
    let mut errs = Vec::new();
    for &rtol in rtols {
        let opts = Options {
            output: Output::Every { dt: 0.02 },
            energy: false,
            ..Options::adaptive(1.0, rtol)
        };
        let (tr, st) = simulate(Seed2dof::default(), scheme, opts).unwrap();
        steps.push(st.steps as f64);
        errs.push(seed2dof_max_error(&tr));
    }
    let p = -loglog_slope(&steps, &errs);
    println!(
        "{:<10} steps {steps:?} errors {errs:.3?} → order {p:.2}",
        scheme.name()
    );
    p
}

#[test]
fn adaptive_orders_on_seed2dof() {
    for (scheme, rtols) in [
        (Scheme::Dopri5, [1e-5, 1e-6, 1e-7, 1e-8]),
        (
            Scheme::Newmark(NewmarkParams::default()),
            [1e-4, 1e-5, 1e-6, 1e-7],
        ),
        (
            Scheme::GenAlpha(GenAlphaParams::default()),
            [1e-4, 1e-5, 1e-6, 1e-7],
        ),
        (Scheme::Hht(HhtParams::default()), [1e-4, 1e-5, 1e-6, 1e-7]),
    ] {
        let p = adaptive_slope(scheme, &rtols);
        let theory = scheme.order() as f64;
        assert!(
            (p - theory).abs() <= 0.3,
            "{}: observed order {p:.2} vs {theory}",
            scheme.name()
        );
    }
}

mbs::multibody! {
    /// dpend with generated tangents, for the iteration-matrix variants.
    pub model DoublePendulumTangents {
        param l = 1.0; param m = 1.0; param g = 9.81;
        dof q[0] = PI / 2; dof q[1] = 0.0;
        body bar1 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar2 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        TOG[bar1] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l/2, 0) * Trotz(q[1]) * Tdisp(0, -l/2, 0);
        gravity(0, -9.81 * g / 9.81, 0);
        option tangents;
    }
}

/// Newton to 1e-12: M alone converges linearly, and at the default 1e-10 its solutions stop
/// ~1e-9 from the exact-matrix ones per step (2e-6 after 1000 steps of dpend).
const NEWTON_TOL: f64 = 1e-12;

#[test]
fn iteration_matrices_exact_finite_differences_and_mass_only() {
    use mbs::IterationMatrix;
    let run = |im: IterationMatrix| {
        // fixed steps: the same step sequence, so results differ only by Newton's tolerance
        let newton = mbs::NewtonOptions {
            atol: NEWTON_TOL,
            rtol: NEWTON_TOL,
            ..Default::default()
        };
        let opts = Options {
            iteration_matrix: im,
            newton,
            output: Output::Last,
            energy: false,
            ..Options::fixed(2.0, 2e-3)
        };
        simulate(
            DoublePendulumTangents::default(),
            Scheme::Newmark(NewmarkParams::default()),
            opts,
        )
        .unwrap()
    };
    let (exact, se) = run(IterationMatrix::Exact);
    let (fd, sf) = run(IterationMatrix::FiniteDifferences);
    let (mass, sm) = run(IterationMatrix::MassOnly);
    let (auto, sa) = run(IterationMatrix::Auto);
    // Auto uses the generated tangents; finite differences spend τ evaluations instead
    assert!(se.tangents > 0 && sf.tangents == 0 && sm.tangents == 0);
    assert_eq!(sa, se);
    assert!(sf.inverse_dynamics > se.inverse_dynamics);
    // all converge to the same motion
    for tr in [&fd, &mass, &auto] {
        let d = tr
            .q(0)
            .iter()
            .zip(exact.q(0))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(d < 1e-8, "{d:e}");
    }
    // M alone is an approximation: more Newton iterations per step
    let per_step = |s: &mbs::Stats| s.newton_iterations as f64 / s.steps as f64;
    assert!(
        per_step(&sm) > per_step(&se),
        "{} vs {}",
        per_step(&sm),
        per_step(&se)
    );
}

#[test]
fn outputs_at_chosen_times_observers_and_frames() {
    use std::sync::{Arc, Mutex};
    let times: Vec<f64> = (0..40).map(|k| 0.0123 + 0.0247 * k as f64).collect();
    for scheme in [
        Scheme::Dopri5,
        Scheme::Radau5,
        Scheme::Bdf(mbs::BdfParams::default()),
        Scheme::GenAlpha(GenAlphaParams::default()),
    ] {
        let opts = Options {
            output: Output::Times(times.clone()),
            frames: true,
            ..Options::adaptive(1.0, 1e-9)
        };
        let mut sim = mbs::Simulation::new(Seed2dof::default(), scheme, opts).unwrap();
        let seen = Arc::new(Mutex::new(Vec::new()));
        let sink = seen.clone();
        sim.observe(move |t: f64, q: &[f64], _: &[f64], _: &[f64]| {
            sink.lock().unwrap().push((t, q[1]))
        });
        mbs::Integrator::integrate_to(&mut sim, 1.0).unwrap();
        let (tr, _) = sim.finish();
        // exactly the chosen times, interpolated between steps as accurately as the steps
        assert_eq!(tr.t, times);
        let err = seed2dof_max_error(&tr);
        assert!(
            err < if scheme.order() >= 5 { 1e-6 } else { 1e-4 },
            "{}: {err:e}",
            scheme.name()
        );
        // observers see every output as it is recorded
        let seen = seen.lock().unwrap();
        assert_eq!(seen.len(), tr.len());
        assert!(
            seen.iter()
                .enumerate()
                .all(|(i, &(t, q1))| t == tr.t[i] && q1 == tr.q(i)[1])
        );
        // poses of both masses on request: mass 2 sits at x = 2 + q1
        assert_eq!(tr.poses.len(), 2 * tr.len());
        let p = tr.poses_at(7)[1].position[0];
        assert!((p - 2.0 - tr.q(7)[1]).abs() < 1e-12);
    }
}

/// A fixed step's Newton iteration on accelerations (the Newmark family and the midpoint
/// rule) converges as far in any units. Without an error tolerance to follow, its absolute
/// weights are the smaller of `newton.atol` and `newton.rtol` times the largest value of each
/// kind the step handles: the 8-bar chain 10⁶ times longer (its velocities 10³ times slower)
/// at the same dimensionless step ends within 2.1e-7 rad of a unit chain whose Newton
/// converges to 1e-15 (asserted 1e-6), where with atol = 1e-10 alone it ended 1.0–1.1e-4 rad
/// off. Radau, whose Newton weighs its stages by atol (Radau3 2.4e-7 off, Radau5 8e-7,
/// asserted 2e-6), is not changed. And a step from a static equilibrium at rest, whose velocities and accelerations
/// are rounding errors, converges at what it resolves when that is within atol itself: the
/// sprung arm so started stays at rest for 1 s, where it stopped in Newton at t = 0.
#[test]
fn a_fixed_step_s_newton_converges_as_far_in_any_units() {
    let run = |s: f64, scheme: Scheme, tight: bool| {
        let model = sweeps::with_params(Chain8::default(), &[("l", 0.5 * s)]);
        let mut o = Options {
            energy: false,
            output: Output::Every { dt: s.sqrt() },
            ..Options::fixed(2.0 * s.sqrt(), 1e-3 * s.sqrt())
        };
        if tight {
            (o.newton.atol, o.newton.rtol, o.newton.max_iterations) = (1e-15, 1e-15, 50);
        }
        let (tr, _) = simulate(model, scheme, o).unwrap();
        tr.q(tr.len() - 1).to_vec()
    };
    // distances from the converged unit chain: (× 10⁶, × 1) for the Newmark family and the
    // midpoint rule, × 10⁶ for Radau3 and Radau5
    let (mut large, mut unit_off, mut radau) = (Vec::new(), Vec::new(), Vec::new());
    for name in [
        "newmark",
        "hht",
        "gen-alpha",
        "midpoint",
        "radau3",
        "radau5",
    ] {
        let scheme = Scheme::from_name(name).unwrap();
        // from the sprung arm's static equilibrium, at rest
        let arm = SprungArm::default();
        let eq = static_equilibrium(&arm, &StaticsOptions::default()).unwrap();
        let o = Options {
            q0: Some(eq.q.clone()),
            qd0: Some(vec![0.0; eq.q.len()]),
            energy: false,
            ..Options::fixed(1.0, 1e-3)
        };
        let (tr, _) = simulate(arm, scheme, o).unwrap_or_else(|e| panic!("{name} at rest: {e}"));
        let moved = (0..tr.len())
            .flat_map(|k| tr.qd(k).to_vec())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        println!("{name:<10} from the sprung arm's equilibrium: |qd| ≤ {moved:.1e} rad/s");
        assert!(moved < 1e-9, "{name}: {moved:e}");
        let unit = run(1.0, scheme, true);
        for s in [1e-6, 1.0, 1e6] {
            let q = run(s, scheme, false);
            let off = (q.iter().zip(&unit)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            println!("{name:<10} × {s:e}: {off:.1e} rad from the converged unit chain");
            // Radau's weights keep atol
            let bound = if name.starts_with("radau") {
                2e-6
            } else {
                1e-6
            };
            assert!(off < bound, "{name} × {s:e}: {off:e}");
            if name.starts_with("radau") {
                if s == 1e6 {
                    radau.push(off);
                }
            } else if s == 1e6 {
                large.push(off);
            } else if s == 1.0 {
                unit_off.push(off);
            }
        }
    }
    quoted::says(
        "README.md",
        &[format!(
            "now {}, like the unit chain's {}; Radau's Newton weighs its stages by atol, {} and {} \
             off there",
            range(&large),
            range(&unit_off),
            short(radau[0]),
            short(radau[1])
        )],
    );
}

/// `x` as the README writes it: two digits, "8e-7" for 8.0e-7.
fn short(x: f64) -> String {
    format!("{x:.1e}").replace(".0e", "e")
}

/// The range of `v` as the README writes it: "1.4–2.1e-7" (one exponent when both share it,
/// one figure when both ends print alike).
fn range(v: &[f64]) -> String {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(0.0, f64::max);
    let (lo, hi) = (format!("{lo:.1e}"), format!("{hi:.1e}"));
    if lo == hi {
        return lo;
    }
    match (lo.split_once('e'), hi.split_once('e')) {
        (Some((m, e)), Some((_, f))) if e == f => format!("{m}–{hi}"),
        _ => format!("{lo}–{hi}"),
    }
}
