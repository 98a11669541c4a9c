//! Messages about steps: a fixed step is not judged by h_min, inconsistent step options are
//! refused before any work, a long run starts with the step its dynamics ask for, a
//! non-finite generalized force is not mistaken for a step, and an rtol beyond what a scheme's
//! local error test holds is said.

use mbs_models::seed2dof;

#[path = "common/quoted.rs"]
mod quoted;
#[path = "common/sweeps.rs"]
mod sweeps;
use mbs::{
    BdfParams, ConstraintMethod, Failure, GenAlphaParams, IterationMatrix, Options, Output, Scheme,
    StepControl, simulate,
};
use mbs_models::fastlink::FastLink;
use mbs_models::springpend::SpringPend;
use mbs_models::undefined_force::{EarlyForce, LateForce};
use seed2dof::Seed2dof;

fn quiet(o: Options) -> Options {
    Options {
        output: Output::Last,
        energy: false,
        ..o
    }
}

/// 1e-4 s is below the old default h_min of this run (1e-12·t_end = 1e-3 s), which stopped
/// it at t = 0 with "the step fell below h_min"; now it steps until its step budget is spent.
#[test]
fn a_fixed_step_below_the_default_h_min_runs() {
    let o = Options {
        max_steps: 2000,
        ..quiet(Options::fixed(1e9, 1e-4))
    };
    let e = simulate(Seed2dof::default(), Scheme::Rk4, o).unwrap_err();
    assert!(
        matches!(
            e.kind,
            Failure::TooMuchWork {
                max_steps: 2000,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(e.stats.steps, 2000);
    assert!((e.t - 0.2).abs() < 1e-9, "stopped at t = {}", e.t);
}

/// Fixed steps far from t = 0: from t0 = 1000 s at h = 1e-5 s the grid point reached after
/// one step was counted as t0 + 0.99999999748 h, below the part in 10⁹ of a step the grid
/// allowed, and every step after it planned for that same point had zero length, until the
/// step budget ran out at t = 1000.00001 s.
#[test]
fn fixed_steps_far_from_zero_stay_on_their_grid() {
    let o = Options {
        t0: 1000.0,
        output: Output::Every { dt: 1e-3 },
        energy: false,
        ..Options::fixed(1000.01, 1e-5)
    };
    let (tr, stats) = simulate(Seed2dof::default(), Scheme::Rk4, o).unwrap();
    assert_eq!(stats.steps, 1000);
    assert_eq!(tr.t.len(), 11);
    assert_eq!(*tr.t.last().unwrap(), 1000.01);
    assert!(stats.h_min > 0.99e-5, "a step of {} s", stats.h_min);
}

/// `Output::Every` keeps t_end's output where t_end − t0 rounds below its whole intervals:
/// from t0 = 100000.3 s to 100000.31 s by 1 ms, (t_end − t0)/dt is 9.99999999476 in floating
/// point, which the part in 10⁹ of an interval did not round up: the output at t_end was left
/// out (and the fixed steps of 1 ms stuck at zero length after two).
#[test]
fn every_output_far_from_zero_ends_at_t_end() {
    let o = Options {
        t0: 100000.3,
        output: Output::Every { dt: 1e-3 },
        energy: false,
        max_steps: 100,
        ..Options::fixed(100000.31, 1e-3)
    };
    let (tr, stats) = simulate(Seed2dof::default(), Scheme::Rk4, o).unwrap();
    assert_eq!(stats.steps, 10);
    assert_eq!(tr.t.len(), 11);
    assert_eq!(*tr.t.last().unwrap(), 100000.31);
}

/// A step stretched to land on a stop time is not longer than h_max: with h_max = 1 ms and
/// t_end = 10.05 ms, the last step was 1.05 ms.
#[test]
fn the_step_onto_t_end_keeps_to_h_max() {
    let o = Options {
        h_max: 1e-3,
        step: StepControl::Adaptive {
            rtol: 1e-2,
            atol: 1e-2,
            h0: Some(1e-3),
        },
        output: Output::Last,
        energy: false,
        ..Options::adaptive(10.05e-3, 1e-2)
    };
    let (_, stats) = simulate(Seed2dof::default(), Scheme::Dopri5, o).unwrap();
    println!("{} steps, the longest {} s", stats.steps, stats.h_max);
    assert!(stats.h_max <= 1e-3, "a step of {} s", stats.h_max);
}

fn invalid(scheme: Scheme, o: Options) -> (&'static str, String) {
    let e = simulate(Seed2dof::default(), scheme, o).unwrap_err();
    assert_eq!(e.stats.steps, 0, "{e}");
    assert_eq!(e.stats.dynamics, 0, "refused before any evaluation: {e}");
    match e.kind {
        Failure::InvalidOption { name, .. } => (name, e.kind.to_string()),
        other => panic!("not an InvalidOption: {other}"),
    }
}

#[test]
fn inconsistent_step_options_are_refused_naming_both() {
    // an h_min above the fixed step
    let (name, msg) = invalid(
        Scheme::Rk4,
        Options {
            h_min: Some(1e-2),
            ..Options::fixed(1.0, 1e-3)
        },
    );
    assert_eq!(name, "h_min");
    for w in [
        "h_min",
        "fixed step h = 0.001",
        "not judged by h_min",
        "h ≥ h_min",
    ] {
        assert!(msg.contains(w), "{w:?} missing in: {msg}");
    }
    // a fixed step below the resolution of time at t_end
    let (name, msg) = invalid(Scheme::Rk4, Options::fixed(1e9, 1e-9));
    assert_eq!(name, "h");
    for w in ["1e-9 (with t_end = 1e9)", "resolution of time", "larger h"] {
        assert!(msg.contains(w), "{w:?} missing in: {msg}");
    }
    // outputs closer than the resolution of time (they repeated the same time)
    let (name, msg) = invalid(
        Scheme::Dopri5,
        Options {
            t0: 1e6,
            output: Output::Every { dt: 1e-9 },
            ..Options::adaptive(1e6 + 0.01, 1e-6)
        },
    );
    assert_eq!(name, "output.dt");
    assert!(msg.contains("resolution of time"), "{msg}");
    // a first step below h_min
    let adaptive_h0 = |h0| StepControl::Adaptive {
        rtol: 1e-6,
        atol: 1e-8,
        h0: Some(h0),
    };
    let (name, msg) = invalid(
        Scheme::Dopri5,
        Options {
            step: adaptive_h0(1e-6),
            h_min: Some(1e-4),
            ..Options::default()
        },
    );
    assert_eq!(name, "h0");
    for w in ["h_min = 0.0001", "h0 ≥ h_min"] {
        assert!(msg.contains(w), "{w:?} missing in: {msg}");
    }
    // an h_min above h_max
    let (name, msg) = invalid(
        Scheme::Dopri5,
        Options {
            h_min: Some(1e-2),
            h_max: 1e-3,
            ..Options::adaptive(1.0, 1e-6)
        },
    );
    assert_eq!(name, "h_min");
    for w in ["h_max = 0.001", "h_min ≤ h_max"] {
        assert!(msg.contains(w), "{w:?} missing in: {msg}");
    }
    // consistent ones still run
    let o = Options {
        h_min: Some(1e-4),
        ..Options::fixed(0.1, 1e-3)
    };
    simulate(Seed2dof::default(), Scheme::Rk4, quiet(o)).unwrap();
}

/// t_end = 1e30 used to push the first step up to the floor 1e-12·t_end = 1e18 s, and the
/// run stopped at t = 0 with "h of coordinate q[0] is not finite (h = 1e18)". The floor now
/// follows t and h_max defaults to the span: the first step is the one the dynamics ask for,
/// and the run goes on until its step budget is spent.
#[test]
fn a_very_long_run_starts_with_a_sane_step() {
    let o = Options::adaptive(1e30, 1e-6);
    assert_eq!(o.h_max(), 1e30);
    assert_eq!(o.h_min(), 1e-12);
    assert_eq!(o.h_min_at(1e6), 1e-6);
    for scheme in [Scheme::Dopri5, Scheme::from_name("radau5").unwrap()] {
        let o = Options {
            max_steps: 200,
            output: Output::Steps,
            ..Options::adaptive(1e30, 1e-6)
        };
        let e = simulate(Seed2dof::default(), scheme, o).unwrap_err();
        assert!(
            matches!(e.kind, Failure::TooMuchWork { max_steps: 200, .. }),
            "{}: {e}",
            scheme.name()
        );
        let first = e.trajectory.t[1] - e.trajectory.t[0];
        assert!(
            first > 0.0 && first < 0.1,
            "{}: first step {first}",
            scheme.name()
        );
        assert!(e.stats.h_max < 10.0, "{}: {}", scheme.name(), e.stats.h_max);
    }
}

#[test]
fn a_non_finite_force_is_called_a_generalized_force() {
    let e = simulate(LateForce::default(), Scheme::Rk4, Options::fixed(1.0, 0.01)).unwrap_err();
    match &e.kind {
        Failure::NonFinite {
            quantity,
            coordinate,
            ..
        } => {
            assert_eq!(*quantity, "generalized force h");
            assert!(coordinate.contains("theta"), "{coordinate}");
        }
        other => panic!("{other}"),
    }
    let msg = e.kind.to_string();
    assert!(
        msg.starts_with("generalized force h of coordinate"),
        "{msg}"
    );
    // at the start already: refused at t0, before any step
    let e = simulate(
        EarlyForce::default(),
        Scheme::Dopri5,
        Options::adaptive(1.0, 1e-6),
    )
    .unwrap_err();
    assert_eq!(e.t, 0.0);
    assert_eq!(e.stats.steps, 0);
    assert!(
        matches!(
            e.kind,
            Failure::NonFinite {
                quantity: "generalized force h",
                ..
            }
        ),
        "{e}"
    );
    // the parameters are at their defaults: the model's expression is to blame
    let msg = e.kind.to_string();
    assert!(
        msg.ends_with("every parameter is at its default: an expression of the model is not defined at the start (a square root of a negative, a division by zero)"),
        "{msg}"
    );
}

/// A parameter that makes the start, or the first step, not finite is named: each parameter
/// set back to its default alone, the one that makes it finite.
#[test]
fn a_start_made_non_finite_by_a_parameter_names_it() {
    use mbs::{Model, Parameters};
    use mbs_models::{dpend::DoublePendulum, top::Top};
    let run = |model: Top| simulate(model, Scheme::Radau5, Options::adaptive(0.1, 1e-6));
    // the top's spin about its axis divides by sin²(theta0): its initial velocities
    let top = sweeps::with_params(Top::default(), &[("theta0", 0.0), ("m", 2.0)]);
    let e = run(top).unwrap_err();
    let msg = e.kind.to_string();
    println!("{msg}");
    assert_eq!(e.stats.steps, 0);
    assert!(
        msg.contains("with `theta0` at its default 0.7 rather than 0 the start is finite: check that parameter"),
        "{msg}"
    );
    assert!(!msg.contains("`m`"), "{msg}");
    // gravity of 1e300: the start is finite, the first step overflows
    let mut dpend = DoublePendulum::default();
    let mut p = dpend.params().clone();
    p.set("g", 1e300).unwrap();
    dpend.set_params(p).unwrap();
    let e = simulate(dpend, Scheme::Dopri5, Options::adaptive(0.1, 1e-6)).unwrap_err();
    let msg = e.kind.to_string();
    println!("{msg}");
    assert!(
        msg.contains(
            "with `g` at its default 9.81 rather than 1e300 a first step of that size is finite"
        ),
        "{msg}"
    );
}

#[test]
fn a_non_finite_initial_value_names_its_coordinate() {
    let (name, msg) = invalid(
        Scheme::Rk4,
        Options {
            qd0: Some(vec![0.0, f64::INFINITY]),
            ..Options::fixed(1.0, 0.01)
        },
    );
    assert_eq!(name, "qd0");
    assert!(msg.contains("inf at coordinate 1"), "{msg}");
}

/// The Newmark family holds its local error at 0.3·rtol^1.5, floored at 10⁴ε; RKC at the
/// same, floored at 100ε; BDF at 0.1·rtol^1.25, floored at 100ε. A tighter rtol than a floor
/// allows is not held: `Stats::tolerance_floor` says so, and so does the run's summary.
#[test]
fn an_rtol_beyond_a_schemes_floor_is_said() {
    let eps = f64::EPSILON;
    let gen_alpha = Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8));
    let bdf = Scheme::Bdf(BdfParams::default());
    for (scheme, rtol, floor) in [
        (gen_alpha, 1e-6, None),
        (gen_alpha, 5e-8, None),
        (gen_alpha, 3e-8, Some(1e4 * eps)),
        (gen_alpha, 1e-10, Some(1e4 * eps)),
        (Scheme::Rkc, 2e-9, None),
        (Scheme::Rkc, 1.5e-9, Some(100.0 * eps)),
        (bdf, 1e-10, None),
        (bdf, 5e-11, Some(100.0 * eps)),
        (Scheme::Radau5, 1e-12, None),
    ] {
        let o = quiet(Options::adaptive(0.01, rtol));
        let (_, stats) = simulate(Seed2dof::default(), scheme, o).unwrap();
        assert_eq!(stats.tolerance_floor, floor, "{scheme:?} at rtol {rtol:e}");
        let said = stats
            .to_string()
            .contains("its tolerance stopped at its floor");
        assert_eq!(said, floor.is_some(), "{stats}");
        // the rtol from which the floor holds: every rtol below it is floored, and said
        match stats.floor_from {
            Some(from) => {
                assert_eq!(floor.is_some(), rtol < from, "{scheme:?}: from {from:e}");
                let below = format!("as at every rtol below {from:.1e}");
                assert_eq!(stats.to_string().contains(&below), floor.is_some());
            }
            None => assert!(matches!(scheme, Scheme::Radau5), "{scheme:?} has a floor"),
        }
    }
}

/// At index 3 the Newmark family holds 0.07·rtol^1.5, floored at 10³ε, Radau5
/// 3·rtol^(4/3) and Radau3 3·rtol^1.5, both floored at 10⁵ε: on a closed loop
/// (fastlink, gen-α at index 3, its default) rtol 5e-8 is held, 1e-8 is not; Radau5 at index
/// 3 holds 5e-9 and not 4e-9, Radau3 4e-8 and not 3.5e-8; a floor holds for every rtol below
/// it, though looser than rtol (Radau5 at 1e-12, Radau3 at 1e-10: before, rtol' fell back to
/// rtol there, and Radau3 at index 3 stopped at h_min on fastlink at rtol 1e-10); with
/// projection RADAU5's transformation has no floor.
#[test]
fn an_rtol_beyond_the_index3_floor_is_said() {
    let gen_alpha = Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8));
    let eps = f64::EPSILON;
    for (scheme, method, rtol, floor) in [
        (gen_alpha, ConstraintMethod::Auto, 5e-8, None),
        (gen_alpha, ConstraintMethod::Auto, 1e-8, Some(1e3 * eps)),
        (Scheme::Radau5, ConstraintMethod::Index3, 5e-9, None),
        (
            Scheme::Radau5,
            ConstraintMethod::Index3,
            4e-9,
            Some(1e5 * eps),
        ),
        (
            Scheme::Radau5,
            ConstraintMethod::Index3,
            1e-12,
            Some(1e5 * eps),
        ),
        (Scheme::Radau3, ConstraintMethod::Index3, 4e-8, None),
        (
            Scheme::Radau3,
            ConstraintMethod::Index3,
            3.5e-8,
            Some(1e5 * eps),
        ),
        (
            Scheme::Radau3,
            ConstraintMethod::Index3,
            1e-10,
            Some(1e5 * eps),
        ),
        (Scheme::Radau5, ConstraintMethod::Projection, 4e-9, None),
    ] {
        let mut o = quiet(Options::adaptive(2e-4, rtol));
        o.constraints.method = method;
        let (_, stats) = simulate(FastLink::default(), scheme, o).unwrap();
        assert_eq!(
            stats.tolerance_floor, floor,
            "{scheme:?} {method:?} at rtol {rtol:e}"
        );
        // with projection Radau5 has no floor; where one is, every rtol below it is floored
        let from = stats.floor_from;
        assert_eq!(from.is_none(), method == ConstraintMethod::Projection);
        assert!(from.is_none_or(|from| floor.is_some() == (rtol < from)));
    }
}

/// A run that runs out of steps while its local tolerance is at the scheme's floor says so,
/// and from which rtol on loosening it saves steps: below that rtol every run holds the same
/// floor (Radau3 at index 3 on fastlink at rtol 1e-10 and 1e-9, its floor 10⁵ε held from rtol
/// ≈ 3.8e-8 on, take the same steps but for the first); where rtol set the tolerance the message says nothing of
/// a floor.
#[test]
fn a_run_out_of_steps_at_its_tolerance_floor_says_which_rtol_leaves_it() {
    let run = |rtol: f64| {
        let mut o = quiet(Options {
            max_steps: 300,
            ..Options::adaptive(0.03, rtol)
        });
        o.constraints.method = ConstraintMethod::Index3;
        simulate(FastLink::default(), Scheme::Radau3, o).unwrap_err()
    };
    let (tight, tighter) = (run(1e-9), run(1e-10));
    for e in [&tight, &tighter] {
        let Failure::TooMuchWork {
            floored: Some(f), ..
        } = &e.kind
        else {
            panic!("{e}")
        };
        assert_eq!(f.floor, 1e5 * f64::EPSILON, "{e}");
        // 3·rtol^1.5 = 10⁵ε
        let from = (1e5 * f64::EPSILON / 3.0).powf(1.0 / 1.5);
        assert!(
            (f.from / from - 1.0).abs() < 1e-5,
            "{} against {from:e}",
            f.from
        );
        assert!(
            e.to_string()
                .contains("its local error test held its floor of 2.2e-11, as it does at every rtol below 3.80e-8"),
            "{e}"
        );
    }
    // the same run below that rtol but for its first step: loosening rtol from 1e-10 to 1e-9
    // took the 300 steps 0.14 % further
    assert!(
        (tight.t / tighter.t - 1.0).abs() < 0.01,
        "{tight}\n{tighter}"
    );
    let loose = run(1e-6);
    assert!(
        matches!(loose.kind, Failure::TooMuchWork { floored: None, .. }),
        "{loose}"
    );
    assert!(!loose.to_string().contains("floor"), "{loose}");
}

/// A component near zero beside large ones of its kind, under an atol below their rounding,
/// is tested at that rounding (100ε times the largest of its kind), not at atol: fastlink's
/// velocities (a crank at 1,100 rad/s, a coupler turning through zero) under atol = 1e-12.
/// `Stats::floored_steps` counts such steps and the summary says so; at atol = 1e-9, above
/// that rounding, there are none. (The Newmark family tests its positions against its own
/// floor, 10⁴ε or 10³ε at index 3, on the tolerance: its weights never reach this one at
/// atol 1e-12.)
#[test]
fn a_weight_held_at_its_rounding_is_said() {
    let bdf = Scheme::Bdf(BdfParams::default());
    let mut counts = Vec::new();
    for (scheme, rtol) in [(Scheme::Dopri5, 1e-10), (Scheme::Radau3, 1e-8), (bdf, 1e-8)] {
        let run = |atol: f64| {
            let o = Options {
                step: StepControl::Adaptive {
                    rtol,
                    atol,
                    h0: None,
                },
                ..quiet(Options::adaptive(0.03, rtol))
            };
            simulate(FastLink::default(), scheme, o).unwrap().1
        };
        let (low, high) = (run(1e-12), run(1e-9));
        println!(
            "{scheme:?} at rtol {rtol:e}: {} of {} steps held at the rounding under atol 1e-12, {} under 1e-9",
            low.floored_steps, low.steps, high.floored_steps
        );
        assert!(low.floored_steps > 0, "{scheme:?}: {low}");
        assert!(
            low.to_string().contains("held a component at its rounding"),
            "{low}"
        );
        assert_eq!(high.floored_steps, 0, "{scheme:?}: {high}");
        assert!(
            !high
                .to_string()
                .contains("held a component at its rounding")
        );
        counts.push((
            quoted::thousands(low.floored_steps),
            quoted::thousands(low.steps),
        ));
    }
    let [(d, dn), (r, rn), (b, bn)] = &counts[..] else {
        unreachable!("three schemes")
    };
    quoted::says(
        "docs/accuracy.md",
        &[format!(
            "on fastlink under atol = 1e-12 DOPRI5 at rtol 1e-10 {d} of its {dn} steps, Radau3 at 1e-8 {r} of {rn}, BDF at 1e-8 {b} of {bn}, none under atol = 1e-9"
        )],
    );
}

fn adaptive(t_end: f64, rtol: f64, atol: f64) -> Options {
    Options {
        step: StepControl::Adaptive {
            rtol,
            atol,
            h0: None,
        },
        ..quiet(Options::adaptive(t_end, rtol))
    }
}

/// Radau's Newton weights its corrections like the error test, not below the rounding of the
/// values its stages handle: a double pendulum released at rest under atol = 1e-30 (any atol
/// from about 1e-25 down) stopped at t = 0 with "Newton did not converge … (last correction
/// 2.3e1)", the rounding of velocities that start at zero weighed against atol alone; it now
/// takes the steps it takes under atol = 1e-20 and lands on the same motion.
#[test]
fn radau_runs_from_rest_under_a_tiny_atol() {
    use mbs_models::dpend::DoublePendulum;
    for scheme in [Scheme::Radau5, Scheme::Radau3] {
        let run = |atol: f64| {
            simulate(DoublePendulum::default(), scheme, adaptive(2.0, 1e-6, atol))
                .unwrap_or_else(|e| panic!("{scheme:?} under atol {atol:e}: {e}"))
        };
        let ((tiny, tiny_stats), (small, small_stats)) = (run(1e-30), run(1e-20));
        let (a, b) = (tiny.q(tiny.len() - 1), small.q(small.len() - 1));
        let apart = a.iter().zip(b).map(|(x, y)| (x - y).abs());
        assert!(apart.fold(0.0, f64::max) < 1e-6, "{scheme:?}");
        assert!(
            tiny_stats.steps <= small_stats.steps + small_stats.steps / 10,
            "{scheme:?}: {} steps under atol 1e-30, {} under 1e-20",
            tiny_stats.steps,
            small_stats.steps
        );
    }
}

/// A step that falls below h_min names the component its last error test was held by, its
/// error and tolerance, and what set that tolerance. The standing hexapod under atol = 1e-30
/// (its feet meet the ground at t ≈ 0.048 s, where a joint velocity of about 1e-10 rad/s is
/// tested at its rounding, 100ε times the largest velocity): the message says to raise atol,
/// not that the motion is stiff. A step held by rtol (the 2-dof seed at rtol 1e-10 with
/// h_min = 0.01 s) names its component with no such advice.
#[test]
fn a_step_below_h_min_names_the_component_that_held_it() {
    use mbs::{HeldBy, SimError};
    fn held_by(e: &SimError) -> &HeldBy {
        match &e.kind {
            Failure::StepTooSmall {
                held_by: Some(b), ..
            } => b,
            _ => panic!("{e}"),
        }
    }
    use mbs_models::hexapod::HexapodStanding;
    let e = simulate(
        HexapodStanding::default(),
        Scheme::Dopri5,
        adaptive(1.0, 1e-6, 1e-30),
    )
    .unwrap_err();
    let b = held_by(&e);
    println!("{e}");
    assert!(b.component.starts_with("the velocity of q["), "{e}");
    assert_eq!(b.set_by, "rounding", "{e}");
    assert!(b.error.abs() > b.tolerance, "{e}");
    assert!(e.to_string().contains("raise atol"), "{e}");
    assert!(e.t > 0.04, "{e}");
    let o = Options {
        h_min: Some(0.01),
        ..quiet(Options::adaptive(10.0, 1e-10))
    };
    let e = simulate(Seed2dof::default(), Scheme::Dopri5, o).unwrap_err();
    let b = held_by(&e);
    println!("{e}");
    assert_eq!(b.set_by, "rtol", "{e}");
    assert!(b.component.contains("q["), "{e}");
    assert!(!e.to_string().contains("raise atol"), "{e}");
    assert!(!b.ran_away() && !e.to_string().contains("ran away"), "{e}");
}

/// The step can fall below h_min after an accepted step too: the test that accepts a step
/// also chooses the next one, and a next step below h_min stops the run. That test's
/// component is named as a rejecting test's is. The double pendulum at rtol 1e-9 over 3 s
/// with h_min from 1e-4 to 8.9e-3 s (forty values; DOPRI5 and Radau5 reach the end under
/// the smaller ones): every run that stops with `StepTooSmall`, under DOPRI5, Radau5,
/// Radau3, BDF and generalized-α, names the component its last error test was held by. Before,
/// 66 of the 157 runs that stopped so said only that the solution "may be singular or too
/// stiff" (DOPRI5 15 of 17, Radau5 20 of 20, Radau3 18 of 40, generalized-α 13 of 40; a
/// simulation of a walking body's balance controller so, at t = 0.51 s, whose step a
/// controller's filtered state had held).
#[test]
fn a_step_below_h_min_after_an_accepted_step_names_its_component() {
    use mbs_models::dpend::DoublePendulum;
    let schemes = [
        Scheme::Dopri5,
        Scheme::Radau5,
        Scheme::Radau3,
        Scheme::Bdf(BdfParams::default()),
        Scheme::GenAlpha(GenAlphaParams::default()),
    ];
    let mut stopped = 0;
    for scheme in schemes {
        for k in 0..40 {
            let h_min = 1e-4 * 10f64.powf(k as f64 / 20.0);
            let o = Options {
                h_min: Some(h_min),
                ..quiet(Options::adaptive(3.0, 1e-9))
            };
            let Err(e) = simulate(DoublePendulum::default(), scheme, o) else {
                continue;
            };
            let Failure::StepTooSmall { held_by, jump, .. } = &e.kind else {
                panic!("{scheme:?}, h_min = {h_min:e}: {e}");
            };
            // a smooth motion: its error falls with the step at the scheme's order
            assert!(jump.is_none(), "{scheme:?}, h_min = {h_min:e}: {e}");
            stopped += 1;
            let b = held_by
                .as_ref()
                .unwrap_or_else(|| panic!("{scheme:?}, h_min = {h_min:e}: {e}"));
            assert!(b.component.contains("q["), "{e}");
            assert!(e.to_string().contains("the error test was held by"), "{e}");
        }
    }
    println!("{stopped} runs stopped below h_min, each naming its component");
    assert!(stopped >= 150, "{stopped}");
}

/// A motion that runs away under a loose rtol is said to: DOPRI5 on the double pendulum
/// released at rest gains energy from its steps' errors, and the error a relative tolerance
/// allows grows with the motion; at rtol 0.2 its velocities grow past a million times their
/// start (from rest: past 1e6 rad/s) and its step falls below h_min. The message says the
/// motion ran away and to tighten rtol, not that it may be stiff (it said so before, and to
/// try Radau5 or BDF).
#[test]
fn a_motion_that_runs_away_under_a_loose_rtol_is_said_to() {
    use mbs_models::dpend::DoublePendulum;
    let o = quiet(Options::adaptive(10.0, 0.2));
    let e = simulate(DoublePendulum::default(), Scheme::Dopri5, o).unwrap_err();
    println!("{e}");
    let Failure::StepTooSmall {
        held_by: Some(b), ..
    } = &e.kind
    else {
        panic!("{e}")
    };
    assert!(b.ran_away(), "{e}");
    assert_eq!((b.set_by, b.start), ("rtol", Some(0.0)), "{e}");
    assert!(
        b.component.starts_with("the velocity of q[") && b.value > 1e6,
        "{e}"
    );
    let text = e.to_string();
    assert!(
        text.contains("ran away") && text.contains("tighten rtol"),
        "{e}"
    );
    assert!(!text.contains("stiff"), "{e}");
    assert!(e.t < 2.0, "{e}");
}

/// An rtol of 1 or more accepts any step (DOPRI5 on the double pendulum at rtol 2 let the
/// velocities grow to 7e17 rad/s before its step fell below h_min), and an output every 1e-300
/// s asks for more outputs than memory holds (it panicked building their times): both are
/// refused before any work, naming the option.
#[test]
fn a_tolerance_of_a_hundred_percent_and_outputs_beyond_memory_are_refused() {
    let (name, msg) = invalid(Scheme::Dopri5, quiet(Options::adaptive(10.0, 2.0)));
    assert_eq!(name, "rtol", "{msg}");
    assert!(msg.contains("must be < 1"), "{msg}");
    let o = Options {
        output: Output::Every { dt: 1e-300 },
        ..Options::adaptive(10.0, 1e-6)
    };
    let (name, msg) = invalid(Scheme::Dopri5, o);
    assert_eq!(name, "output.dt", "{msg}");
    assert!(msg.contains("10⁸ outputs"), "{msg}");
    // the largest rtol below 1 and a dense output within the bound still run
    let o = Options {
        output: Output::Every { dt: 1e-3 },
        ..Options::adaptive(1.0, 0.5)
    };
    assert!(simulate(Seed2dof::default(), Scheme::Radau5, o).is_ok());
}

/// Options that passed and then misled: an h_min or h_max below the resolution of time (t + h
/// would not move t), an h_max below a fixed step (it was cut silently), a Newton iteration
/// limit no iteration needs, and output times named by the first offending entry.
#[test]
fn steps_that_would_not_move_time_and_caps_on_fixed_steps_are_refused() {
    let adaptive_at = |t0: f64| Options {
        t0,
        ..quiet(Options::adaptive(t0 + 1.0, 1e-6))
    };
    let (name, msg) = invalid(
        Scheme::Dopri5,
        Options {
            h_min: Some(1e-13),
            ..adaptive_at(1e6)
        },
    );
    assert_eq!(name, "h_min", "{msg}");
    assert!(msg.contains("resolution of time"), "{msg}");
    let (name, _) = invalid(
        Scheme::Dopri5,
        Options {
            h_max: 1e-300,
            ..adaptive_at(0.0)
        },
    );
    assert_eq!(name, "h_max");
    let (name, msg) = invalid(
        Scheme::Rk4,
        Options {
            h_max: 1e-3,
            ..quiet(Options::fixed(1.0, 1e-2))
        },
    );
    assert_eq!(name, "h_max", "{msg}");
    let mut o = quiet(Options::adaptive(1.0, 1e-6));
    o.newton.max_iterations = usize::MAX;
    assert_eq!(invalid(Scheme::Radau5, o).0, "newton.max_iterations");
    let (name, msg) = invalid(
        Scheme::Dopri5,
        Options {
            output: Output::Times(vec![0.1, 0.2, 1.5, 0.3]),
            ..adaptive_at(0.0)
        },
    );
    assert_eq!(name, "output.times");
    assert!(msg.contains("1.5 at index 2"), "{msg}");
}

/// `Output::Every` ends on t_end even where the last multiple of dt rounds past it (3 · 0.1 =
/// 0.30000000000000004 > 0.3, whose output was lost), and a run that fails under
/// `Output::Last` keeps its last accepted state (it kept nothing).
#[test]
fn every_dt_ends_on_t_end_and_a_failed_last_output_run_keeps_its_state() {
    for (t_end, n) in [(0.3, 4), (0.7, 8), (1.2, 13)] {
        let o = Options {
            output: Output::Every { dt: 0.1 },
            energy: false,
            ..Options::adaptive(t_end, 1e-6)
        };
        let (tr, _) = simulate(Seed2dof::default(), Scheme::Dopri5, o).unwrap();
        assert_eq!(tr.len(), n, "t_end {t_end}: {:?}", tr.t);
        assert_eq!(*tr.t.last().unwrap(), t_end);
    }
    let o = Options {
        max_steps: 50,
        ..quiet(Options::adaptive(10.0, 1e-8))
    };
    let e = simulate(Seed2dof::default(), Scheme::Dopri5, o).unwrap_err();
    assert!(matches!(e.kind, Failure::TooMuchWork { .. }), "{e}");
    assert_eq!(e.trajectory.len(), 1, "the last accepted state");
    assert_eq!(e.trajectory.t[0], e.t);
    assert!(e.t > 0.0);
}

/// A step that shrank for Newton's sake is not blamed on the error test: the stiff spring
/// pendulum (k = 1e8 N/m) iterated with M alone (`IterationMatrix::MassOnly`, whose Newton
/// converges only for h well below √(m/k) = 1e-4 s) under an h_min of 1 ms fails its Newton
/// iterations down to h_min under Radau5, Radau3 and BDF, no step rejected by its error, and
/// each says that Newton did not converge there. The cases that showed it before, fastlink
/// under Radau3 at rtol 1e-9 at index 3 and (atol 1e-14) at index 2, now reach their end:
/// the first since Radau3's tolerance at index 3 has its floor, the second since Radau's
/// Newton weighs the stage positions no finer than their rounding. The first had accepted a
/// step at h_min with an error 6e-4 of its tolerance, and the predictive correction took the
/// shrinking for the error's trend and cut the next step by 5, below h_min ("the step fell
/// below h_min … raise atol"): Radau restarts that correction after a failed Newton
/// iteration, which no case known now reaches.
#[test]
fn a_step_shrunk_by_newton_is_not_blamed_on_the_error_test() {
    let model = sweeps::with_params(SpringPend::default(), &[("k", 1e8)]);
    for scheme in [
        Scheme::Radau5,
        Scheme::Radau3,
        Scheme::Bdf(BdfParams::default()),
    ] {
        let o = Options {
            h_min: Some(1e-3),
            iteration_matrix: IterationMatrix::MassOnly,
            q0: Some(vec![0.5, 1.0 + 9.81 / 1e8]),
            ..quiet(Options::adaptive(1.0, 1e-6))
        };
        let e = simulate(model.clone(), scheme, o).unwrap_err();
        println!("{}: {e}\n{}", scheme.name(), e.stats);
        assert!(
            matches!(e.kind, Failure::NewtonDiverged { fixed: false, .. }),
            "{}: {e}",
            scheme.name()
        );
        assert!(e.to_string().contains("h_min"), "{e}");
        assert!(e.stats.rejected_newton >= 2, "{}", e.stats);
        assert_eq!(e.stats.rejected_error, 0, "{}", e.stats);
    }
    // fastlink at index 2 under Radau3 at rtol 1e-9, atol 1e-14 stopped there at t = 6.4e-8 s
    let mut o = quiet(Options::adaptive(0.03, 1e-9));
    o.step = StepControl::Adaptive {
        rtol: 1e-9,
        atol: 1e-14,
        h0: None,
    };
    o.constraints.method = ConstraintMethod::Index2;
    let (tr, _) = simulate(FastLink::default(), Scheme::Radau3, o).unwrap();
    assert_eq!(*tr.t.last().unwrap(), 0.03);
}

/// A step that collapses at a jump in the forces says so: the standing hexapod's feet touch
/// the ground at t = 0.048 s, where the contact's damping force c·ż jumps from 0 to about
/// 220 N; a step across that errs by about h·Δa, so that over the rejections from about one
/// t the error falls in proportion to h (order 1.0 under BDF and RKC, 0.9 under Radau3), and
/// at tight tolerances the steps fall below h_min. Before, the message only said to raise
/// atol, as for a component too small to resolve.
#[test]
fn a_step_collapsing_at_a_jump_in_the_forces_says_so() {
    for (scheme, rtol) in [
        (Scheme::Bdf(BdfParams::default()), 1e-10),
        (Scheme::Radau3, 1e-10),
        (Scheme::Rkc, 1e-6),
    ] {
        let o = Options {
            max_steps: 20_000,
            ..quiet(Options::adaptive(0.1, rtol))
        };
        let e = simulate(mbs_models::hexapod::HexapodStanding::default(), scheme, o).unwrap_err();
        println!("{}: {e}", scheme.name());
        let Failure::StepTooSmall {
            jump: Some(order), ..
        } = e.kind
        else {
            panic!("{e}")
        };
        assert!(order < 1.5, "{e}");
        assert!((e.t - 0.0481).abs() < 1e-3, "{e}");
        assert!(e.to_string().contains("jump"), "{e}");
    }
}

/// A mass matrix singular at the start because of a parameter names it: a bar of no length
/// stacks the Cartesian pendulum's hinges on its centre, where its angle moves no mass.
#[test]
fn a_mass_matrix_made_singular_by_a_parameter_names_it() {
    use mbs_models::dpend_cartesian::DoublePendulumCartesian;
    let model = sweeps::with_params(DoublePendulumCartesian::default(), &[("l", 0.0)]);
    let e = simulate(model, Scheme::Dopri5, Options::adaptive(0.2, 1e-6)).unwrap_err();
    let msg = e.kind.to_string();
    println!("{msg}");
    assert!(matches!(e.kind, Failure::SingularMatrix { .. }), "{msg}");
    assert!(
        msg.contains("with `l` at its default 1 rather than 0 M is regular at the start: check that parameter"),
        "{msg}"
    );
    // at the defaults, a singular M is the coordinates' doing: nothing is added
    let e = simulate(
        DoublePendulumCartesian::default(),
        Scheme::Dopri5,
        Options {
            q0: Some(vec![0.0; 6]),
            ..Options::adaptive(0.2, 1e-6)
        },
    );
    if let Err(e) = e {
        assert!(!e.kind.to_string().contains("default"), "{e}");
    }
}
