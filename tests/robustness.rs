//! Every scheme, constraint method and kind of step on the repository's models, from loose
//! to tight tolerances and from fine to coarse fixed steps: a run ends, or stops with a typed
//! failure that keeps what it computed. Never a panic, never a non-finite value in a
//! trajectory (returned or kept), never a stop that loses the outputs before it.
//!
//! 2,145 runs of 1 s, at most 20,000 steps each, on 14 models; 385 more with the sensitivities
//! of two models' motion to their parameters, and 224 under global error control; and every
//! parameter of 14 models at the edges of its range (291 values refused by `set_params`, 786
//! runs of the others, where a start or first step that is not finite names the parameter
//! that makes it so); and every numeric option at the edges of its range on two models under
//! three schemes (1,008 runs, 727 refused up front). The sweep that first ran this found a
//! message blaming an error test that had passed (Radau's predictive step correction after
//! failed Newton iterations, `tests/step_messages.rs`), a loop closure with no advice
//! (`tests/failures.rs`) and RKC's fixed steps going non-finite on fastlink's saddle
//! (`tests/scheme_rkc.rs`).

use mbs::{
    ConstraintMethod, Failure, Model, Options, Output, Scheme, SimError, StepControl, simulate,
};
use mbs_models::*;
use std::panic::{AssertUnwindSafe, catch_unwind};

#[path = "common/quoted.rs"]
mod quoted;
#[path = "common/sweeps.rs"]
mod sweeps;

use quoted::thousands;

/// The runs that ended as `kind` (0 where none did).
fn count(kinds: &Kinds, kind: &str) -> usize {
    kinds.get(kind).copied().unwrap_or(0)
}

fn methods(closed: bool) -> Vec<ConstraintMethod> {
    if !closed {
        return vec![ConstraintMethod::Auto];
    }
    vec![
        ConstraintMethod::Auto,
        ConstraintMethod::Index3,
        ConstraintMethod::Index2,
        ConstraintMethod::Projection,
        ConstraintMethod::Partitioning,
        ConstraintMethod::Baumgarte {
            alpha: 10.0,
            beta: 10.0,
        },
    ]
}

fn steps() -> [Options; 5] {
    [
        Options::adaptive(1.0, 1e-2),
        Options::adaptive(1.0, 1e-6),
        Options::adaptive(1.0, 1e-10),
        Options::fixed(1.0, 0.1),
        Options::fixed(1.0, 1e-3),
    ]
}

fn finite(tr: &mbs::Trajectory) -> bool {
    (0..tr.len()).all(|i| tr.q(i).iter().chain(tr.qd(i)).all(|x| x.is_finite()))
}

/// A stop refused before any work (options, a scheme that cannot take the constraints) or at
/// the start, before a first step (a start that cannot be made consistent, a mass matrix
/// singular or forces not finite there), has no trajectory; every other keeps its start at
/// least, the outputs before the failure, none past it, and all finite.
fn check_failure(tag: &str, e: &SimError) -> Result<(), String> {
    let refused = matches!(
        e.kind,
        Failure::InvalidOption { .. } | Failure::ConstraintsUnsupported { .. }
    ) || (e.h == 0.0 && e.stats.steps == 0);
    let text = e.to_string();
    if text.trim().is_empty() {
        return Err(format!("{tag}: an empty message"));
    }
    if let Failure::InvalidOption { name: "", .. } = &e.kind {
        return Err(format!("{tag}: an invalid option without a name: {text}"));
    }
    let longest = sweeps::longest_number(&text);
    if longest > 12 {
        return Err(format!("{tag}: a number of {longest} digits: {text}"));
    }
    if !refused {
        if e.trajectory.is_empty() {
            return Err(format!("{tag}: nothing kept: {text}"));
        }
        let last = *e.trajectory.t.last().unwrap();
        if last > e.t {
            return Err(format!(
                "{tag}: an output at {last} past the stop at {}",
                e.t
            ));
        }
    }
    if !finite(&e.trajectory) {
        return Err(format!("{tag}: a non-finite value kept: {text}"));
    }
    Ok(())
}

/// Counts a run's ending by kind (`ok` for a run that returned), and the problems with it:
/// a panic, a non-finite value returned, or what [`check_failure`] finds in a failure.
fn record(
    tag: &str,
    r: std::thread::Result<Result<mbs::Trajectory, SimError>>,
    ok: &str,
    kinds: &mut Kinds,
    problems: &mut Vec<String>,
) {
    match r {
        Err(_) => problems.push(format!("{tag}: panicked")),
        Ok(Ok(tr)) => {
            if !finite(&tr) {
                problems.push(format!("{tag}: a non-finite value returned"));
            }
            *kinds.entry(ok.into()).or_default() += 1;
        }
        Ok(Err(e)) => {
            if let Err(p) = check_failure(tag, &e) {
                problems.push(p);
            }
            let kind = format!("{:?}", e.kind);
            let kind = kind.split([' ', '(', '{']).next().unwrap_or("").to_string();
            *kinds.entry(kind).or_default() += 1;
        }
    }
}

/// Runs `model` under `scheme` and `o`, its panic caught, and records how it ended.
fn run_and_record<M: Model + 'static>(
    tag: &str,
    model: M,
    scheme: Scheme,
    o: Options,
    kinds: &mut Kinds,
    problems: &mut Vec<String>,
) {
    let r = catch_unwind(AssertUnwindSafe(|| simulate(model, scheme, o)));
    record(
        tag,
        r.map(|r| r.map(|(tr, _)| tr)),
        "finished",
        kinds,
        problems,
    );
}

/// Runs the sweep on one model (`make` makes a copy for each run); returns the runs, the
/// failures by kind and the problems.
fn sweep<M: Model + 'static>(
    name: &str,
    make: impl Fn() -> M,
    closed: bool,
    kinds: &mut Kinds,
    problems: &mut Vec<String>,
) -> usize {
    let mut runs = 0;
    for scheme in Scheme::all() {
        for method in methods(closed) {
            for o in steps() {
                let mut o = Options {
                    max_steps: 20_000,
                    output: Output::Every { dt: 0.05 },
                    energy: false,
                    ..o
                };
                o.constraints.method = method;
                let tag = format!("{name} {} {method:?} {:?}", scheme.name(), o.step);
                runs += 1;
                run_and_record(&tag, make(), scheme, o, kinds, problems);
            }
        }
    }
    runs
}

/// Runs `sweeps` with the default panic report silenced on this thread (the panics they look
/// for are caught; the report would only repeat them), then asserts that they found no problem and that no
/// run ended non-finite: these models are finite wherever a step that is not refused takes
/// them (a run that ends non-finite outgrew its motion unrefused, as RKC at a fixed step on
/// fastlink's saddle did, `tests/scheme_rkc.rs`). Returns the runs and their endings by kind.
fn quietly(sweeps: impl FnOnce(&mut Kinds, &mut Vec<String>) -> usize) -> (usize, Kinds) {
    let (runs, kinds) = quietly_finite_or_not(sweeps);
    assert!(!kinds.contains_key("NonFinite"), "{kinds:?}");
    (runs, kinds)
}

/// [`quietly`] where a run may stop `NonFinite`: a model given parameters of 1e300 overflows.
fn quietly_finite_or_not(
    sweeps: impl FnOnce(&mut Kinds, &mut Vec<String>) -> usize,
) -> (usize, Kinds) {
    let (mut kinds, mut problems) = (Kinds::new(), Vec::new());
    let runs = sweeps::silenced(|| sweeps(&mut kinds, &mut problems));
    println!("{runs} runs: {kinds:?}");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    (runs, kinds)
}

/// Endings by kind.
type Kinds = std::collections::BTreeMap<String, usize>;

#[test]
fn every_run_ends_or_stops_typed_with_what_it_computed() {
    let (runs, kinds) = quietly(|k, p| {
        let mut runs = 0;
        runs += sweep("dpend", dpend::DoublePendulum::default, false, k, p);
        runs += sweep("seed2dof", seed2dof::Seed2dof::default, false, k, p);
        runs += sweep("chain8", chain8::Chain8::default, false, k, p);
        runs += sweep("arm3d_6", arm3d_6::Arm3d6::default, false, k, p);
        runs += sweep("tumble", tumble::TumbleBall::default, false, k, p);
        runs += sweep("top", top::Top::default, false, k, p);
        let spherical = spherical_pendulum::SphericalPendulumZyx::default();
        runs += sweep("spherical", || spherical.clone(), false, k, p);
        runs += sweep("springpend", springpend::SpringPend::default, false, k, p);
        runs += sweep("fourbar", fourbar::FourBar::default, true, k, p);
        let slidercrank = slidercrank::SliderCrankClosed::default();
        runs += sweep("slidercrank", || slidercrank.clone(), true, k, p);
        runs += sweep("pendulum3", pendulum3::Pendulum3::default, true, k, p);
        runs += sweep("fastlink", fastlink::FastLink::default, true, k, p);
        let cartesian = dpend_cartesian::DoublePendulumCartesian::default();
        runs += sweep("dpend_cartesian", || cartesian.clone(), true, k, p);
        let standing = hexapod::HexapodStanding::default();
        runs += sweep("hexapod_standing", || standing.clone(), false, k, p);
        runs
    });
    assert_eq!(runs, 2145);
    quoted::says(
        "docs/robustness.md",
        &[format!(
            "{} runs: {} finish, the others stop with one of {} typed failures",
            thousands(runs),
            thousands(count(&kinds, "finished")),
            quoted::word(kinds.len() - 1)
        )],
    );
    // the sweep reaches every kind of ending it is meant to test
    for kind in [
        "finished",
        "TooMuchWork",
        "NewtonDiverged",
        "UnstableStep",
        "SingularConfiguration",
        "ConstraintDrift",
        "InvalidOption",
        "ConstraintsUnsupported",
    ] {
        assert!(
            kinds.contains_key(kind),
            "no run ended in {kind}: {kinds:?}"
        );
    }
}

/// The same sweep on models wrapped with the sensitivities of their motion
/// (`Sensitivities`: NQ·(1 + NS) coordinates, one error control over the motion and each
/// parameter's), an open chain and a closed loop.
#[test]
fn every_run_with_sensitivities_ends_or_stops_typed() {
    use mbs::Sensitivities;
    let (runs, kinds) = quietly(|k, p| {
        let arm = || Sensitivities::new(sprung_arm::SprungArm::default()).unwrap();
        let fourbar = || Sensitivities::new(fourbar::SensitiveFourBar::default()).unwrap();
        sweep("sprung_arm sensitivities", arm, false, k, p)
            + sweep("fourbar sensitivities", fourbar, true, k, p)
    });
    assert!(kinds.contains_key("finished"), "{kinds:?}");
    quoted::says(
        "docs/robustness.md",
        &[format!(
            "the same holds for {runs} runs with the sensitivities of two models' motion, {} finished",
            count(&kinds, "finished")
        )],
    );
}

/// Global error control (`simulate_global`) over every adaptive scheme and constraint method
/// at a loose and a middling tolerance: it returns a finite run whose estimate is within the
/// tolerance, or stops typed (`GlobalToleranceNotMet` keeping its most accurate complete
/// trajectory, or the first run's own failure) — never a panic or a non-finite value.
#[test]
fn every_globally_controlled_run_ends_or_stops_typed() {
    use mbs::{GlobalControl, simulate_global};
    fn each<M: Model + Clone + 'static>(
        name: &str,
        model: M,
        closed: bool,
        kinds: &mut Kinds,
        problems: &mut Vec<String>,
    ) -> usize {
        let control = GlobalControl {
            max_runs: 3,
            ..GlobalControl::default()
        };
        let mut runs = 0;
        for scheme in Scheme::all().into_iter().filter(|s| s.is_adaptive()) {
            for method in methods(closed) {
                for rtol in [1e-2, 1e-6] {
                    let mut o = Options {
                        max_steps: 20_000,
                        output: Output::Every { dt: 0.05 },
                        energy: false,
                        ..Options::adaptive(0.5, rtol)
                    };
                    o.constraints.method = method;
                    let tag = format!("{name} global {} {method:?} rtol {rtol:e}", scheme.name());
                    runs += 1;
                    let r = catch_unwind(AssertUnwindSafe(|| {
                        simulate_global(&model, scheme, &o, &control)
                    }));
                    if let Ok(Ok((_, _, report))) = &r
                        && (report.estimate.is_nan() || report.estimate > 1.0)
                    {
                        problems.push(format!("{tag}: returned at {}", report.estimate));
                    }
                    record(
                        &tag,
                        r.map(|r| r.map(|(tr, ..)| tr)),
                        "met",
                        kinds,
                        problems,
                    );
                }
            }
        }
        runs
    }
    let (runs, kinds) = quietly(|k, p| {
        each("dpend", dpend::DoublePendulum::default(), false, k, p)
            + each("tumble", tumble::TumbleBall::default(), false, k, p)
            + each("fourbar", fourbar::FourBar::default(), true, k, p)
            + each("fastlink", fastlink::FastLink::default(), true, k, p)
    });
    for kind in ["met", "GlobalToleranceNotMet"] {
        assert!(
            kinds.contains_key(kind),
            "no run ended in {kind}: {kinds:?}"
        );
    }
    quoted::says(
        "docs/robustness.md",
        &[format!(
            "for {runs} runs under global error control, {} met, {} `GlobalToleranceNotMet`",
            count(&kinds, "met"),
            count(&kinds, "GlobalToleranceNotMet")
        )],
    );
}

/// Every parameter of every model set to the edges of its range, one at a time: zero, its
/// opposite, a millionth and a million times its default, ±1e300, 1e-300, NaN and infinity.
/// `set_params` refuses a value with a typed `ParamError` that names the parameter or the
/// body, or the model runs (DOPRI5 and Radau5, 0.5 s) and ends or stops typed with what it
/// computed: never a panic or a non-finite value (a parameter the validation lets through,
/// such as a length of zero that stacks two joints, is the motion's to handle).
#[test]
fn every_parameter_at_its_edges_is_refused_or_runs_typed() {
    use mbs::Parameters;
    fn each<M: Model + Clone + 'static>(
        name: &str,
        model: M,
        kinds: &mut Kinds,
        problems: &mut Vec<String>,
    ) -> usize {
        let mut runs = 0;
        let defaults = model.params().values();
        for (k, &param) in M::Params::NAMES.iter().enumerate() {
            let v = defaults[k];
            for value in sweeps::parameter_edges(v) {
                let tag = format!("{name} {param} = {value:e}");
                let mut p = model.params().clone();
                if let Err(e) = p.set(param, value) {
                    problems.push(format!("{tag}: set refused a known name: {e}"));
                    continue;
                }
                let mut m = model.clone();
                let set = catch_unwind(AssertUnwindSafe(|| m.set_params(p)));
                match set {
                    Err(_) => {
                        problems.push(format!("{tag}: set_params panicked"));
                        continue;
                    }
                    Ok(Err(e)) => {
                        let text = e.to_string();
                        if text.trim().is_empty() {
                            problems.push(format!("{tag}: an empty refusal"));
                        }
                        if !value.is_finite() && !text.contains(param) {
                            problems
                                .push(format!("{tag}: a refusal that does not name it: {text}"));
                        }
                        *kinds.entry("ParamError".into()).or_default() += 1;
                        continue;
                    }
                    Ok(Ok(())) => {}
                }
                for scheme in [Scheme::Dopri5, Scheme::Radau5] {
                    let o = Options {
                        max_steps: 5_000,
                        output: Output::Every { dt: 0.05 },
                        energy: false,
                        ..Options::adaptive(0.5, 1e-6)
                    };
                    let tag = format!("{tag} {}", scheme.name());
                    runs += 1;
                    run_and_record(&tag, m.clone(), scheme, o, kinds, problems);
                }
            }
        }
        runs
    }
    let (runs, kinds) = quietly_finite_or_not(|k, p| {
        each("dpend", dpend::DoublePendulum::default(), k, p)
            + each("seed2dof", seed2dof::Seed2dof::default(), k, p)
            + each("chain8", chain8::Chain8::default(), k, p)
            + each("arm3d_6", arm3d_6::Arm3d6::default(), k, p)
            + each("tumble", tumble::TumbleBall::default(), k, p)
            + each("top", top::Top::default(), k, p)
            + each("springpend", springpend::SpringPend::default(), k, p)
            + each("sprung_arm", sprung_arm::SprungArm::default(), k, p)
            + each("fourbar", fourbar::FourBar::default(), k, p)
            + each(
                "slidercrank",
                slidercrank::SliderCrankClosed::default(),
                k,
                p,
            )
            + each("pendulum3", pendulum3::Pendulum3::default(), k, p)
            + each("fastlink", fastlink::FastLink::default(), k, p)
            + each(
                "dpend_cartesian",
                dpend_cartesian::DoublePendulumCartesian::default(),
                k,
                p,
            )
            + each(
                "hexapod_standing",
                hexapod::HexapodStanding::default(),
                k,
                p,
            )
    });
    println!("{runs} runs after the parameters were accepted");
    assert!(kinds.contains_key("ParamError"), "{kinds:?}");
    assert!(kinds.contains_key("finished"), "{kinds:?}");
    quoted::says(
        "docs/robustness.md",
        &[format!(
            "`set_params` refuses {} with a typed `ParamError` and of the {} runs of the others {} finish",
            thousands(count(&kinds, "ParamError")),
            thousands(runs),
            thousands(count(&kinds, "finished"))
        )],
    );
}

/// Every numeric option at the edges of its range, one at a time (0, −1, 1e-300, 1e300, NaN,
/// ±∞; counts 0, 1 and the largest; output times unsorted, repeated, before the start, NaN;
/// a start of the wrong length or not finite), on an open chain and a closed loop under an
/// explicit, an implicit and a fixed-step scheme: refused up front with a typed
/// `InvalidOption` that names the option, or run to an end or a typed stop with what it
/// computed; never a panic.
#[test]
fn every_option_at_its_edges_is_refused_or_runs_typed() {
    type Edit = Box<dyn Fn(&mut Options, f64)>;
    let float = |set: fn(&mut Options, f64)| -> Edit { Box::new(set) };
    let fields: Vec<(&str, Edit)> = vec![
        ("t0", float(|o, x| o.t0 = x)),
        ("t_end", float(|o, x| o.t_end = x)),
        ("h_max", float(|o, x| o.h_max = x)),
        ("h_min", float(|o, x| o.h_min = Some(x))),
        (
            "newton.tolerance_factor",
            float(|o, x| o.newton.tolerance_factor = x),
        ),
        ("newton.atol", float(|o, x| o.newton.atol = x)),
        ("newton.rtol", float(|o, x| o.newton.rtol = x)),
        (
            "newton.keep_below",
            float(|o, x| o.newton.keep_below = Some(x)),
        ),
        ("singularity_tol", float(|o, x| o.singularity_tol = x)),
        ("chart_switch", float(|o, x| o.chart_switch = x)),
        (
            "constraints.tolerance",
            float(|o, x| o.constraints.tolerance = x),
        ),
        (
            "constraints.drift_tol",
            float(|o, x| o.constraints.drift_tol = x),
        ),
        (
            "step (rtol)",
            float(|o, x| {
                if let StepControl::Adaptive { rtol, .. } = &mut o.step {
                    *rtol = x;
                }
            }),
        ),
        (
            "step (atol)",
            float(|o, x| {
                if let StepControl::Adaptive { atol, .. } = &mut o.step {
                    *atol = x;
                }
            }),
        ),
        (
            "step (h0 or h)",
            float(|o, x| match &mut o.step {
                StepControl::Adaptive { h0, .. } => *h0 = Some(x),
                StepControl::Fixed { h } => *h = x,
            }),
        ),
        (
            "output (dt)",
            float(|o, x| o.output = Output::Every { dt: x }),
        ),
        (
            "output (times)",
            float(|o, x| o.output = Output::Times(vec![0.5, x, 0.2])),
        ),
        ("q0", float(|o, x| o.q0 = Some(vec![x; 4]))),
        ("qd0", float(|o, x| o.qd0 = Some(vec![x; 2]))),
        (
            "max_steps",
            float(|o, x| o.max_steps = x.clamp(0.0, 1e9) as usize),
        ),
        (
            "newton.max_iterations",
            float(|o, x| o.newton.max_iterations = x.clamp(0.0, 1e9) as usize),
        ),
        (
            "constraints.max_iterations",
            float(|o, x| o.constraints.max_iterations = x.clamp(0.0, 1e9) as usize),
        ),
    ];
    let values = [
        0.0,
        -1.0,
        1e-300,
        1e300,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1.0,
    ];
    fn each<M: Model + Clone + 'static>(
        name: &str,
        model: M,
        fields: &[(&str, Edit)],
        values: &[f64],
        kinds: &mut Kinds,
        problems: &mut Vec<String>,
    ) -> usize {
        let mut runs = 0;
        for (field, edit) in fields {
            for &x in values {
                for (scheme, base) in [
                    (Scheme::Dopri5, Options::adaptive(0.3, 1e-6)),
                    (Scheme::Radau5, Options::adaptive(0.3, 1e-6)),
                    (Scheme::Rk4, Options::fixed(0.3, 1e-3)),
                ] {
                    let mut o = Options {
                        max_steps: 20_000,
                        energy: false,
                        ..base
                    };
                    edit(&mut o, x);
                    if o.max_steps > 20_000 {
                        // the largest count is a run bounded by t_end alone
                        o.max_steps = usize::MAX;
                    }
                    let tag = format!("{name} {} {field} = {x:e}", scheme.name());
                    runs += 1;
                    run_and_record(&tag, model.clone(), scheme, o, kinds, problems);
                }
            }
        }
        runs
    }
    // a start of 1e300 rad/s overflows the forces: `NonFinite` at the start is its answer
    let (runs, kinds) = quietly_finite_or_not(|k, p| {
        each(
            "dpend",
            dpend::DoublePendulum::default(),
            &fields,
            &values,
            k,
            p,
        ) + each(
            "fourbar",
            fourbar::FourBar::default(),
            &fields,
            &values,
            k,
            p,
        )
    });
    println!("{runs} runs");
    assert!(kinds.contains_key("InvalidOption"), "{kinds:?}");
    assert!(kinds.contains_key("finished"), "{kinds:?}");
    quoted::says(
        "docs/robustness.md",
        &[format!(
            "{} of {} runs refused up front with an `InvalidOption`",
            thousands(count(&kinds, "InvalidOption")),
            thousands(runs)
        )],
    );
}
