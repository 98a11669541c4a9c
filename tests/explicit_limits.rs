//! Explicit schemes know their limits: past them they stop with a typed error that says what
//! to do, before any non-finite value, rather than return a wrong trajectory.

#[path = "common/quoted.rs"]
mod quoted;

use mbs_models::{dpend, seed2dof};

use mbs::{Failure, Options, Output, Scheme, simulate};

mbs::multibody! {
    /// A 1 kg point mass on a 1 m massless rod, started at 0.5 rad: E = −8.6 J.
    pub model Pendulum {
        dof theta = 0.5;
        body bob { mass = 1.0; }
        TOG[bob] = Trotz(theta) * Tdisp(0, -1, 0);
        gravity(0, -9.81, 0);
    }
}

fn all_finite(tr: &mbs::Trajectory) -> bool {
    tr.q_data
        .iter()
        .chain(&tr.qd_data)
        .chain(&tr.qdd_data)
        .all(|x| x.is_finite())
}

#[test]
fn euler_refuses_a_step_that_pumps_energy_into_an_oscillation() {
    // h = 0.5 s on ω ≈ 3.1 rad/s: once ran to the end with E rising from −8.6 J to +29.7 J
    let e = simulate(
        Pendulum::default(),
        Scheme::ExplicitEuler,
        Options::fixed(10.0, 0.5),
    )
    .unwrap_err();
    let Failure::UnstableStep {
        scheme,
        rho,
        h_stable,
        limit,
        ..
    } = e.kind
    else {
        panic!("{e}")
    };
    assert_eq!(scheme, "explicit Euler");
    assert_eq!(e.t, 0.0, "refused at the first step");
    // ω² = g cos(0.5) at the start
    let omega = (9.81 * 0.5f64.cos()).sqrt();
    assert!((rho - omega).abs() < 1e-3 * omega, "{rho} {omega}");
    assert!((limit - 0.226).abs() < 1e-9 && (h_stable - 0.226 / omega).abs() < 1e-6);
    let text = e.to_string();
    assert!(
        text.contains("explicit Euler") && text.contains("take h <"),
        "{text}"
    );
    quoted::says(
        "README.md",
        &[format!(
            "explicit Euler | `euler` | 1 | unstable on undamped oscillations: refused past ωh = \
             {limit:.3} (amplitude ×2 a period)"
        )],
    );

    // the advised step runs, and the energy stays within a factor 2 of its start over a period
    let h = 0.9 * h_stable;
    let (tr, _) = simulate(
        Pendulum::default(),
        Scheme::ExplicitEuler,
        Options::fixed(2.0, h),
    )
    .unwrap();
    let e0 = tr.energy[0].kinetic + tr.energy[0].potential;
    let e1 = tr.energy.last().map(|e| e.kinetic + e.potential).unwrap();
    println!("h = {h:.4}: E {e0:.3} → {e1:.3} J");
    assert!(e1 < e0 + 0.5 * e0.abs(), "{e0} → {e1}");
    // a step that small by a factor 50 is the scheme's ordinary use
    let (tr, _) = simulate(
        seed2dof::Seed2dof::default(),
        Scheme::ExplicitEuler,
        Options::fixed(1.0, 1e-4),
    )
    .unwrap();
    assert!(all_finite(&tr));
}

#[test]
fn euler_on_a_decaying_mode_keeps_its_real_interval() {
    mbs::multibody! {
        /// An overdamped slider: λ = −99.99 and −0.01 (c = 100, k = 1).
        pub model Overdamped {
            dof x = 1.0;
            body mass { mass = 1.0; }
            TOG[mass] = Tdisp(x, 0, 0);
            spring(ground, mass, k = 1.0, l0 = 0.0, axis = x);
            damper(ground, mass, c = 100.0, axis = x);
        }
    }
    // h λ = −1.9: stable for Euler
    let (tr, _) = simulate(
        Overdamped::default(),
        Scheme::ExplicitEuler,
        Options::fixed(1.0, 0.019),
    )
    .unwrap();
    assert!(all_finite(&tr) && tr.q(0).iter().all(|x| x.abs() <= 1.0));
    // h λ = −2.1: refused with the real interval's limit
    let e = simulate(
        Overdamped::default(),
        Scheme::ExplicitEuler,
        Options::fixed(1.0, 0.021),
    )
    .unwrap_err();
    match e.kind {
        Failure::UnstableStep {
            limit, h_stable, ..
        } => {
            assert_eq!(limit, 2.0);
            assert!((h_stable - 0.02).abs() < 1e-4, "{h_stable}");
            quoted::says(
                "README.md",
                &[format!(
                    "(amplitude ×2 a period), \\|hλ\\| < {limit} on decay (a typed error)"
                )],
            );
        }
        other => panic!("{other}"),
    }
}

#[test]
fn rk4_on_dpend_past_its_limit_stops_before_any_non_finite_value() {
    // dpend starts horizontal, where gravity gives no stiffness: the first check passes, the
    // state swings into the unstable range within a step
    let e = simulate(
        dpend::DoublePendulum::default(),
        Scheme::Rk4,
        Options::fixed(10.0, 1.2),
    )
    .unwrap_err();
    println!("{e}");
    let Failure::UnstableStep { h_rho, limit, .. } = e.kind else {
        panic!("{e}")
    };
    assert!(h_rho > limit);
    assert!(all_finite(&e.trajectory));
}

#[test]
fn dopri5_with_a_fixed_step_past_its_limit_stops_and_below_it_runs() {
    // seed2dof's fast mode, ω₂ ≈ 63 rad/s, at h = 0.5 s: this once ran to the end and
    // returned q ≈ 1e24 as if it were an answer
    let e = simulate(
        seed2dof::Seed2dof::default(),
        Scheme::Dopri5,
        Options::fixed(2.0, 0.5),
    )
    .unwrap_err();
    println!("{e}");
    let Failure::UnstableStep {
        h_rho,
        limit,
        h_stable,
        ..
    } = e.kind
    else {
        panic!("{e}")
    };
    assert!(
        h_rho > limit && limit == 0.997,
        "an oscillating mode: {limit}"
    );
    assert!(all_finite(&e.trajectory));
    // the advised step runs, and the motion stays bounded (|q₂| ≤ 1 exactly)
    let (tr, _) = simulate(
        seed2dof::Seed2dof::default(),
        Scheme::Dopri5,
        Options::fixed(2.0, 0.9 * h_stable),
    )
    .unwrap();
    let q = tr.q(tr.len() - 1)[1];
    assert!(q.is_finite() && q.abs() < 1.01, "{q}");
}

mbs::multibody! {
    /// A slider on a stiff spring with a stiff damper (k = c = 1e4): λ ≈ −1e4 and −1. Once the
    /// fast mode has decayed (a millisecond) the motion is slow, but an explicit scheme's step
    /// stays bound to 1/|λ_fast|.
    pub model StiffSlider {
        dof x = 1.0;
        body mass { mass = 1.0; }
        TOG[mass] = Tdisp(x, 0, 0);
        spring(ground, mass, k = 1e4, l0 = 0.0, axis = x);
        damper(ground, mass, c = 1e4, axis = x);
    }
}

fn quiet(opts: Options) -> Options {
    Options {
        output: Output::Last,
        energy: false,
        ..opts
    }
}

#[test]
fn dopri5_detects_stiffness_and_says_so() {
    // to the end: the run completes, and its statistics say it was stiff
    let (_, stats) = simulate(
        StiffSlider::default(),
        Scheme::Dopri5,
        quiet(Options::adaptive(5.0, 1e-6)),
    )
    .unwrap();
    println!("{stats}");
    let t = stats.stiff_from.expect("detected as stiff");
    assert!(stats.stiff_detections >= 1);
    // the fast mode has decayed within 1 ms; the test needs 15 accepted steps past it
    assert!(t < 0.05, "{t}");
    // held at h·|λ| ≈ 3.3: about 5 s × 1e4 / 3.3 steps
    assert!(stats.steps > 10_000, "{}", stats.steps);
    assert!(stats.to_string().contains("stiff from t = "), "{stats}");

    // with too few steps allowed: a typed failure that names the stiffness and the schemes
    let opts = Options {
        max_steps: 2000,
        ..quiet(Options::adaptive(5.0, 1e-6))
    };
    let e = simulate(StiffSlider::default(), Scheme::Dopri5, opts).unwrap_err();
    let text = e.to_string();
    println!("{text}");
    match e.kind {
        Failure::LikelyStiff {
            scheme,
            t: from,
            max_steps,
            held_most,
        } => {
            assert_eq!((scheme, max_steps), ("dopri5", 2000));
            assert_eq!(from, t, "the same detection as the full run");
            // the error test of the steps is held by the stiff coordinate
            let h = held_most.expect("an error test held the steps");
            assert!(h.component.starts_with("q[0]"), "{text}");
        }
        other => panic!("{other}"),
    }
    assert!(text.contains("radau5") && text.contains("bdf"), "{text}");

    // the advised scheme takes few steps on it
    let (_, radau) = simulate(
        StiffSlider::default(),
        Scheme::Radau5,
        quiet(Options::adaptive(5.0, 1e-6)),
    )
    .unwrap();
    println!(
        "radau5: {} steps, dopri5: {} steps",
        radau.steps, stats.steps
    );
    assert!(radau.steps * 20 < stats.steps);
    assert_eq!(radau.stiff_detections, 0);
}

#[test]
fn dopri5_finds_no_stiffness_on_smooth_problems() {
    for tol in [1e-3, 1e-6, 1e-9] {
        let (_, stats) = simulate(
            dpend::DoublePendulum::default(),
            Scheme::Dopri5,
            quiet(Options::adaptive(10.0, tol)),
        )
        .unwrap();
        assert_eq!((stats.stiff_detections, stats.stiff_from), (0, None));
        assert!(!stats.to_string().contains("stiff"), "{stats}");
        let (_, stats) = simulate(
            seed2dof::Seed2dof::default(),
            Scheme::Dopri5,
            quiet(Options::adaptive(10.0, tol)),
        )
        .unwrap();
        assert_eq!((stats.stiff_detections, stats.stiff_from), (0, None));
    }
    // too few steps on a smooth problem stays TooMuchWork
    let opts = Options {
        max_steps: 20,
        ..quiet(Options::adaptive(10.0, 1e-9))
    };
    let e = simulate(dpend::DoublePendulum::default(), Scheme::Dopri5, opts).unwrap_err();
    assert!(
        matches!(e.kind, Failure::TooMuchWork { max_steps: 20, .. }),
        "{e}"
    );
}

/// A fixed step that is the whole run is checked after it is taken: the double pendulum,
/// released where gravity has no stiffness (ρ ≈ 0 at the start, so the check before the step
/// passes), in one step of 10 s ran to the end with its energy 100 % off and no word under
/// explicit Euler, RK4 and fixed-step DOPRI5. The step changes the state by more than its own
/// size; ρ at its end refuses it, at t = 0 with the start kept, advising a step no larger than
/// a hundredth of it (that end state is one the step blew up).
#[test]
fn a_single_step_over_the_whole_run_is_checked_at_its_end() {
    use mbs_models::dpend::DoublePendulum;
    for scheme in [Scheme::ExplicitEuler, Scheme::Rk4, Scheme::Dopri5] {
        let o = Options {
            output: Output::Steps,
            ..Options::fixed(10.0, 10.0)
        };
        let e = simulate(DoublePendulum::default(), scheme, o).unwrap_err();
        println!("{scheme:?}: {e}");
        let Failure::UnstableStep {
            at_end, h_stable, ..
        } = e.kind
        else {
            panic!("{scheme:?}: {e}")
        };
        assert!(at_end, "{e}");
        assert!(h_stable <= 0.1 + 1e-12, "{e}");
        assert_eq!(e.t, 0.0);
        assert_eq!(e.trajectory.len(), 1, "the start kept");
        assert!(
            e.to_string()
                .contains("changed the state by more than its own size")
        );
        // h·ρ past 10⁶ in three digits of a power of ten, not forty digits
        let text = e.to_string();
        let h_rho = text
            .split("h·ρ = ")
            .nth(1)
            .and_then(|t| t.split(' ').next());
        assert!(h_rho.is_some_and(|x| x.len() < 12), "{text}");
    }
}
