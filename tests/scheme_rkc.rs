//! Runge–Kutta–Chebyshev (`Scheme::Rkc`): order 2, a stability interval that grows as the
//! square of its stages, so that fast decaying modes cost the square root of their
//! stiffness; refused, typed, where its region does not reach (undamped stiff oscillation, an
//! oscillation behind a faster decaying mode); adaptive steps that follow rtol.
//!
//! `cargo test --release --test scheme_rkc -- --nocapture` prints the figures.

#[path = "common/quoted.rs"]
mod quoted;

use mbs::{Failure, Model, Options, Output, Scheme, simulate};
use mbs_models::damped_chain::DampedChain;
use mbs_models::{chain16_stiff, dpend};

mbs::multibody! {
    /// Two independent sliders: x with a damper (λ = −1e4 1/s), y on a spring (ω = 3,000
    /// rad/s, undamped). The oscillation is slower than the decay, so a power iteration on J
    /// finds only the decay; RKC's region, narrow across the real axis, does not hold
    /// hω = 3.
    pub model Hidden {
        param c = 1e4; param k = 9e6;
        dof x = 0.0; dof y = 1e-3;
        body a { mass = 1.0; }
        body b { mass = 1.0; }
        TOG[a] = Tdisp(x, 0, 0);
        TOG[b] = Tdisp(0, y, 0);
        generalized_force(x, -c * qd[0]);
        generalized_force(y, -k * q[1]);
    }
}

/// The largest difference of q and qd at t_end between two runs.
fn difference(a: &mbs::Trajectory, b: &mbs::Trajectory) -> f64 {
    let (i, j) = (a.len() - 1, b.len() - 1);
    a.q(i)
        .iter()
        .zip(b.q(j))
        .chain(a.qd(i).iter().zip(b.qd(j)))
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn last_only(mut o: Options) -> Options {
    o.output = Output::Last;
    o
}

/// The advised step of RKC's refusal `e`.
fn refused(e: &mbs::SimError) -> f64 {
    match e.kind {
        Failure::UnstableStep {
            scheme: "RKC",
            h_stable,
            ..
        } => h_stable,
        ref other => panic!("{other}"),
    }
}

/// The double pendulum at t_end by DOPRI5 at `rtol`.
fn dpend_reference(t_end: f64, rtol: f64) -> mbs::Trajectory {
    let model = dpend::DoublePendulum::default();
    let o = last_only(Options::adaptive(t_end, rtol));
    simulate(model, Scheme::Dopri5, o).unwrap().0
}

#[test]
fn order_two_on_the_double_pendulum() {
    let t_end = 1.0;
    let reference = dpend_reference(t_end, 1e-12);
    let errors: Vec<f64> = [4e-3, 2e-3, 1e-3]
        .iter()
        .map(|&h| {
            let (tr, _) = simulate(
                dpend::DoublePendulum::default(),
                Scheme::Rkc,
                last_only(Options::fixed(t_end, h)),
            )
            .unwrap();
            difference(&tr, &reference)
        })
        .collect();
    let orders: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect();
    println!("dpend, RKC at h = 4, 2, 1 ms: errors {errors:?}, observed orders {orders:?}");
    for p in orders {
        assert!((1.8..2.3).contains(&p), "order {p}");
    }
}

#[test]
fn fast_decay_costs_the_square_root_of_its_stiffness() {
    let t_end = 1.0;
    let h = 0.01;
    let (reference, _) = simulate(
        DampedChain::default(),
        Scheme::Radau5,
        last_only(Options::adaptive(t_end, 1e-10)),
    )
    .unwrap();
    // RK4 is refused at this step, naming the fastest mode
    let e = simulate(
        DampedChain::default(),
        Scheme::Rk4,
        last_only(Options::fixed(t_end, h)),
    )
    .unwrap_err();
    let Failure::UnstableStep { rho, .. } = e.kind else {
        panic!("{e}")
    };
    assert!(rho * h > 2.785, "{rho}");
    // RKC takes it with stages growing as √(hρ)
    let (tr, stats) = simulate(
        DampedChain::default(),
        Scheme::Rkc,
        last_only(Options::fixed(t_end, h)),
    )
    .unwrap();
    let per_step = stats.evaluations() as f64 / stats.steps as f64;
    let err = difference(&tr, &reference);
    // RK4 at a step it accepts
    let (tr4, stats4) = simulate(
        DampedChain::default(),
        Scheme::Rk4,
        last_only(Options::fixed(t_end, 2.5 / rho)),
    )
    .unwrap();
    println!(
        "damped chain, ρ ≈ {rho:.0} 1/s (hρ = {:.1} at h = {h}): RKC {} steps, {:.1} evaluations a step, {} in all, error {err:.2e}; RK4 at h = 2.5/ρ: {} evaluations, error {:.2e}",
        rho * h,
        stats.steps,
        per_step,
        stats.evaluations(),
        stats4.evaluations(),
        difference(&tr4, &reference)
    );
    // stages: the least s with β(s) ≈ 0.53 s² ≥ 1.5 hρ, plus the estimates of the modes
    let stages = (1.5 * rho * h / 0.5).sqrt() + 1.0;
    assert!(per_step <= stages + 1.5, "{per_step} against {stages}");
    assert!(stats.evaluations() * 3 < stats4.evaluations());
    assert!(err < 1e-3, "{err}");
    quoted::says(
        "README.md",
        &[format!(
            "dampedchain (2 s, self-computed; a damper in every joint, decaying modes to {rho:.1e} 1/s)"
        )],
    );
}

#[test]
fn an_undamped_stiff_oscillation_is_refused() {
    // chain16_stiff's joint springs: modes to about 1e5 rad/s, undamped
    let e = simulate(
        chain16_stiff::Chain16Stiff::default(),
        Scheme::Rkc,
        Options::fixed(0.1, 1e-4),
    )
    .unwrap_err();
    let h_stable = refused(&e);
    assert_eq!(e.t, 0.0, "refused at the first step");
    assert!(h_stable < 1e-4);
    assert!(e.to_string().contains("take h <"), "{e}");
    // the advised step runs
    simulate(
        chain16_stiff::Chain16Stiff::default(),
        Scheme::Rkc,
        last_only(Options::fixed(1e-3, 0.9 * h_stable)),
    )
    .unwrap();
}

#[test]
fn an_oscillation_behind_a_faster_decay_is_seen() {
    // hλ = −10 for the damper, hω = 3 for the spring: without the second estimate the stages
    // would be chosen for the damper alone and the spring's amplitude would grow
    let e = simulate(Hidden::default(), Scheme::Rkc, Options::fixed(0.1, 1e-3)).unwrap_err();
    let h_stable = refused(&e);
    assert_eq!(e.t, 0.0, "refused at the first step");
    // near the imaginary axis the region's half-width is 0.30–0.38: h below 0.38/ω
    assert!(h_stable * 3000.0 < 0.38, "{h_stable}");
    // at the advised step the spring's amplitude grows by at most 1 % a period
    let h = h_stable;
    let (tr, _) = simulate(
        Hidden::default(),
        Scheme::Rkc,
        Options::fixed(1000.0 * h, h),
    )
    .unwrap();
    let energy = |i: usize| 0.5 * tr.qd(i)[1].powi(2) + 0.5 * 9e6 * tr.q(i)[1].powi(2);
    let (e0, e1) = (energy(0), energy(tr.len() - 1));
    let periods = 1000.0 * h * 3000.0 / (2.0 * std::f64::consts::PI);
    let growth = (e1 / e0).powf(0.5 / periods) - 1.0;
    println!(
        "hidden oscillation: refused at h = 1 ms, h_stable {h_stable:.3e} s (hω = {:.3}); energy {e0:.4e} → {e1:.4e} over {periods:.0} periods: amplitude {:+.3} % a period",
        3000.0 * h_stable,
        100.0 * growth
    );
    assert!(growth < 0.0101, "{growth}");
    // with the check off the step is taken, with the most stages
    let unchecked = Options {
        stability_check: false,
        ..Options::fixed(0.01, 1e-3)
    };
    let (_, stats) = simulate(Hidden::default(), Scheme::Rkc, unchecked).unwrap();
    assert!(stats.evaluations() > 200 * stats.steps, "{stats:?}");
}

#[test]
fn adaptive_steps_follow_rtol() {
    let t_end = 2.0;
    let reference = dpend_reference(t_end, 1e-13);
    let mut last = f64::INFINITY;
    for rtol in [1e-4, 1e-5, 1e-6, 1e-7, 1e-8] {
        let (tr, stats) = simulate(
            dpend::DoublePendulum::default(),
            Scheme::Rkc,
            last_only(Options::adaptive(t_end, rtol)),
        )
        .unwrap();
        let err = difference(&tr, &reference);
        let digits = -err.log10();
        println!(
            "dpend, RKC rtol {rtol:.0e}: error {err:.2e} ({digits:.2} digits), {} steps, {} rejected, {} evaluations",
            stats.steps,
            stats.rejected_error,
            stats.evaluations()
        );
        assert!((digits + rtol.log10()).abs() < 1.5, "rtol {rtol}: {err}");
        assert!(err < last * 10f64.powf(0.2), "{err} after {last}");
        last = err;
    }
    // on the damped chain DOPRI5's steps are held by its fast modes (3.3/ρ ≈ 1 ms), RKC's
    // by accuracy
    let (_, stats) = simulate(
        DampedChain::default(),
        Scheme::Rkc,
        last_only(Options::adaptive(1.0, 1e-3)),
    )
    .unwrap();
    let (_, dopri) = simulate(
        DampedChain::default(),
        Scheme::Dopri5,
        last_only(Options::adaptive(1.0, 1e-3)),
    )
    .unwrap();
    println!(
        "damped chain, rtol 1e-3: RKC {} steps, {} evaluations; DOPRI5 {} steps, {} evaluations",
        stats.steps,
        stats.evaluations(),
        dopri.steps,
        dopri.evaluations()
    );
    assert!(stats.steps * 2 < dopri.steps && stats.evaluations() * 2 < dopri.evaluations());
    assert_eq!(DampedChain::NQ, 6);
}

/// Fastlink released into its spring's push is a saddle (ρ ≈ 807 1/s), whose sign the estimate
/// of the fastest mode does not always read: at a fixed step of 30 ms or 0.1 s RKC's stages
/// grew as Chebyshev polynomials do on the positive axis and went non-finite within the first
/// step ("generalized force h of coordinate q[0] is not finite"). The step is now refused as
/// outgrowing that mode, with the advised step, and the start kept. At the advised step the
/// run takes two steps and is refused again, the spring's push having made a mode of about
/// 1e9 1/s (an adaptive scheme is what this motion needs).
#[test]
fn a_step_that_outgrows_a_growing_mode_is_refused() {
    use mbs::ConstraintMethod;
    use mbs_models::fastlink::FastLink;
    // ρ and the limit of the first refusal, as the README quotes them
    let mut first = None;
    for method in [ConstraintMethod::Auto, ConstraintMethod::Projection] {
        for h in [0.03, 0.1] {
            let mut o = Options::fixed(0.1, h);
            o.constraints.method = method;
            let e = simulate(FastLink::default(), Scheme::Rkc, o).unwrap_err();
            println!("{method:?}, h = {h}: {e}");
            let Failure::UnstableStep {
                rho, h_rho, limit, ..
            } = e.kind
            else {
                panic!("{e}")
            };
            first.get_or_insert((rho, limit));
            assert!((700.0..900.0).contains(&rho), "{rho}");
            assert!((h_rho - h * rho).abs() < 1e-9 * h_rho);
            assert_eq!(e.trajectory.len(), 1, "the start kept");
            let advised = refused(&e);
            let mut o = Options::fixed(0.03, advised);
            o.constraints.method = method;
            // it runs, or is refused again where the motion outgrows it (never non-finite)
            match simulate(FastLink::default(), Scheme::Rkc, o) {
                Ok((tr, _)) => println!(
                    "  at the advised {advised:.3e} s: to t = {}",
                    tr.t.last().unwrap()
                ),
                Err(e) => {
                    println!("  at the advised {advised:.3e} s: {e}");
                    assert!(matches!(e.kind, Failure::UnstableStep { .. }), "{e}");
                }
            }
        }
    }
    let (rho, limit) = first.expect("refused");
    quoted::says(
        "README.md",
        &[format!(
            "a fixed step whose stages go non-finite past h·ρ = {limit:.2} is refused as outgrowing \
             a growing mode (fastlink released into its spring, a saddle whose sign the estimate \
             misreads, ρ ≈ {rho:.0} 1/s: at 30 ms and 0.1 s it ended with"
        )],
    );
}
