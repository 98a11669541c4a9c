//! Failures are values: typed errors with the trajectory computed so far, never a panic, never
//! a non-finite value in a trajectory.

#[path = "common/quoted.rs"]
mod quoted;

use mbs_models::seed2dof;

use mbs::{
    Failure, GenAlphaParams, HhtParams, Model, NewmarkParams, Options, OutOfSteps, Output, Scheme,
    Simulation, simulate,
};
use mbs_models::undefined_force::LateForce;
use seed2dof::Seed2dof;

mbs::multibody! {
    /// A slider driven through a crank-like sine: its inertia vanishes at q = π/2.
    pub model Degenerate {
        dof q[0] = PI / 2; dof q[1] = 0.0;
        body slider { mass = 1.0; }
        body other { mass = 2.0; }
        TOG[slider] = Tdisp(sin(q[0]), 0, 0);
        TOG[other] = Tdisp(0, q[1], 0);
    }
}

fn all_finite(tr: &mbs::Trajectory) -> bool {
    tr.q_data
        .iter()
        .chain(&tr.qd_data)
        .chain(&tr.qdd_data)
        .all(|x| x.is_finite())
        && tr
            .energy
            .iter()
            .all(|e| e.kinetic.is_finite() && e.potential.is_finite())
}

#[test]
fn rk4_past_its_stability_limit_stops_before_any_non_finite_value() {
    let e = simulate(Seed2dof::default(), Scheme::Rk4, Options::fixed(10.0, 0.2)).unwrap_err();
    assert!(matches!(e.kind, Failure::UnstableStep { .. }), "{e}");
    assert!(all_finite(&e.trajectory));
    // the stability edge h < 2.785/ω₂ of RK4 (2√2/ω₂ on the imaginary axis): 0.044 s runs
    // 1000 periods of the 1 Hz mode, 0.046 s is refused
    let opts = |h| Options {
        output: Output::Last,
        energy: false,
        ..Options::fixed(1000.0, h)
    };
    let (tr, _) = simulate(Seed2dof::default(), Scheme::Rk4, opts(0.044)).unwrap();
    assert!(all_finite(&tr) && tr.q(0)[1].abs() < 2.0);
    let e = simulate(Seed2dof::default(), Scheme::Rk4, opts(0.046)).unwrap_err();
    match e.kind {
        Failure::UnstableStep { h_stable, .. } => {
            assert!((0.044..0.046).contains(&h_stable), "{h_stable}")
        }
        other => panic!("{other}"),
    }
}

#[test]
fn invalid_options_are_named_before_any_work() {
    let cases: Vec<(Scheme, Options, &str)> = vec![
        (
            Scheme::Rk4,
            Options {
                q0: Some(vec![f64::NAN, 0.0]),
                ..Options::fixed(1.0, 0.01)
            },
            "q0",
        ),
        (
            Scheme::Rk4,
            Options {
                t0: 2.0,
                ..Options::fixed(1.0, 0.01)
            },
            "t_end",
        ),
        (Scheme::Rk4, Options::fixed(1.0, -0.01), "h"),
        (Scheme::Dopri5, Options::adaptive(1.0, 1e-16), "rtol"),
        (Scheme::Dopri5, Options::adaptive(1.0, 0.0), "rtol"),
        // a component at zero would have no tolerance (Radau's Newton divided by it)
        (
            Scheme::Radau5,
            Options {
                step: mbs::StepControl::Adaptive {
                    rtol: 1e-6,
                    atol: 0.0,
                    h0: None,
                },
                ..Options::adaptive(1.0, 1e-6)
            },
            "atol",
        ),
        (
            Scheme::GenAlpha(GenAlphaParams::from_rho_inf(1.5)),
            Options::fixed(1.0, 0.01),
            "gen_alpha.rho_inf",
        ),
        (
            Scheme::Hht(HhtParams { alpha: -0.5 }),
            Options::fixed(1.0, 0.01),
            "hht.alpha",
        ),
        (
            Scheme::Newmark(NewmarkParams {
                beta: 0.1,
                gamma: 0.5,
            }),
            Options::fixed(1.0, 0.01),
            "newmark.beta",
        ),
        (
            Scheme::Newmark(NewmarkParams {
                beta: 0.25,
                gamma: 0.4,
            }),
            Options::fixed(1.0, 0.01),
            "newmark.gamma",
        ),
    ];
    for (scheme, opts, name) in cases {
        let e = Simulation::new(Seed2dof::default(), scheme, opts)
            .err()
            .expect("refused");
        match &e.kind {
            Failure::InvalidOption { name: n, .. } => assert_eq!(*n, name, "{e}"),
            other => panic!("{other}"),
        }
        assert_eq!(e.stats.evaluations(), 0, "nothing was evaluated");
    }
    // parameters are validated too
    let mut model = Seed2dof::default();
    let mut p = model.params().clone();
    p.m1 = f64::NAN;
    assert!(model.set_params(p).is_err());
}

#[test]
fn a_model_that_returns_nan_stops_every_scheme_near_the_time_it_starts() {
    for scheme in Scheme::all() {
        let mut modes = vec![Options::fixed(2.0, 0.01)];
        if scheme.is_adaptive() {
            modes.push(Options::adaptive(2.0, 1e-6));
        }
        for opts in modes {
            let e = simulate(LateForce::default(), scheme, opts).unwrap_err();
            match &e.kind {
                Failure::NonFinite { coordinate, .. } => {
                    assert_eq!(coordinate, "q[0] (theta)", "{}: {e}", scheme.name())
                }
                other => panic!("{}: {other}", scheme.name()),
            }
            assert!(
                (0.45..=0.5).contains(&e.t),
                "{}: stopped at t = {}",
                scheme.name(),
                e.t
            );
            assert!(
                all_finite(&e.trajectory) && !e.trajectory.is_empty(),
                "{}",
                scheme.name()
            );
        }
    }
}

#[test]
fn a_singular_mass_matrix_is_named_by_its_coordinate() {
    let e = Simulation::new(
        Degenerate::default(),
        Scheme::Dopri5,
        Options::adaptive(1.0, 1e-6),
    )
    .err()
    .unwrap();
    match e.kind {
        Failure::SingularMatrix { coordinates, .. } => {
            assert_eq!(coordinates, vec!["q[0]".to_string()])
        }
        other => panic!("{other}"),
    }
}

#[test]
fn work_limits_are_typed_errors() {
    let o = Options {
        max_steps: 50,
        ..Options::adaptive(10.0, 1e-8)
    };
    let e = simulate(Seed2dof::default(), Scheme::Dopri5, o).unwrap_err();
    assert!(
        matches!(e.kind, Failure::TooMuchWork { max_steps: 50, .. }),
        "{e}"
    );
    assert_eq!(e.trajectory.len(), e.stats.steps + 1);
    let o = Options {
        h_min: Some(0.01),
        ..Options::adaptive(10.0, 1e-10)
    };
    let e = simulate(Seed2dof::default(), Scheme::Dopri5, o).unwrap_err();
    assert!(
        matches!(e.kind, Failure::StepTooSmall { given: true, .. }),
        "{e}"
    );
    // a floor the user gave is the first thing to lower
    assert!(e.to_string().contains("given in Options::h_min"), "{e}");
    assert!(e.to_string().contains("lower h_min"), "{e}");
}

/// A run out of steps says what its kind of step and scheme can change: at a fixed step the
/// steps it needs; an implicit scheme of high order is not told to use a scheme for stiff
/// problems, an order-2 scheme is told of its order, DOPRI5 that its stiffness detection was
/// silent (which does not prove the problem is not stiff).
#[test]
fn a_run_out_of_steps_says_what_to_change_for_its_scheme() {
    let run = |scheme: Scheme, o: Options| {
        let e = simulate(Seed2dof::default(), scheme, o).unwrap_err();
        println!("{}: {e}", scheme.name());
        let Failure::TooMuchWork { cause, .. } = e.kind else {
            panic!("{e}")
        };
        (cause, e.to_string())
    };
    let budget = |o: Options| Options { max_steps: 40, ..o };
    let (cause, text) = run(Scheme::Rk4, budget(Options::fixed(1.0, 1e-3)));
    assert_eq!(cause, OutOfSteps::Fixed(1000));
    assert!(
        text.contains("needs 1000 steps") && !text.contains("stiff"),
        "{text}"
    );
    // 0.03 s at 0.01 s: three steps, whatever the rounding of 0.03/0.01
    let e = simulate(
        Seed2dof::default(),
        Scheme::Rk4,
        Options {
            max_steps: 2,
            ..Options::fixed(0.03, 0.01)
        },
    )
    .unwrap_err();
    assert!(
        matches!(
            e.kind,
            Failure::TooMuchWork {
                cause: OutOfSteps::Fixed(3),
                ..
            }
        ),
        "{e}"
    );
    for scheme in [Scheme::Radau5, Scheme::Bdf(Default::default())] {
        let (cause, text) = run(scheme, budget(Options::adaptive(10.0, 1e-10)));
        assert_eq!(cause, OutOfSteps::Implicit(scheme.name()));
        assert!(
            text.contains("already a scheme for stiff problems"),
            "{text}"
        );
        assert!(!text.contains("use radau5"), "{text}");
    }
    let (_, text) = run(
        Scheme::GenAlpha(Default::default()),
        budget(Options::adaptive(10.0, 1e-8)),
    );
    assert!(
        text.contains("of order 2") && text.contains("radau5"),
        "{text}"
    );
    let (_, text) = run(Scheme::Dopri5, budget(Options::adaptive(10.0, 1e-10)));
    assert!(
        text.contains("stiffness detection did not find") && text.contains("radau5"),
        "{text}"
    );
}

/// A run out of steps names the component whose error test held most of its steps: the
/// seed's second mass oscillating on its spring against a first mass 10¹² times heavier
/// (which then hardly moves, its spring to the ground removed), under DOPRI5 and BDF (a PI
/// controller of the step, and an elementary one with a choice of order).
#[test]
fn a_run_out_of_steps_names_the_component_that_held_them() {
    let mut model = Seed2dof::default();
    let mut p = model.params().clone();
    p.m1 = 1e12;
    p.k1 = 0.0;
    model.set_params(p).unwrap();
    for scheme in [Scheme::Dopri5, Scheme::Bdf(Default::default())] {
        let o = Options {
            max_steps: 300,
            ..Options::adaptive(100.0, 1e-8)
        };
        let e = simulate(model.clone(), scheme, o).unwrap_err();
        println!("{scheme:?}: {e}");
        let Failure::TooMuchWork {
            held_most: Some(h), ..
        } = &e.kind
        else {
            panic!("{e}")
        };
        assert!(h.component.contains("q[1]"), "{e}");
        assert!(h.steps as f64 > 0.9 * h.of as f64, "{e}");
        assert!(h.of > 0 && h.of <= e.stats.steps, "{e}");
        assert!(e.to_string().contains("was held by"), "{e}");
        // a run that ends says the same in its Stats
        let (_, stats) = simulate(model.clone(), scheme, Options::adaptive(1.0, 1e-8)).unwrap();
        let h = stats.held_most.as_ref().expect("held");
        assert!(
            h.component.contains("q[1]") && h.of == stats.steps,
            "{stats}"
        );
        assert!(
            stats
                .to_string()
                .contains("the error test was held by q[1]")
        );
    }
}

/// Newton that fails at a fixed step names the component of its last correction with the
/// largest weighted term: the double pendulum at h = 0.3 s, where every implicit scheme's
/// Newton diverges from the start, its outer link's velocity the largest correction.
#[test]
fn newton_that_fails_names_its_largest_correction() {
    use mbs_models::dpend::DoublePendulum;
    let schemes = [
        Scheme::GenAlpha(Default::default()),
        Scheme::Hht(Default::default()),
        Scheme::Radau5,
        Scheme::Bdf(Default::default()),
        Scheme::ImplicitMidpoint,
    ];
    for scheme in schemes {
        let o = Options {
            output: Output::Last,
            ..Options::fixed(10.0, 0.3)
        };
        let e = simulate(DoublePendulum::default(), scheme, o).unwrap_err();
        println!("{scheme:?}: {e}");
        let Failure::NewtonDiverged {
            largest: Some(c), ..
        } = &e.kind
        else {
            panic!("{scheme:?}: {e}")
        };
        assert_eq!(c, "the velocity of q[1]", "{scheme:?}: {e}");
        let text = e.to_string();
        assert!(text.contains("largest in the velocity of q[1]"), "{text}");
        // the step was the user's: said so, without h_min, which a fixed step never meets
        assert!(
            matches!(e.kind, Failure::NewtonDiverged { fixed: true, .. })
                && text.contains("at the fixed step")
                && !text.contains("h_min"),
            "{text}"
        );
    }
}

/// Requests that cannot be met are refused before the run: outputs that would not fit in
/// memory (the process once aborted reserving them), global control asked for more samples
/// than a trajectory may hold, and an assembly given states of the wrong size.
#[test]
fn requests_beyond_memory_or_size_are_refused() {
    // 9·10⁷ outputs with the poses of every frame: 23.8 GB
    let opts = Options {
        output: Output::Every { dt: 1e-8 },
        frames: true,
        ..Options::fixed(0.9, 1e-3)
    };
    let e = simulate(Seed2dof::default(), Scheme::Rk4, opts).unwrap_err();
    println!("{e}");
    match &e.kind {
        Failure::InvalidOption { name, value, .. } => {
            assert_eq!(*name, "output", "{e}");
            assert!(value.starts_with("90000001 outputs of"), "{e}");
            // the size and the limit, as docs/accuracy.md quotes them
            let size = value.trim_start_matches("90000001 outputs of ");
            let limit = e.to_string();
            let limit = limit
                .split("than a trajectory may (")
                .nth(1)
                .and_then(|t| t.split(')').next())
                .unwrap_or_else(|| panic!("{e}"))
                .to_string();
            quoted::says(
                "docs/accuracy.md",
                &[format!(
                    "outputs that would take more than {limit} of memory, with their size: 9·10⁷ \
                     outputs of seed2dof with its frames' poses, {size}, filled the memory"
                )],
            );
        }
        other => panic!("{other}"),
    }
    let control = mbs::GlobalControl {
        samples: usize::MAX,
        ..Default::default()
    };
    let e = mbs::simulate_global(
        &Seed2dof::default(),
        Scheme::Dopri5,
        &Options::adaptive(1.0, 1e-6),
        &control,
    )
    .unwrap_err();
    assert!(e.to_string().contains("samples ≤ 10⁸"), "{e}");

    let model = mbs_models::slidercrank::SliderCrank::default();
    let (mut q, mut qd) = (vec![0.0; 3], vec![0.0; 2]);
    let e = mbs::assemble(&model, 0.0, &mut q, &mut qd, &Default::default()).unwrap_err();
    assert!(
        matches!(e, Failure::InvalidOption { name: "qd", .. }),
        "{e}"
    );
    let bad = mbs::ConstraintOptions {
        max_iterations: 0,
        ..Default::default()
    };
    let mut qd = vec![0.0; 3];
    let e = mbs::assemble(&model, 0.0, &mut q, &mut qd, &bad).unwrap_err();
    assert!(
        matches!(
            e,
            Failure::InvalidOption {
                name: "constraints.max_iterations",
                ..
            }
        ),
        "{e}"
    );
}

/// A loop that Newton cannot close after a fixed step too large for it says to take a smaller
/// one: fastlink under BDF with partitioning at a fixed 0.1 s (its motion happens in 30 ms).
#[test]
fn a_loop_not_closed_after_a_large_fixed_step_advises_a_smaller_one() {
    let mut o = Options::fixed(1.0, 0.1);
    o.constraints.method = mbs::ConstraintMethod::Partitioning;
    let e = simulate(
        mbs_models::fastlink::FastLink::default(),
        Scheme::Bdf(Default::default()),
        o,
    )
    .unwrap_err();
    println!("{e}");
    assert!(matches!(e.kind, Failure::ClosureFailed { .. }), "{e}");
    assert!(e.to_string().contains("take a smaller one"), "{e}");
    assert_eq!(e.t, 0.0);
    assert_eq!(e.trajectory.len(), 1);
}
