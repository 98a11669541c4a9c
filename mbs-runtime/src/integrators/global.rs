//! Global error control: `rtol` as a bound on the error of the whole trajectory.
//!
//! Every adaptive scheme controls the error of one step. How much of it reaches the end
//! depends on the motion: a crank that turns three times or a linkage that passes near a
//! dead point amplifies each step's error, and the trajectory comes out 1.5–3 digits short of
//! rtol on such models whatever the scheme (`tests/tolerance_proportionality.rs`). No local
//! test sees this. [`simulate_global`] measures it: it integrates again at a tighter tolerance
//! and takes the difference of the two runs at the same output times as the error of the
//! looser one (global error estimation by reintegration, Shampine, *Numerical Solution of
//! Ordinary Differential Equations*, 1994, §4.3; Hairer, Nørsett & Wanner I, §II.4). When the
//! estimate exceeds the tolerance, it runs again with a local tolerance chosen from the
//! estimates, until an estimate is within the tolerance.
//!
//! **What is measured.** The state of [`Trajectory::measured_states`] (q and qd; a rotation
//! joint by its rotation and angular velocity, so chart switches at different times do not
//! count) at each output, in the user's weights: the estimate is
//!
//! ```text
//! E = max over outputs and components |y_k − y_k+1| / (atol + rtol·|y_k+1|)
//! ```
//!
//! of two runs k (looser) and k + 1 (tighter), divided by 1 − ρ^s (ρ the ratio of their
//! tolerances, s the measured rate at which the error follows the local tolerance, 1 at
//! first), so that E ≤ 1 means the looser run is within atol + rtol·|y| everywhere. With atol
//! = rtol/100 this is the Test Set's mixed error with floor 0.01, divided by rtol. Extra
//! states (muscles, motors) and multipliers are not measured.
//!
//! **The sequence of runs.** Run 0 at the user's (rtol, atol), run 1 at a tenth of both. After
//! each pair, if E ≤ 1 the looser run of the pair is returned with E, its estimated error (the
//! tighter one only measured it; returning it would give a result more accurate than asked by
//! an unmeasured amount). Otherwise the next local tolerance is a tenth of the last when the
//! last run is predicted within half the tolerance (it only needs checking), or whatever the
//! measured rate s predicts brings it to 0.3 of the tolerance (at most 100× tighter in one
//! go). The rate is re-measured from each pair of estimates (clamped to [0.3, 2]).
//!
//! **The scheme's floor.** A scheme whose local error test holds a floor below some local
//! rtol ([`Stats::floor_from`]: the Newmark family, RKC, BDF, Radau at index 3) takes no more
//! steps below it: a run there is a run at its edge, and one at the edge checks nothing. The
//! candidates therefore stay at twice that rtol or above, the runs that check them at it or
//! above; when the last candidate lies below four times that rtol, the next run, at the edge,
//! only checks it, and a last run below twice that rtol ends the sequence
//! ([`GlobalFloor::Held`]). Generalized-α at index 3 on the four-bar at rtol 1e-4, its floor
//! held from local rtol 2.2e-8, chose a candidate at 1.2e-8 (the 100× step below from an
//! estimate of 1.8 and a slow rate), which no tighter run could check, and stopped
//! `GlobalToleranceNotMet` (`tests/global_error.rs`). Before, a checking run below the floor's
//! edge, which takes the steps of a run at the edge, counted as a run ten times tighter than
//! its candidate where it was less, and the estimate came out too small: over the tolerance
//! test's runs (`tests/tolerance_proportionality.rs`) eight returned as met were 0.01–0.26
//! digits short of rtol, and seven more (BDF at rtol 1e-8 on the Cartesian double pendulum
//! and the four-bar, Radau at index 3 on Cash's pendulum and the double pendulum) returned
//! within it, which a run at the floor's edge cannot show; all fifteen now end
//! `GlobalToleranceNotMet`, and the returned runs are at most 0.05 digits short.
//!
//! **When it stops.** The runs stop with [`Failure::GlobalToleranceNotMet`], keeping the most
//! accurate complete trajectory, after [`GlobalControl::max_runs`] runs, when the local rtol
//! would fall below [`GlobalControl::min_rtol`] (the two its `limit`, [`GlobalLimit`]), when a
//! run fails (its failure is the `cause`), at the scheme's floor as above, or when the tighter run of a pair takes at most 5 %
//! more steps than the looser one ([`GlobalFloor::NoMoreSteps`]): rtol then does not set the step (the Newmark family at index 2 holds its
//! local tolerance at 10⁴ε; Radau5 at index 2 takes no more steps either on fastlink and on
//! the Cartesian double pendulum at rtol 1e-4, `tests/tolerance_proportionality.rs`), the runs differ by the noise of Newton's iterations,
//! and their difference says nothing of the error: before this check, gen-α at index 2 on
//! the four-bar at rtol 1e-8 took the same steps (within a few) at local rtol 1e-8 and 1e-9,
//! and their difference called a run 1.9 digits short "within rtol" (the
//! tolerance-proportionality test now asserts that no returned run is more than 0.2 digits
//! short).
//!
//! **Cost.** Two runs at least, the second at a tenth of the tolerance: by the order, about
//! 2.6× one run for a 5th-order scheme, 3–4× for a 2nd-order one, more when the first run is
//! short of the tolerance (four runs for DOPRI5 on the four-bar at rtol 1e-6,
//! `tests/global_error.rs`). The work of every run is summed in [`GlobalReport::work`].
//!
//! **Outputs.** The runs are compared at the same times: [`Output::Times`] and
//! [`Output::Every`] are kept (the first run's output times are given to the others);
//! [`Output::Steps`] and [`Output::Last`] are replaced by [`GlobalControl::samples`] evenly
//! spaced times (steps differ from run to run). Sampled controllers hold state that a second
//! run could not start from again, so global control takes a model without
//! [`Inputs`](crate::Inputs).

use super::driver::{refused, simulate};
use super::sim_error::SimError;
use crate::error::{Failure, GlobalFloor, GlobalLimit};
use crate::model::Model;
use crate::options::{Options, Output, Scheme, StepControl};
use crate::stats::Stats;
use crate::trajectory::Trajectory;

/// Limits of [`simulate_global`].
#[derive(Clone, Debug, PartialEq)]
pub struct GlobalControl {
    /// runs in all before [`Failure::GlobalToleranceNotMet`] (default 6)
    pub max_runs: usize,
    /// the smallest local rtol a run may be given (default 1e-13)
    pub min_rtol: f64,
    /// output times compared when the options ask for every step or the last one (default
    /// 100, evenly spaced over (t0, t_end])
    pub samples: usize,
}

impl Default for GlobalControl {
    fn default() -> Self {
        GlobalControl {
            max_runs: 6,
            min_rtol: 1e-13,
            samples: 100,
        }
    }
}

/// One run of a global error control.
#[derive(Clone, Debug, PartialEq)]
pub struct GlobalRun {
    /// the local tolerances the scheme was given
    pub rtol: f64,
    pub atol: f64,
    pub steps: usize,
    /// the estimated global error of this run in the user's tolerance (≤ 1: met), measured
    /// against the next run; `None` for the last run
    pub estimate: Option<f64>,
}

/// What [`simulate_global`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct GlobalReport {
    /// every run, in order; the returned trajectory is the one before the last (the last only
    /// measured its error)
    pub runs: Vec<GlobalRun>,
    /// the estimated global error of the returned run, in the user's tolerance (≤ 1)
    pub estimate: f64,
    /// the measured rate s at which the error follows the local tolerance (1 when only one
    /// estimate was made)
    pub rate: f64,
    /// the work of all runs together
    pub work: Stats,
}

impl std::fmt::Display for GlobalReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "global error estimated at {:.2e} of the tolerance after {} runs (local rtol",
            self.estimate,
            self.runs.len()
        )?;
        for (i, r) in self.runs.iter().enumerate() {
            let sep = if i == 0 { " " } else { ", " };
            write!(f, "{sep}{:.1e}", r.rtol)?;
            if let Some(e) = r.estimate {
                write!(f, " → {e:.2e}")?;
            }
        }
        write!(f, "; {} steps in all)", self.work.steps)
    }
}

/// Runs `scheme` on copies of `model` until the estimated global error of the trajectory is
/// within the options' tolerances (module documentation). Returns the run whose error was
/// estimated within them, its `Stats`, and what the control did. A first run that fails
/// returns its own [`SimError`]; a later one that fails, an accuracy floor, or an estimate
/// still above the tolerance when the limits are reached returns
/// [`Failure::GlobalToleranceNotMet`] with the most accurate complete trajectory. Fixed steps
/// are refused (there is no tolerance to meet).
pub fn simulate_global<M: Model + Clone + 'static>(
    model: &M,
    scheme: Scheme,
    options: &Options,
    control: &GlobalControl,
) -> Result<(Trajectory, Stats, GlobalReport), SimError> {
    let StepControl::Adaptive { rtol, atol, h0 } = options.step else {
        return Err(refused(
            model,
            Failure::InvalidOption {
                name: "step",
                value: "fixed".into(),
                reason: "global error control needs adaptive steps (a tolerance to meet)",
            },
            options.t0,
        ));
    };
    if control.max_runs < 2
        || control.samples == 0
        || control.samples > 100_000_000
        || !(control.min_rtol > 0.0 && control.min_rtol < rtol)
    {
        return Err(refused(
            model,
            Failure::InvalidOption {
                name: "global control",
                value: format!("{control:?}"),
                reason: "needs max_runs ≥ 2, 1 ≤ samples ≤ 10⁸ and 0 < min_rtol < rtol",
            },
            options.t0,
        ));
    }
    let joints = model.info().rotation_joints;
    let run = |output: Output, r: f64, a: f64| {
        let o = Options {
            step: StepControl::Adaptive {
                rtol: r,
                atol: a,
                h0,
            },
            output,
            ..options.clone()
        };
        simulate(model.clone(), scheme, o)
    };
    let output = match &options.output {
        o @ (Output::Times(_) | Output::Every { .. }) => o.clone(),
        Output::Steps | Output::Last => {
            let (t0, t1, n) = (options.t0, options.t_end, control.samples);
            Output::Times(
                (1..=n)
                    .map(|k| (t0 + (t1 - t0) * (k as f64 / n as f64)).min(t1))
                    .collect(),
            )
        }
    };
    let (first, first_stats) = run(output, rtol, atol)?;
    if !first.t.iter().any(|&t| t > options.t0) {
        // nothing to compare: two runs would agree at t0 alone and "meet" any tolerance
        return Err(refused(
            model,
            Failure::InvalidOption {
                name: "output",
                value: format!("{:?}", options.output),
                reason: "global control compares its runs at outputs after t0, and this gives none: give output times after t0 (and t_end > t0)",
            },
            options.t0,
        ));
    }
    let times = Output::Times(first.t.clone());
    let mut work = first_stats.clone();
    // below this local rtol the scheme's error test holds its floor: a run there takes no
    // more steps than one at it, and checks nothing
    let floor_from = first_stats.floor_from;
    let mut runs = vec![GlobalRun {
        rtol,
        atol,
        steps: first_stats.steps,
        estimate: None,
    }];
    // the last run: the candidate the next run checks
    let mut last = (first.measured_states(joints), first, first_stats);
    let (mut rate, mut estimate) = (1.0_f64, f64::INFINITY);
    // (local rtol, estimate) of the last run estimated
    let mut prev: Option<(f64, f64)> = None;
    loop {
        let (r_last, a_last) = runs.last().map(|r| (r.rtol, r.atol)).expect("one run");
        let mut factor = match prev {
            None => 0.1,
            Some((r_prev, e_prev)) => {
                let predicted = e_prev * (r_last / r_prev).powf(rate);
                if predicted <= 0.5 {
                    0.1
                } else {
                    (0.3 / predicted).powf(1.0 / rate).clamp(1e-2, 0.1)
                }
            }
        };
        let not_met = |stop: Stop, work, traj: Trajectory, runs| {
            let t = traj.t.last().copied().unwrap_or(options.t0);
            let (floor, limit, cause) = match stop {
                Stop::Floor(f) => (Some(f), None, None),
                Stop::Limit(l) => (None, Some(l), None),
                Stop::Failed(f) => (None, None, Some(Box::new(f))),
            };
            SimError {
                kind: Failure::GlobalToleranceNotMet {
                    scheme: scheme.name(),
                    estimate,
                    rtol: r_last,
                    runs,
                    floor,
                    limit,
                    cause,
                },
                t,
                h: 0.0,
                stats: Box::new(work),
                trajectory: Box::new(traj),
            }
        };
        if let Some(from) = floor_from {
            if r_last < 2.0 * from * (1.0 - 1e-9) {
                // a run at the floor's edge (or below it, which takes the same steps) would be
                // less than twice as tight as the last: too close to check it (a candidate put
                // at twice the edge may land a rounding below it, and is checked)
                let held = Stop::Floor(GlobalFloor::Held { from });
                return Err(not_met(held, work, last.1, runs.len()));
            }
            if r_last * factor < 2.0 * from {
                factor = if r_last >= 4.0 * from {
                    // the tightest candidate a run at the floor's edge can still check
                    2.0 * from / r_last
                } else {
                    // the last candidate: the next run, at the floor's edge, checks it
                    from / r_last
                };
            }
        }
        let r_next = r_last * factor;
        if runs.len() >= control.max_runs {
            let limit = Stop::Limit(GlobalLimit::Runs {
                max_runs: control.max_runs,
            });
            return Err(not_met(limit, work, last.1, runs.len()));
        }
        if r_next < control.min_rtol {
            let limit = Stop::Limit(GlobalLimit::MinRtol {
                needed: r_next,
                min_rtol: control.min_rtol,
            });
            return Err(not_met(limit, work, last.1, runs.len()));
        }
        let a_next = a_last * factor;
        let (next, next_stats) = match run(times.clone(), r_next, a_next) {
            Ok(run) => run,
            Err(e) => {
                work.add_work(&e.stats);
                return Err(not_met(Stop::Failed(e.kind), work, last.1, runs.len() + 1));
            }
        };
        work.add_work(&next_stats);
        let states = next.measured_states(joints);
        let difference = distance(&last.0, &states, rtol, atol);
        if next_stats.steps as f64 <= 1.05 * last.2.steps as f64 {
            // a tenth of the tolerance and no more steps: rtol does not set the step (the
            // scheme holds its local tolerance at a floor), and the runs differ by noise
            let floor = Stop::Floor(GlobalFloor::NoMoreSteps);
            return Err(not_met(floor, work, last.1, runs.len() + 1));
        }
        // the tighter run's own error is ρ^s of the looser one's
        let ratio = factor.powf(rate.max(0.5));
        estimate = difference / (1.0 - ratio);
        runs.last_mut().expect("one run").estimate = Some(estimate);
        if let Some((r_prev, e_prev)) = prev
            && estimate > 0.0
            && e_prev > 0.0
        {
            rate = ((estimate / e_prev).ln() / (r_last / r_prev).ln()).clamp(0.3, 2.0);
        }
        prev = Some((r_last, estimate));
        runs.push(GlobalRun {
            rtol: r_next,
            atol: a_next,
            steps: next_stats.steps,
            estimate: None,
        });
        if estimate <= 1.0 {
            let report = GlobalReport {
                runs,
                estimate,
                rate,
                work,
            };
            return Ok((last.1, last.2, report));
        }
        last = (states, next, next_stats);
    }
}

/// What ended the runs of a [`Failure::GlobalToleranceNotMet`]: one of its `floor`, `limit`
/// and `cause`.
enum Stop {
    Floor(GlobalFloor),
    Limit(GlobalLimit),
    Failed(Failure),
}

/// max over outputs and components of |a − b| / (atol + rtol·|b|); infinite when the runs'
/// outputs do not line up.
fn distance(a: &[Vec<f64>], b: &[Vec<f64>], rtol: f64, atol: f64) -> f64 {
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    a.iter()
        .zip(b)
        .flat_map(|(ya, yb)| ya.iter().zip(yb))
        .map(|(x, y)| (x - y).abs() / (atol + rtol * y.abs()))
        .fold(0.0, f64::max)
}
