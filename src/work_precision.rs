//! Work–precision studies: what accuracy costs in time, scheme by scheme.
//!
//! A [`Study`] runs a model with several schemes, each over a sweep of tolerances (adaptive
//! steps) or of fixed steps, measures every run against a [`Reference`] and times it; the
//! result, a [`WorkPrecision`] table, prints itself (`Display`), writes CSV and draws the
//! work–precision diagram (error against CPU time, log–log, one line per scheme) through
//! [`crate::plot`].
//!
//! **Error measure.** The state is y = (q, qd), all coordinates then all velocities; a
//! rotation joint (`Tball`, `Tfree`, or Euler angles named by [`Study::euler_angles`]) is
//! measured without its chart: its three angles by the nine entries of its rotation, its
//! rates by its angular velocity in its own axes ([`state_size`]). At a
//! sampled time t the error of a run is the mixed relative error of the Test Set for IVP
//! Solvers (Mazzia & Magherini), with an absolute floor `a` for components near zero:
//!
//! ```text
//! e(t) = max_i |y_i(t) − y_ref,i(t)| / (a + |y_ref,i(t)|)        mescd = −log10 e(t_end)
//! ```
//!
//! The Test Set takes a = atol/rtol of the run; here a is one number for the whole study
//! ([`Study::floor`], default 1e-2: the atol/rtol of [`Study::atol_factor`]'s default), so
//! every run, adaptive or fixed-step, is measured in the same norm. `e_max` is the largest
//! e(t) over the reference's sampled times (the runs output exactly there, by the schemes'
//! own interpolation), so it also sees the error between steps.
//!
//! **Work.** `cpu` is the time of [`crate::simulate`] (set-up, start and integration, on the
//! calling thread, no energy recorded) on [`Study::clock`]: the thread's CPU time
//! (the `cpu-time` crate: `CLOCK_THREAD_CPUTIME_ID` on Unix, `GetThreadTimes` on Windows), which
//! other processes on a busy machine do not inflate, wall time where it cannot be read; the wall time is kept too. Both are the
//! best of up to [`Study::repeats`] repeats; the repeats stop early once a row has used
//! [`Study::repeat_budget`], and the count is in the `reps` column. Steps, rejections (error
//! test, Newton), evaluations of the model (M+h, forward dynamics, M, τ, tangents: [`Stats::evaluations`]) and
//! LU/Cholesky factorisations come from the run's [`Stats`]. A run that fails is a row of its
//! own with the typed [`Failure`], the time it reached and the work it had done: nothing is
//! dropped. The chart leaves out failures and runs without a correct digit (e ≥ 1).
//!
//! ```no_run
//! # mbs::multibody! { pub model Osc { param k = 100.0; dof x = 0.1;
//! #     body b { mass = 1.0; } TOG[b] = Tdisp(x, 0, 0); spring(ground, b, k = k, l0 = 0, axis = x); } }
//! use mbs::work_precision::{Reference, Setting, Study, Sweep, decades};
//! use mbs::{Options, Scheme};
//!
//! let times: Vec<f64> = (1..=10).map(|k| 0.1 * k as f64).collect();
//! let reference = Reference::compute(
//!     &Osc::default(), times, (Scheme::Dopri5, Setting::Rtol(1e-13)),
//!     Some((Scheme::Rk4, Setting::Step(1e-4))),
//!     &Options::default(),
//! ).unwrap();
//! let study = Study::new("oscillator", reference)
//!     .sweep(Sweep::adaptive(Scheme::Dopri5, &decades(4, 10)))
//!     .sweep(Sweep::fixed(Scheme::Rk4, &[1e-2, 5e-3, 2.5e-3]));
//! let table = study.run(&Osc::default()).unwrap();
//! println!("{table}");
//! std::fs::write("wp.csv", table.to_csv()).unwrap();
//! table.write_svg(std::path::Path::new("wp.svg")).unwrap();
//! ```

use crate::plot::{Chart, PlotError, Series};
use crate::{
    ConstraintMethod, Failure, GlobalControl, Model, Options, Output, RotationJoint, Scheme,
    SimError, Stats, StepControl, Trajectory, simulate, simulate_global,
};
use std::fmt::{self, Write as _};
use std::path::Path;
use std::time::{Duration, Instant};

/// The clock that times the runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    /// CPU time of the calling thread: what the run itself consumed
    ThreadCpu,
    /// elapsed time
    Wall,
}

impl Clock {
    /// The thread's CPU clock where it can be read, wall time otherwise.
    pub fn best() -> Clock {
        if thread_cpu_time().is_some() {
            Clock::ThreadCpu
        } else {
            Clock::Wall
        }
    }

    /// `thread CPU time` or `wall time`.
    pub fn name(self) -> &'static str {
        match self {
            Clock::ThreadCpu => "thread CPU time",
            Clock::Wall => "wall time",
        }
    }

    /// Runs `f` and returns its result, its time on this clock and its wall time.
    fn time<R>(self, f: impl FnOnce() -> R) -> (R, Duration, Duration) {
        let cpu0 = match self {
            Clock::ThreadCpu => thread_cpu_time(),
            Clock::Wall => None,
        };
        let start = Instant::now();
        let r = f();
        let wall = start.elapsed();
        let cpu = match (cpu0, thread_cpu_time()) {
            (Some(a), Some(b)) if self == Clock::ThreadCpu => b.saturating_sub(a),
            _ => wall,
        };
        (r, cpu, wall)
    }
}

/// CPU time consumed by the calling thread so far, `None` where it cannot be read.
fn thread_cpu_time() -> Option<Duration> {
    cpu_time::ThreadTime::try_now()
        .ok()
        .map(|t| t.as_duration())
}

/// One setting of a sweep: a relative tolerance (adaptive steps, atol = rtol ·
/// [`Study::atol_factor`]) or a fixed step h (s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    Rtol(f64),
    Step(f64),
}

impl Setting {
    /// `rtol` or `h`.
    pub fn kind(&self) -> &'static str {
        match self {
            Setting::Rtol(_) => "rtol",
            Setting::Step(_) => "h",
        }
    }

    /// The tolerance or the step.
    pub fn value(&self) -> f64 {
        match *self {
            Setting::Rtol(v) | Setting::Step(v) => v,
        }
    }
}

impl fmt::Display for Setting {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.kind(), short(self.value()))
    }
}

/// 1e-8, 2.5e-3, 0.04: a number in the shortest of `{:e}` and `{}`.
fn short(v: f64) -> String {
    let e = format!("{v:e}");
    let d = format!("{v}");
    if d.len() <= e.len() { d } else { e }
}

/// 10⁻ᶠʳᵒᵐ, 10⁻⁽ᶠʳᵒᵐ⁺¹⁾, … 10⁻ᵗᵒ: tolerances one decade apart.
pub fn decades(from: i32, to: i32) -> Vec<f64> {
    (from..=to).map(|k| 10f64.powi(-k)).collect()
}

/// h0, h0/2, … h0/2ⁿ⁻¹: `n` fixed steps, each half the last.
pub fn halvings(h0: f64, n: usize) -> Vec<f64> {
    (0..n).map(|k| h0 / 2f64.powi(k as i32)).collect()
}

/// One scheme over a sweep of settings, with the constraint method it uses on constrained
/// models (`None`: the study's [`Options::constraints`], `Auto` by default).
#[derive(Clone, Debug)]
pub struct Sweep {
    pub scheme: Scheme,
    pub settings: Vec<Setting>,
    pub constraints: Option<ConstraintMethod>,
    /// the legend of its line: the scheme's name, with the constraint method if given
    pub label: String,
    /// adaptive runs under global error control ([`mbs_runtime::simulate_global`]): the
    /// row's time and work are those of all its runs (default `None`: one run, local control)
    pub global: Option<GlobalControl>,
}

impl Sweep {
    /// Adaptive steps at each relative tolerance.
    pub fn adaptive(scheme: Scheme, rtols: &[f64]) -> Sweep {
        Sweep {
            scheme,
            settings: rtols.iter().map(|&r| Setting::Rtol(r)).collect(),
            constraints: None,
            label: scheme.name().to_string(),
            global: None,
        }
    }

    /// Fixed steps of each size h (s).
    pub fn fixed(scheme: Scheme, steps: &[f64]) -> Sweep {
        Sweep {
            scheme,
            settings: steps.iter().map(|&h| Setting::Step(h)).collect(),
            constraints: None,
            label: scheme.name().to_string(),
            global: None,
        }
    }

    /// The same sweep with constraints integrated by `method` (the label says which).
    pub fn with_constraints(mut self, method: ConstraintMethod) -> Sweep {
        self.constraints = Some(method);
        self.label = format!("{} ({})", self.scheme.name(), method.name());
        self
    }

    /// The same sweep under global error control with the default limits (the label says
    /// so): rtol bounds the error of the trajectory, not of a step.
    pub fn global(mut self) -> Sweep {
        self.global = Some(GlobalControl::default());
        self.label = format!("{} global", self.label);
        self
    }

    /// The same sweep under another legend.
    pub fn labelled(mut self, label: impl Into<String>) -> Sweep {
        self.label = label.into();
        self
    }
}

/// Where a reference comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// a closed-form solution
    Exact(String),
    /// data computed outside mbs (a file, another tool)
    Data(String),
    /// computed by mbs itself at an extreme tolerance (or a tiny fixed step): not independent
    /// of what it measures
    Computed {
        scheme: Scheme,
        setting: Setting,
        steps: usize,
        cpu: Duration,
        /// the second run that checks it, if any
        check: Option<(Scheme, Setting)>,
        /// what was computed, when it is not the studied model itself (see [`Reference::map`])
        note: String,
    },
}

impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Source::Exact(what) => write!(f, "exact: {what}"),
            Source::Data(what) => write!(f, "data: {what}"),
            Source::Computed {
                scheme,
                setting,
                steps,
                cpu,
                check,
                note,
            } => {
                write!(
                    f,
                    "SELF-COMPUTED by mbs with {} at {setting}{} ({steps} steps, {:.3} s)",
                    scheme.name(),
                    match setting {
                        Setting::Rtol(r) => format!(", atol {}", short(r * 1e-2)),
                        Setting::Step(_) => String::new(),
                    },
                    cpu.as_secs_f64()
                )?;
                if let Some((s, set)) = check {
                    write!(f, ", checked by {} at {set}", s.name())?;
                }
                if !note.is_empty() {
                    write!(f, "; {note}")?;
                }
                Ok(())
            }
        }
    }
}

/// The states a study measures against: y_ref = (q, qd) at sampled times, the last of which
/// is the end time of every run.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    pub source: Source,
    /// sorted, after t0; the last is t_end
    pub times: Vec<f64>,
    /// y_ref = (q, qd) at each time
    pub states: Vec<Vec<f64>>,
    /// a second, independent computation of the same states (another scheme): how far the
    /// two are apart estimates the reference's own error
    pub check: Option<Vec<Vec<f64>>>,
}

impl Reference {
    /// From a closed-form solution `y(t) = (q, qd)` at `times`.
    pub fn exact(what: impl Into<String>, times: Vec<f64>, y: impl Fn(f64) -> Vec<f64>) -> Self {
        let states = times.iter().map(|&t| y(t)).collect();
        Reference {
            source: Source::Exact(what.into()),
            times,
            states,
            check: None,
        }
    }

    /// From data computed elsewhere: `states[k]` = (q, qd) at `times[k]`.
    pub fn data(what: impl Into<String>, times: Vec<f64>, states: Vec<Vec<f64>>) -> Self {
        Reference {
            source: Source::Data(what.into()),
            times,
            states,
            check: None,
        }
    }

    /// Computed by mbs: `model` from its initial state (or `options.q0`, `qd0`) to the last of
    /// `times` with `primary` = (scheme, setting) (adaptive at atol = rtol/100, or a fixed
    /// step), outputs at `times`; with `check`, a second run (another scheme, or a tiny fixed
    /// step) whose distance from the first estimates the reference's error. `options` gives
    /// everything else (t0, initial state, constraint method, iteration matrix, max_steps);
    /// its step, output and t_end are replaced.
    pub fn compute<M: Model + Clone + 'static>(
        model: &M,
        times: Vec<f64>,
        primary: (Scheme, Setting),
        check: Option<(Scheme, Setting)>,
        options: &Options,
    ) -> Result<Reference, ReferenceError> {
        let t_end = times.last().copied().unwrap_or(options.t0);
        let opts = |setting: Setting| Options {
            t_end,
            step: match setting {
                Setting::Rtol(rtol) => StepControl::Adaptive {
                    rtol,
                    atol: rtol * 1e-2,
                    h0: None,
                },
                Setting::Step(h) => StepControl::Fixed { h },
            },
            output: Output::Times(times.clone()),
            energy: false,
            ..options.clone()
        };
        let start = Instant::now();
        let (tr, st) = simulate(model.clone(), primary.0, opts(primary.1)).map_err(|e| {
            ReferenceError::Run {
                scheme: primary.0.name(),
                error: Box::new(e),
            }
        })?;
        let cpu = start.elapsed();
        let check_run = check.map(|(scheme, setting)| (scheme, opts(setting)));
        let mut reference = Reference {
            source: Source::Computed {
                scheme: primary.0,
                setting: primary.1,
                steps: st.steps,
                cpu,
                check,
                note: String::new(),
            },
            states: tr.measured_states(model.info().rotation_joints),
            times,
            check: None,
        };
        if let Some((scheme, o)) = check_run {
            match simulate(model.clone(), scheme, o) {
                Ok((tc, _)) => {
                    reference.check = Some(tc.measured_states(model.info().rotation_joints));
                }
                Err(e) => {
                    // the reference itself is kept, without its check
                    if let Source::Computed { check, .. } = &mut reference.source {
                        *check = None;
                    }
                    return Err(ReferenceError::Check {
                        scheme: scheme.name(),
                        error: Box::new(e),
                        reference: Box::new(reference),
                    });
                }
            }
        }
        Ok(reference)
    }

    /// The same reference with every state (and check state) passed through `f(t, y)`: e.g.
    /// a reference computed on another formulation of the model, mapped to the studied
    /// model's coordinates. `what` says so in the source.
    pub fn map(mut self, what: &str, f: impl Fn(f64, &[f64]) -> Vec<f64>) -> Reference {
        let apply = |states: &mut Vec<Vec<f64>>| {
            for (y, &t) in states.iter_mut().zip(&self.times) {
                *y = f(t, y);
            }
        };
        apply(&mut self.states);
        if let Some(c) = self.check.as_mut() {
            apply(c);
        }
        match &mut self.source {
            Source::Computed { note, .. } => *note = what.to_string(),
            Source::Exact(s) | Source::Data(s) => {
                s.push_str("; ");
                s.push_str(what);
            }
        }
        self
    }

    /// The end time of the study: the last sampled time.
    pub fn t_end(&self) -> f64 {
        self.times.last().copied().unwrap_or(0.0)
    }

    /// The reference's estimated error: the largest mixed distance (floor `a`) between it and
    /// its check, at t_end and over all sampled times (`None` without a check).
    pub fn estimated_error(&self, floor: f64) -> Option<(f64, f64)> {
        let check = self.check.as_ref()?;
        let per: Vec<f64> = self
            .states
            .iter()
            .zip(check)
            .map(|(r, c)| mixed_error(c, r, floor))
            .collect();
        Some((
            per.last().copied().unwrap_or(0.0),
            per.iter().copied().fold(0.0, f64::max),
        ))
    }
}

pub use mbs_runtime::state_size;

/// Why [`Reference::compute`] gave no reference: its own run failed, or the run that checks
/// it did (the reference, computed, is then kept without its check).
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    #[error("the reference run ({scheme}) failed: {error}")]
    Run {
        scheme: &'static str,
        error: Box<SimError>,
    },
    #[error(
        "the run that checks the reference ({scheme}) failed: {error}; the reference itself was computed (kept in the error, without its check)"
    )]
    Check {
        scheme: &'static str,
        error: Box<SimError>,
        reference: Box<Reference>,
    },
}

/// max_i |y_i − r_i| / (a + |r_i|): the Test Set's mixed error with absolute floor `a`.
/// NaN when a component is not comparable (NaN or infinite) or the lengths differ: a state
/// that cannot be measured is never taken for an exact one.
pub fn mixed_error(y: &[f64], reference: &[f64], floor: f64) -> f64 {
    if y.len() != reference.len() {
        return f64::NAN;
    }
    y.iter()
        .zip(reference)
        .map(|(y, r)| (y - r).abs() / (floor + r.abs()))
        .fold(0.0, |m, e| {
            if e.is_nan() || m.is_nan() {
                f64::NAN
            } else {
                m.max(e)
            }
        })
}

/// Significant correct digits of a mixed error: −log10 e (+∞ for an exact result).
pub fn mescd(error: f64) -> f64 {
    -error.log10()
}

/// What to run and against what.
#[derive(Clone, Debug)]
pub struct Study {
    /// the model's name, in titles and the CSV
    pub title: String,
    pub reference: Reference,
    pub sweeps: Vec<Sweep>,
    /// absolute floor `a` of the mixed error (default 1e-2)
    pub floor: f64,
    /// atol = atol_factor · rtol for adaptive runs (default 1e-2, as [`Options::adaptive`])
    pub atol_factor: f64,
    /// timed repeats of each successful run, the best kept (default 3)
    pub repeats: usize,
    /// no further repeat once a row has taken this long (default 1 s)
    pub repeat_budget: Duration,
    /// what `cpu` measures (default [`Clock::best`])
    pub clock: Clock,
    /// everything else of a run (t0, initial state, constraint options, iteration matrix,
    /// max_steps …); its t_end, step, output and energy are set by the study
    pub options: Options,
    /// ZYX Euler angles (a, b, c) of a model without rotation joints, measured as a rotation
    /// joint's are (its rotation and angular velocity, [`state_size`]), so that the model
    /// compares with a twin on `Tball`/`Tfree` against the same reference (default none)
    pub euler_angles: Vec<[usize; 3]>,
}

/// Why a study could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StudyError {
    #[error("the reference has no sampled time")]
    NoTimes,
    #[error("the reference's times must be sorted, finite and after t0 = {t0}: {times:?}")]
    BadTimes { t0: f64, times: Vec<f64> },
    #[error("the reference has {states} states for {times} times")]
    StatesTimes { states: usize, times: usize },
    #[error(
        "reference state {index} has {len} components; the model needs {expected} (q then qd, a rotation joint's angles as the 9 entries of its rotation and its rates as its angular velocity)"
    )]
    StateSize {
        index: usize,
        len: usize,
        expected: usize,
    },
    #[error("{name} = {value} is invalid: {reason}")]
    Invalid {
        name: &'static str,
        value: String,
        reason: &'static str,
    },
    #[error(
        "reference state {index} has component {component} = {value}: a reference must be finite (a run that failed, or a function outside its domain?)"
    )]
    NonFiniteReference {
        index: usize,
        component: usize,
        value: f64,
    },
    #[error("the study has no sweep: add one with `Study::sweep`")]
    NoSweeps,
    #[error("sweep `{label}` has no setting: give it tolerances or steps")]
    EmptySweep { label: String },
    #[error(
        "sweep `{label}` asks for global error control on fixed steps: global control needs tolerances (`Sweep::adaptive`)"
    )]
    GlobalNeedsRtol { label: String },
}

impl Study {
    /// A study against `reference`, with no sweep yet and the defaults above.
    pub fn new(title: impl Into<String>, reference: Reference) -> Study {
        Study {
            title: title.into(),
            reference,
            sweeps: Vec::new(),
            floor: 1e-2,
            atol_factor: 1e-2,
            repeats: 3,
            repeat_budget: Duration::from_secs(1),
            clock: Clock::best(),
            options: Options::default(),
            euler_angles: Vec::new(),
        }
    }

    /// Adds a sweep.
    pub fn sweep(mut self, sweep: Sweep) -> Study {
        self.sweeps.push(sweep);
        self
    }

    /// The exact options of one run: reproduce a row with
    /// `mbs::simulate(model, sweep.scheme, study.options_for(&sweep, setting))`.
    pub fn options_for(&self, sweep: &Sweep, setting: Setting) -> Options {
        let mut o = Options {
            t_end: self.reference.t_end(),
            step: match setting {
                Setting::Rtol(rtol) => StepControl::Adaptive {
                    rtol,
                    atol: rtol * self.atol_factor,
                    h0: None,
                },
                Setting::Step(h) => StepControl::Fixed { h },
            },
            output: Output::Times(self.reference.times.clone()),
            energy: false,
            ..self.options.clone()
        };
        if let Some(m) = sweep.constraints {
            o.constraints.method = m;
        }
        o
    }

    fn validate(&self, nq: usize, rotation_joints: &[RotationJoint]) -> Result<(), StudyError> {
        let joints = rotation_joints.len();
        let r = &self.reference;
        if r.times.is_empty() {
            return Err(StudyError::NoTimes);
        }
        let t0 = self.options.t0;
        if r.times.iter().any(|t| !t.is_finite() || *t <= t0)
            || r.times.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(StudyError::BadTimes {
                t0,
                times: r.times.clone(),
            });
        }
        let sets = std::iter::once(&r.states).chain(r.check.as_ref());
        for states in sets {
            if states.len() != r.times.len() {
                return Err(StudyError::StatesTimes {
                    states: states.len(),
                    times: r.times.len(),
                });
            }
            let expected = state_size(nq, joints);
            if let Some((index, y)) = states.iter().enumerate().find(|(_, y)| y.len() != expected) {
                return Err(StudyError::StateSize {
                    index,
                    len: y.len(),
                    expected,
                });
            }
            for (index, y) in states.iter().enumerate() {
                if let Some(component) = y.iter().position(|v| !v.is_finite()) {
                    return Err(StudyError::NonFiniteReference {
                        index,
                        component,
                        value: y[component],
                    });
                }
            }
        }
        let invalid = |name, value: f64, reason| {
            Err(StudyError::Invalid {
                name,
                value: value.to_string(),
                reason,
            })
        };
        if !(self.floor >= 0.0 && self.floor.is_finite()) {
            return invalid("floor", self.floor, "must be ≥ 0 and finite");
        }
        if !(self.atol_factor > 0.0 && self.atol_factor.is_finite()) {
            return invalid(
                "atol_factor",
                self.atol_factor,
                "must be > 0 and finite (a run's atol must be > 0)",
            );
        }
        if self.repeats == 0 {
            return invalid("repeats", 0.0, "must be at least 1");
        }
        // the Euler angles named, with the model's own joints: coordinates, each in one joint
        let mut angles: Vec<usize> = rotation_joints.iter().flat_map(|j| j.angles).collect();
        let named = angles.len();
        angles.sort_unstable();
        angles.dedup();
        if angles.len() < named || angles.last().is_some_and(|&k| k >= nq) {
            return Err(StudyError::Invalid {
                name: "euler_angles",
                value: format!("{:?}", self.euler_angles),
                reason: "must name coordinates of the model (below its number of coordinates), each in one triple only and none of a `Tball` or `Tfree` joint's",
            });
        }
        if self.sweeps.is_empty() {
            return Err(StudyError::NoSweeps);
        }
        for sweep in &self.sweeps {
            if sweep.settings.is_empty() {
                return Err(StudyError::EmptySweep {
                    label: sweep.label.clone(),
                });
            }
            if sweep.global.is_some()
                && sweep.settings.iter().any(|s| matches!(s, Setting::Step(_)))
            {
                return Err(StudyError::GlobalNeedsRtol {
                    label: sweep.label.clone(),
                });
            }
        }
        Ok(())
    }

    /// Runs every setting of every sweep on a clone of `model`, in order, one at a time.
    pub fn run<M: Model + Clone + 'static>(&self, model: &M) -> Result<WorkPrecision, StudyError> {
        self.validate(M::NQ, &self.joints(model))?;
        let mut rows = Vec::new();
        for sweep in &self.sweeps {
            for &setting in &sweep.settings {
                rows.push(self.run_one(model, sweep, setting));
            }
        }
        Ok(WorkPrecision {
            title: self.title.clone(),
            source: self.reference.source.to_string(),
            t_end: self.reference.t_end(),
            samples: self.reference.times.len(),
            floor: self.floor,
            atol_factor: self.atol_factor,
            repeats: self.repeats,
            clock: self.clock,
            reference_error: self.reference.estimated_error(self.floor),
            rotations: !self.joints(model).is_empty(),
            rows,
        })
    }

    fn run_one<M: Model + Clone + 'static>(
        &self,
        model: &M,
        sweep: &Sweep,
        setting: Setting,
    ) -> Row {
        let options = self.options_for(sweep, setting);
        let method = (M::NC > 0).then_some(options.constraints.method);
        let (mut best, mut best_wall) = (Duration::MAX, Duration::MAX);
        let mut spent = Duration::ZERO;
        let mut repeats = 0;
        let mut last = None;
        while repeats < self.repeats && (repeats == 0 || spent < self.repeat_budget) {
            let (m, o) = (model.clone(), options.clone());
            let (result, cpu, wall) = self.clock.time(|| match &sweep.global {
                Some(g) if matches!(setting, Setting::Rtol(_)) => {
                    simulate_global(&m, sweep.scheme, &o, g)
                        .map(|(tr, _, report)| (tr, report.work))
                        .map_err(Box::new)
                }
                _ => simulate(m, sweep.scheme, o).map_err(Box::new),
            });
            repeats += 1;
            spent += wall;
            best = best.min(cpu);
            best_wall = best_wall.min(wall);
            let failed = result.is_err();
            last = Some(result);
            if failed {
                break; // a failure is recorded once, as it happened
            }
        }
        let row = |stats, outcome| Row {
            label: sweep.label.clone(),
            scheme: sweep.scheme,
            constraints: method,
            setting,
            cpu: best,
            wall: best_wall,
            repeats,
            stats,
            outcome,
        };
        match last.expect("at least one run") {
            Err(e) => {
                let SimError { kind, t, stats, .. } = *e;
                row(*stats, Err(RunFailure { kind, t }))
            }
            Ok((tr, stats)) => {
                let outcome = self.measure(model, &tr);
                row(stats, outcome)
            }
        }
    }

    /// The rotation joints a run is measured by: the model's, or `euler_angles` read as
    /// joints with the identity chart.
    fn joints<M: Model>(&self, model: &M) -> Vec<RotationJoint> {
        let mut joints = model.info().rotation_joints.to_vec();
        joints.extend(self.euler_angles.iter().map(|&angles| RotationJoint {
            frame: 0,
            angles,
            translation: None,
        }));
        joints
    }

    fn measure<M: Model + Clone>(
        &self,
        model: &M,
        tr: &Trajectory,
    ) -> Result<Accuracy, RunFailure> {
        let r = &self.reference;
        let y = tr.measured_states(&self.joints(model));
        let times_match = y.len() == r.times.len()
            && tr
                .t
                .iter()
                .zip(&r.times)
                .all(|(a, b)| (a - b).abs() <= 1e-9 * b.abs().max(1.0));
        if !times_match {
            // cannot happen with Output::Times unless the runtime changes: say so, do not guess
            return Err(RunFailure {
                kind: Failure::InvalidOption {
                    name: "output.times",
                    value: format!("{} outputs for {} reference times", y.len(), r.times.len()),
                    reason: "the run's outputs do not match the reference's times",
                },
                t: tr.t.last().copied().unwrap_or(f64::NAN),
            });
        }
        let errors: Vec<f64> = y
            .iter()
            .zip(&r.states)
            .map(|(y, r)| mixed_error(y, r, self.floor))
            .collect();
        let (k, e_max) =
            errors
                .iter()
                .enumerate()
                .fold(
                    (0, f64::NEG_INFINITY),
                    |(kb, b), (k, &e)| {
                        if e > b { (k, e) } else { (kb, b) }
                    },
                );
        let error_end = *errors.last().expect("at least one time");
        Ok(Accuracy {
            mescd: mescd(error_end),
            error_end,
            error_max: e_max,
            t_worst: r.times[k],
            drift: (M::NC > 0).then(|| tr.constraint_residual(model)),
        })
    }
}

/// How close a successful run came.
#[derive(Clone, Debug, PartialEq)]
pub struct Accuracy {
    /// −log10 of `error_end`
    pub mescd: f64,
    /// mixed error e(t_end)
    pub error_end: f64,
    /// largest e(t) over the sampled times, and where it was
    pub error_max: f64,
    pub t_worst: f64,
    /// constrained models: max |Φ| over the sampled outputs
    pub drift: Option<f64>,
}

/// A run that stopped early: the typed failure and the time reached.
#[derive(Clone, Debug, PartialEq)]
pub struct RunFailure {
    pub kind: Failure,
    pub t: f64,
}

impl RunFailure {
    /// The failure's variant name: `UnstableStep`, `TooMuchWork`, …
    pub fn name(&self) -> String {
        let d = format!("{:?}", self.kind);
        d.split(|c: char| !c.is_alphanumeric())
            .next()
            .unwrap_or("")
            .to_string()
    }
}

/// One run of a study.
#[derive(Clone, Debug)]
pub struct Row {
    /// the sweep's label
    pub label: String,
    pub scheme: Scheme,
    /// the constraint method, for constrained models
    pub constraints: Option<ConstraintMethod>,
    pub setting: Setting,
    /// best time on the study's [`Clock`] over `repeats` runs (the single run's time for a
    /// failure)
    pub cpu: Duration,
    /// best wall time over the same runs
    pub wall: Duration,
    pub repeats: usize,
    /// the work of the run (of the failed run up to its failure)
    pub stats: Stats,
    pub outcome: Result<Accuracy, RunFailure>,
}

/// The result of a study: one row per run, in the order of the sweeps.
#[derive(Clone, Debug)]
pub struct WorkPrecision {
    pub title: String,
    /// the reference's [`Source`], as text
    pub source: String,
    pub t_end: f64,
    /// how many sampled times
    pub samples: usize,
    pub floor: f64,
    pub atol_factor: f64,
    pub repeats: usize,
    pub clock: Clock,
    /// the reference's estimated error (at t_end, max over samples), when it was checked
    pub reference_error: Option<(f64, f64)>,
    /// whether rotations are measured by their matrices and angular velocities (a model with
    /// rotation joints or [`Study::euler_angles`])
    pub rotations: bool,
    pub rows: Vec<Row>,
}

const CSV_HEADER: &str = "model,scheme,label,constraints,setting,value,status,mescd,error_end,error_max,t_worst,drift,cpu_s,wall_s,repeats,steps,rejected_error,rejected_newton,evaluations,dynamics,forward_dynamics,mass_matrix,inverse_dynamics,tangents,factorizations,newton_iterations,failure,t_failure,message";

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

impl WorkPrecision {
    /// CSV: the header [`Self::csv_header`], then one line per run.
    pub fn to_csv(&self) -> String {
        let mut out = String::from(CSV_HEADER);
        out.push('\n');
        for r in &self.rows {
            let s = &r.stats;
            let (status, acc, fail) = match &r.outcome {
                Ok(a) => (
                    "ok",
                    format!(
                        "{},{:e},{:e},{},{}",
                        a.mescd,
                        a.error_end,
                        a.error_max,
                        a.t_worst,
                        a.drift.map(|d| format!("{d:e}")).unwrap_or_default()
                    ),
                    ",,".to_string(),
                ),
                Err(f) => (
                    "failed",
                    ",,,,".to_string(),
                    format!("{},{},{}", f.name(), f.t, csv_field(&f.kind.to_string())),
                ),
            };
            let _ = writeln!(
                out,
                "{},{},{},{},{},{:e},{status},{acc},{:e},{:e},{},{},{},{},{},{},{},{},{},{},{},{},{fail}",
                csv_field(&self.title),
                r.scheme.name(),
                csv_field(&r.label),
                r.constraints.map(|m| m.name()).unwrap_or(""),
                r.setting.kind(),
                r.setting.value(),
                r.cpu.as_secs_f64(),
                r.wall.as_secs_f64(),
                r.repeats,
                s.steps,
                s.rejected_error,
                s.rejected_newton,
                s.evaluations(),
                s.dynamics,
                s.forward_dynamics,
                s.mass_matrix,
                s.inverse_dynamics,
                s.tangents,
                s.factorizations,
                s.newton_iterations,
            );
        }
        out
    }

    /// The CSV's header line.
    pub fn csv_header() -> &'static str {
        CSV_HEADER
    }

    /// The chart and its lines: e(t_end) against CPU time, one line per sweep label (the
    /// successful runs with at least one correct digit, e < 1, in the sweep's order), and the
    /// reference's estimated error as a horizontal line when it was checked.
    pub fn chart(&self) -> (Chart, Vec<Series>) {
        let mut series: Vec<Series> = Vec::new();
        for r in &self.rows {
            let Ok(a) = &r.outcome else { continue };
            if a.error_end.is_nan() || a.error_end >= 1.0 {
                continue; // no correct digit: in the table and the CSV, not on the chart
            }
            let p = (r.cpu.as_secs_f64(), a.error_end);
            match series.iter_mut().find(|s| s.name == r.label) {
                Some(s) => s.points.push(p),
                None => series.push(Series {
                    name: r.label.clone(),
                    points: vec![p],
                }),
            }
        }
        if let Some((e, _)) = self.reference_error {
            let cpus = || {
                self.rows
                    .iter()
                    .filter(|r| r.outcome.is_ok())
                    .map(|r| r.cpu.as_secs_f64())
                    .filter(|c| *c > 0.0)
            };
            let lo = cpus().fold(f64::INFINITY, f64::min);
            let hi = cpus().fold(0.0, f64::max);
            if lo.is_finite() && hi > 0.0 && e > 0.0 {
                series.push(Series {
                    name: "reference's error (est.)".into(),
                    points: vec![(lo, e), (hi, e)],
                });
            }
        }
        let chart = Chart {
            title: format!("{}: error at t = {} s vs CPU time", self.title, self.t_end),
            x_label: format!("{} (s), best of ≤ {} runs", self.clock.name(), self.repeats),
            y_label: format!("mixed error at t_end (floor {})", short(self.floor)),
            size: (1000, 660),
            // fast and accurate at once: the corner no scheme reaches
            legend: crate::plot::Legend::LowerLeft,
            ..Chart::default()
        };
        (chart, series)
    }

    /// The SVG text of the work–precision diagram.
    pub fn svg(&self) -> Result<String, PlotError> {
        let (chart, series) = self.chart();
        crate::plot::line_chart_svg(&chart, &series)
    }

    /// Writes the diagram to `path`.
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        let (chart, series) = self.chart();
        crate::plot::line_chart(path, &chart, &series)
    }

    /// The rows of one label.
    pub fn rows_of<'a>(&'a self, label: &'a str) -> impl Iterator<Item = &'a Row> + 'a {
        self.rows.iter().filter(move |r| r.label == label)
    }

    /// The cheapest successful run reaching `digits` significant digits (mescd) at t_end.
    pub fn cheapest(&self, digits: f64) -> Option<&Row> {
        self.cheapest_per_label(digits).into_iter().next()
    }

    /// For each sweep label that reaches `digits` significant digits at t_end, its cheapest
    /// such run; sorted by CPU time, cheapest first.
    pub fn cheapest_per_label(&self, digits: f64) -> Vec<&Row> {
        let mut best: Vec<&Row> = Vec::new();
        for r in &self.rows {
            if !matches!(&r.outcome, Ok(a) if a.mescd >= digits) {
                continue;
            }
            match best.iter_mut().find(|b| b.label == r.label) {
                Some(b) if b.cpu <= r.cpu => {}
                Some(b) => *b = r,
                None => best.push(r),
            }
        }
        best.sort_by_key(|r| r.cpu);
        best
    }
}

impl fmt::Display for WorkPrecision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "work–precision: {} to t = {} s", self.title, self.t_end)?;
        writeln!(f, "reference: {}", self.source)?;
        if let Some((end, max)) = self.reference_error {
            writeln!(
                f,
                "reference's estimated error (distance to its check): {end:.1e} at t_end, {max:.1e} max"
            )?;
        }
        writeln!(
            f,
            "error e(t) = max_i |y_i − y_ref,i| / ({} + |y_ref,i|) over y = (q, qd){}; mescd = −log10 e(t_end); \
             e_max over {} sampled times; adaptive runs at atol = {}·rtol",
            short(self.floor),
            if self.rotations {
                ", rotations as matrices and angular velocities"
            } else {
                ""
            },
            self.samples,
            short(self.atol_factor)
        )?;
        writeln!(
            f,
            "CPU: {} of one run, best of `reps` (≤ {}); evals = M+h, forward-dynamics, M, τ and tangent evaluations; LU = factorisations",
            self.clock.name(),
            self.repeats
        )?;
        let drift = self.rows.iter().any(|r| r.constraints.is_some());
        let w = self
            .rows
            .iter()
            .map(|r| r.label.chars().count())
            .fold(6, usize::max);
        write!(
            f,
            "\n{:<w$} {:>12} {:>6} {:>9} {:>9} {:>10} {:>4} {:>8} {:>10} {:>9} {:>8}",
            "scheme",
            "setting",
            "mescd",
            "e(t_end)",
            "e_max",
            "CPU ms",
            "reps",
            "steps",
            "rej err/N",
            "evals",
            "LU"
        )?;
        if drift {
            write!(f, " {:>9}", "max |Φ|")?;
        }
        writeln!(f)?;
        for r in &self.rows {
            let s = &r.stats;
            let rej = format!("{}/{}", s.rejected_error, s.rejected_newton);
            let (mescd, e_end, e_max) = match &r.outcome {
                Ok(a) => (
                    format!("{:.2}", a.mescd),
                    format!("{:.2e}", a.error_end),
                    format!("{:.2e}", a.error_max),
                ),
                Err(_) => ("—".into(), "—".into(), "—".into()),
            };
            write!(
                f,
                "{:<w$} {:>12} {:>6} {:>9} {:>9} {:>10.3} {:>4} {:>8} {:>10} {:>9} {:>8}",
                r.label,
                r.setting.to_string(),
                mescd,
                e_end,
                e_max,
                r.cpu.as_secs_f64() * 1e3,
                r.repeats,
                s.steps,
                rej,
                s.evaluations(),
                s.factorizations
            )?;
            match &r.outcome {
                Ok(a) => {
                    if let (true, Some(d)) = (drift, a.drift) {
                        write!(f, " {d:>9.1e}")?;
                    }
                }
                Err(e) => write!(f, "  FAILED at t = {:.4} s: {}: {}", e.t, e.name(), e.kind)?,
            }
            writeln!(f)?;
        }
        Ok(())
    }
}

/// How one adaptive sweep's error follows its tolerance: the digits −log10 e_max of every run
/// against those of its rtol (tolerance proportionality). A sweep whose runs gain one digit
/// per decade of rtol, close to rtol itself, is one whose rtol means what it says.
#[derive(Clone, Debug, PartialEq)]
pub struct Proportionality {
    pub label: String,
    /// the sweep's tolerances, in its order
    pub rtols: Vec<f64>,
    /// −log10 e_max of each run; `None` where the run failed
    pub digits: Vec<Option<f64>>,
}

impl Proportionality {
    /// digits − (−log10 rtol) of each successful run: negative where the run is less accurate
    /// than rtol.
    pub fn offsets(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.rtols
            .iter()
            .zip(&self.digits)
            .filter_map(|(r, d)| d.map(|d| (*r, d + r.log10())))
    }

    /// The largest number of digits lost from one rtol to the next, tighter, one (0 when every
    /// tightening gained); failed runs, and exact ones (infinitely many digits), are skipped.
    pub fn largest_loss(&self) -> f64 {
        let ok: Vec<f64> = self
            .digits
            .iter()
            .flatten()
            .copied()
            .filter(|d| d.is_finite())
            .collect();
        ok.windows(2).map(|w| w[0] - w[1]).fold(0.0, f64::max)
    }

    /// Least-squares slope of the digits against −log10 rtol (1 for a proportional sweep);
    /// `None` below two successful runs at different tolerances (failed and exact runs do not
    /// count).
    pub fn slope(&self) -> Option<f64> {
        let pts: Vec<(f64, f64)> = self
            .rtols
            .iter()
            .zip(&self.digits)
            .filter_map(|(r, d)| d.map(|d| (-r.log10(), d)))
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect();
        let n = pts.len() as f64;
        let (mx, my) = pts
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let sxy: f64 = pts.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = pts.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
        (sxx > 0.0).then(|| sxy / sxx)
    }
}

impl WorkPrecision {
    /// The tolerance proportionality of every adaptive sweep, in the study's order (sweeps of
    /// fixed steps have no rtol to follow and are left out).
    pub fn proportionality(&self) -> Vec<Proportionality> {
        let mut out: Vec<Proportionality> = Vec::new();
        for r in &self.rows {
            let Setting::Rtol(rtol) = r.setting else {
                continue;
            };
            let digits = r.outcome.as_ref().ok().map(|a| -a.error_max.log10());
            match out.iter_mut().find(|p| p.label == r.label) {
                Some(p) => {
                    p.rtols.push(rtol);
                    p.digits.push(digits);
                }
                None => out.push(Proportionality {
                    label: r.label.clone(),
                    rtols: vec![rtol],
                    digits: vec![digits],
                }),
            }
        }
        out
    }

    /// The proportionality table: for each adaptive sweep, −log10 e_max at each rtol, the
    /// slope, the mean offset from rtol's digits and the largest loss when rtol tightens.
    pub fn proportionality_table(&self) -> String {
        let props = self.proportionality();
        let w = props
            .iter()
            .map(|p| p.label.chars().count())
            .fold(6, usize::max);
        let mut s = format!(
            "tolerance proportionality: {} (digits = −log10 e_max)\n{:<w$}",
            self.title, "scheme"
        );
        // every sweep's rtols, loosest first: a sweep over fewer leaves its other columns
        // blank (the first sweep's headed every row, and a shorter row shifted its slope,
        // offset and loss under the wrong headers)
        let mut rtols: Vec<f64> = props.iter().flat_map(|p| p.rtols.iter().copied()).collect();
        rtols.sort_by(|a, b| b.total_cmp(a));
        rtols.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * b.abs());
        for r in &rtols {
            let _ = write!(s, " {:>6}", short(*r));
        }
        let _ = writeln!(s, " {:>6} {:>7} {:>6}", "slope", "offset", "loss");
        for p in &props {
            let _ = write!(s, "{:<w$}", p.label);
            for r in &rtols {
                let at = p.rtols.iter().position(|x| (x - r).abs() <= 1e-9 * r.abs());
                match at.map(|k| p.digits[k]) {
                    Some(Some(d)) => {
                        let _ = write!(s, " {d:>6.2}");
                    }
                    Some(None) => {
                        let _ = write!(s, " {:>6}", "fail");
                    }
                    None => {
                        let _ = write!(s, " {:>6}", "");
                    }
                }
            }
            let offsets: Vec<f64> = p
                .offsets()
                .map(|(_, o)| o)
                .filter(|o| o.is_finite())
                .collect();
            let mean =
                (!offsets.is_empty()).then(|| offsets.iter().sum::<f64>() / offsets.len() as f64);
            let shown = |x: Option<f64>, w: usize| match x {
                Some(x) => format!("{x:>w$.2}"),
                None => format!("{:>w$}", "—"),
            };
            let _ = writeln!(
                s,
                " {} {} {:>6.2}",
                shown(p.slope(), 6),
                shown(mean, 7),
                p.largest_loss()
            );
        }
        s
    }
}
