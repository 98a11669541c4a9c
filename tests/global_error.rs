//! Global error control (`mbs::simulate_global`): rtol as a bound on the error of the whole
//! trajectory. Local error control leaves the four-bar two digits short of rtol; global control
//! brings it within rtol and its estimate says how far the returned run is from the truth; a
//! tolerance a scheme cannot reach is a typed failure that keeps the most accurate trajectory;
//! rotation joints are compared without their charts.
//!
//! `cargo test --release --test global_error -- --nocapture` prints the reports.

use mbs::{
    ConstraintMethod, Failure, GenAlphaParams, GlobalControl, GlobalFloor, GlobalLimit, Model,
    Options, Output, Scheme, Trajectory, simulate, simulate_global,
};
use mbs_models::{fastlink, fourbar, tumble};

#[path = "common/quoted.rs"]
mod quoted;

/// Largest |y − r| / (atol + rtol·|r|) over the outputs and measured components (a rotation
/// joint by its rotation and angular velocity): the error in the user's tolerance (1 = at
/// the tolerance).
fn error_in_tolerance(
    model: &impl Model,
    tr: &Trajectory,
    reference: &Trajectory,
    rtol: f64,
    atol: f64,
) -> f64 {
    let joints = model.info().rotation_joints;
    let (a, b) = (
        tr.measured_states(joints),
        reference.measured_states(joints),
    );
    assert_eq!(a.len(), b.len(), "outputs at the same times");
    a.iter()
        .zip(&b)
        .flat_map(|(ya, yb)| ya.iter().zip(yb))
        .map(|(y, r)| (y - r).abs() / (atol + rtol * r.abs()))
        .fold(0.0, f64::max)
}

fn times(t_end: f64, n: usize) -> Vec<f64> {
    (1..=n).map(|k| t_end * k as f64 / n as f64).collect()
}

fn options(t_end: f64, rtol: f64, n: usize) -> Options {
    Options {
        output: Output::Times(times(t_end, n)),
        energy: false,
        ..Options::adaptive(t_end, rtol)
    }
}

/// The four-bar over 2 s (its crank's fast turns amplify every step's error): DOPRI5 with
/// local control at rtol 1e-6 is more than a digit short; under global control the returned
/// run is within rtol, and the estimate is within a factor 3 of its true error (against
/// DOPRI5 at rtol 1e-13, whose own error is below 1e-10).
#[test]
fn global_control_brings_the_four_bar_within_rtol_where_local_control_falls_short() {
    let model = fourbar::FourBar::default();
    let rtol = 1e-6;
    let (reference, _) =
        simulate(model.clone(), Scheme::Dopri5, options(2.0, 1e-13, 20)).expect("reference");
    let (local, _) =
        simulate(model.clone(), Scheme::Dopri5, options(2.0, rtol, 20)).expect("local");
    let e_local = error_in_tolerance(&model, &local, &reference, rtol, rtol / 100.0);
    let o = options(2.0, rtol, 20);
    let (tr, stats, report) =
        simulate_global(&model, Scheme::Dopri5, &o, &GlobalControl::default()).expect("global");
    let e = error_in_tolerance(&model, &tr, &reference, rtol, rtol / 100.0);
    println!("local: {e_local:.3e} of the tolerance; global: {e:.3e}, {report}");
    assert!(
        e_local > 10.0,
        "local control is more than a digit short: {e_local}"
    );
    assert!(e <= 1.0, "global control meets rtol: {e}");
    assert!(report.estimate <= 1.0);
    assert!(
        e / report.estimate < 3.0 && report.estimate / e < 3.0,
        "the estimate {} is within a factor 3 of the true error {e}",
        report.estimate
    );
    // work: every run counted, the returned run's own stats among them
    let steps: usize = report.runs.iter().map(|r| r.steps).sum();
    assert_eq!(report.work.steps, steps);
    assert!(report.runs.iter().any(|r| r.steps == stats.steps));
    assert!(report.runs.len() <= 4, "{report}");
    assert!(report.runs.windows(2).all(|w| w[1].rtol < w[0].rtol));
    quoted::says(
        "README.md",
        &[format!(
            "On the four-bar, DOPRI5 at rtol 1e-6 is {e_local:.0}× the tolerance short with local control; globally controlled it lands at {e:.2} of it, the estimate saying {:.2}, after {} runs ({} steps in all)",
            report.estimate,
            report.runs.len(),
            quoted::thousands(report.work.steps)
        )],
    );
}

/// A tolerance the scheme cannot reach: generalized-α at index 3 holds its local error test
/// at its floor (10³ε) from local rtol ≈ 2.2e-8 on, and is 4–5 digits short of rtol on
/// fastlink. At rtol 1e-8 its first run is already floored: no tighter run could check it, and
/// the control stops after it, saying so, with the typed failure and that run's whole
/// trajectory (before, it ran a second, floored run of as many steps to find that out).
/// At rtol 1e-6 it tightens until its candidates reach twice that rtol, and stops there.
#[test]
fn an_unreachable_tolerance_is_a_typed_failure_that_keeps_the_trajectory() {
    let model = fastlink::FastLink::default();
    let scheme = Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8));
    for (rtol, expected_runs) in [(1e-8, 1..=1), (1e-6, 2..=6)] {
        let mut o = options(0.03, rtol, 30);
        o.constraints.method = ConstraintMethod::Index3;
        let err = simulate_global(&model, scheme, &o, &GlobalControl::default())
            .expect_err("out of gen-α index 3's reach on fastlink");
        println!("rtol {rtol:e}: {}", err.kind);
        let Failure::GlobalToleranceNotMet {
            estimate,
            runs,
            floor,
            rtol: kept,
            ..
        } = err.kind
        else {
            panic!("a typed failure: {}", err.kind);
        };
        let Some(GlobalFloor::Held { from }) = floor else {
            panic!("stopped at the scheme's floor: {floor:?}");
        };
        assert_eq!(
            Some(from),
            err.stats.floor_from,
            "the floor the runs report"
        );
        assert!((2e-8..2.5e-8).contains(&from), "{from}");
        assert!(estimate > 1.0, "{estimate}");
        assert!(expected_runs.contains(&runs), "{runs} runs");
        // the first run, at the user's rtol, or a run no tighter than the floor's edge
        assert!(
            kept == rtol || kept >= from * (1.0 - 1e-9),
            "kept the run at local rtol {kept:e}"
        );
        assert!(
            err.kind.to_string().contains(&format!(
                "holds its floor at every local rtol below {from:.1e}"
            )) && err
                .kind
                .to_string()
                .contains("holds no floor there (dopri5, or radau5"),
            "{}",
            err.kind
        );
        assert_eq!(err.trajectory.len(), 30, "the whole trajectory is kept");
        assert!((err.t - 0.03).abs() < 1e-12);
    }
}

/// The default Newmark scheme, generalized-α at index 3, on the four-bar over 2 s at rtol 1e-4:
/// its local control is 1.5 digits short (2.46 digits), it takes local rtol 2.2e-7 to meet the
/// tolerance, and its local error test holds its floor from 2.2e-8 on. The control keeps its
/// candidates at twice that rtol or above, so that a run at it can check them, and meets the
/// tolerance; before, a candidate chosen at 1.2e-8, floored, could be checked by no tighter
/// run, and the control stopped `GlobalToleranceNotMet`.
#[test]
fn global_control_keeps_its_candidates_where_a_tighter_run_can_check_them() {
    let model = fourbar::FourBar::default();
    let rtol = 1e-4;
    let scheme = Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8));
    let (reference, _) =
        simulate(model.clone(), Scheme::Dopri5, options(2.0, 1e-13, 20)).expect("reference");
    let o = options(2.0, rtol, 20);
    let (local, local_stats) = simulate(model.clone(), scheme, o.clone()).expect("local");
    let e_local = error_in_tolerance(&model, &local, &reference, rtol, rtol / 100.0);
    let (tr, stats, report) =
        simulate_global(&model, scheme, &o, &GlobalControl::default()).expect("met");
    let e = error_in_tolerance(&model, &tr, &reference, rtol, rtol / 100.0);
    println!("local: {e_local:.3e} of the tolerance; global: {e:.3e}, {report}");
    let from = local_stats
        .floor_from
        .expect("gen-α at index 3 has a floor");
    assert!((2e-8..2.5e-8).contains(&from), "{from}");
    assert!(e_local > 10.0, "local control is more than a digit short");
    assert!(e <= 1.0 && report.estimate <= 1.0, "met: {e}");
    let (last, candidates) = report.runs.split_last().expect("runs");
    for run in candidates {
        assert!(run.rtol >= 2.0 * from * (1.0 - 1e-9), "{report}");
    }
    assert!(
        last.rtol >= from * (1.0 - 1e-9),
        "the checking run is not floored"
    );
    assert!(report.runs.iter().any(|r| r.steps == stats.steps));
}

/// The limits of `GlobalControl` that end the runs are named, and the advice fits the scheme:
/// DOPRI5 on fastlink at rtol 1e-10 would need its next run at local rtol 1e-14, below
/// `min_rtol` (the linkage amplifies each step's error by more than three decades), and is
/// not told to use a scheme of higher order, which it is; on the four-bar at rtol 1e-6 with
/// two runs allowed, where it takes four, it is told to raise that limit; gen-α, of order 2,
/// stopped there by the same limit at rtol 1e-4, is told of DOPRI5 and Radau5. Before, each
/// was advised "a scheme of higher order (radau5, dopri5, bdf)", BDF among them, whose error
/// test holds a floor of 100ε, and not told which limit had stopped it.
#[test]
fn the_limit_that_ended_the_runs_is_named_and_the_advice_fits_the_scheme() {
    let gen_alpha = Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8));
    let two_runs = GlobalControl {
        max_runs: 2,
        ..GlobalControl::default()
    };
    let fast = |scheme, rtol, control: &GlobalControl| {
        let model = fastlink::FastLink::default();
        simulate_global(&model, scheme, &options(0.03, rtol, 20), control)
    };
    let four_bar = |scheme, rtol, control: &GlobalControl| {
        let model = fourbar::FourBar::default();
        simulate_global(&model, scheme, &options(2.0, rtol, 20), control)
    };
    let cases = [
        fast(Scheme::Dopri5, 1e-10, &GlobalControl::default()),
        four_bar(Scheme::Dopri5, 1e-6, &two_runs),
        four_bar(gen_alpha, 1e-4, &two_runs),
    ];
    for (result, scheme) in cases
        .into_iter()
        .zip([Scheme::Dopri5, Scheme::Dopri5, gen_alpha])
    {
        let err = result.expect_err("not met within the limits");
        let text = err.kind.to_string();
        println!("{}: {text}", scheme.name());
        let Failure::GlobalToleranceNotMet {
            limit: Some(limit),
            floor: None,
            scheme: named,
            ..
        } = err.kind
        else {
            panic!("stopped by a limit of GlobalControl: {text}");
        };
        assert_eq!(named, scheme.name());
        match limit {
            GlobalLimit::MinRtol { needed, min_rtol } => {
                assert!(needed < min_rtol && min_rtol == 1e-13, "{needed:e}");
                assert!(text.contains("`GlobalControl::min_rtol`"), "{text}");
            }
            GlobalLimit::Runs { max_runs } => {
                assert_eq!(max_runs, 2);
                assert!(text.contains("raise `GlobalControl::max_runs`"), "{text}");
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(
            text.contains("a scheme of higher order"),
            scheme == gen_alpha,
            "{text}"
        );
        assert!(!text.contains("bdf"), "BDF has a floor: {text}");
        assert_eq!(err.trajectory.len(), 20, "the whole trajectory is kept");
    }
}

/// Fixed steps have no tolerance to meet: refused before any work, by name.
#[test]
fn fixed_steps_are_refused() {
    let o = Options::fixed(1.0, 1e-3);
    let err = simulate_global(
        &fourbar::FourBar::default(),
        Scheme::Rk4,
        &o,
        &GlobalControl::default(),
    )
    .expect_err("fixed steps");
    assert!(
        matches!(err.kind, Failure::InvalidOption { name: "step", .. }),
        "{}",
        err.kind
    );
    assert_eq!(err.stats.steps, 0);
}

/// Runs with nothing to compare (no output after t0, or t_end = t0), and a floor on the local
/// tolerance that leaves no tighter run, are refused by name: before, two runs that agreed at
/// t0 alone "met" any tolerance.
#[test]
fn nothing_to_compare_and_a_floor_above_rtol_are_refused() {
    let model = fourbar::FourBar::default();
    let control = GlobalControl::default();
    for o in [
        Options {
            output: Output::Times(vec![]),
            ..options(1.0, 1e-6, 1)
        },
        Options {
            output: Output::Times(vec![0.0]),
            ..options(1.0, 1e-6, 1)
        },
        Options {
            output: Output::Steps,
            ..options(0.0, 1e-6, 1)
        },
    ] {
        let err = simulate_global(&model, Scheme::Dopri5, &o, &control).expect_err("refused");
        assert!(
            matches!(err.kind, Failure::InvalidOption { name: "output", .. }),
            "{:?}: {}",
            o.output,
            err.kind
        );
    }
    for min_rtol in [1e-6, 1.0, f64::INFINITY, 0.0, -1e-9, f64::NAN] {
        let control = GlobalControl {
            min_rtol,
            ..GlobalControl::default()
        };
        let err = simulate_global(&model, Scheme::Dopri5, &options(1.0, 1e-6, 10), &control)
            .expect_err("refused");
        assert!(
            matches!(
                err.kind,
                Failure::InvalidOption {
                    name: "global control",
                    ..
                }
            ) && err.kind.to_string().contains("min_rtol < rtol"),
            "min_rtol {min_rtol}: {}",
            err.kind
        );
    }
}

/// A body on a spherical joint tumbling through its flips: each run re-centres its chart at
/// its own times, so the runs are compared by rotation and angular velocity, not angles. The
/// control converges over 10 s (the first flip), and the result is within rtol of a run at rtol
/// 1e-12.
#[test]
fn rotation_joints_are_compared_without_their_charts() {
    let model = tumble::TumbleBall::default();
    let rtol = 1e-5;
    let (reference, _) =
        simulate(model.clone(), Scheme::Dopri5, options(10.0, 1e-12, 50)).expect("reference");
    let o = options(10.0, rtol, 50);
    let (tr, stats, report) =
        simulate_global(&model, Scheme::Dopri5, &o, &GlobalControl::default()).expect("global");
    let e = error_in_tolerance(&model, &tr, &reference, rtol, rtol / 100.0);
    println!("tumble on Tball: {e:.3e} of the tolerance, {report}");
    assert!(stats.chart_switches > 0, "the charts were re-centred");
    assert!(e <= 1.0, "{e}");
    let first = report.runs[0].estimate.expect("the first run's estimate");
    quoted::says(
        "README.md",
        &[format!(
            "the tumbling body on a ball joint at rtol 1e-5 over 10 s goes from an estimated {first:.0e}× short to {e:.2} (estimate {:.2}) in {} runs",
            report.estimate,
            report.runs.len()
        )],
    );
}

/// Global control's own sample times stay within [t0, t_end] where their last rounds past it
/// (0.3 + 0.6 = 0.9000000000000001 > 0.9: the first run was refused, naming times the user
/// never gave).
#[test]
fn its_sample_times_end_on_t_end() {
    let o = Options {
        t0: 0.3,
        output: Output::Steps,
        energy: false,
        ..Options::adaptive(0.9, 1e-5)
    };
    let (tr, _, report) = simulate_global(
        &fourbar::FourBar::default(),
        Scheme::Dopri5,
        &o,
        &GlobalControl::default(),
    )
    .unwrap();
    assert_eq!(*tr.t.last().unwrap(), 0.9, "{report}");
}
