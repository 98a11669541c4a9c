//! The interface between the driver and a scheme: `Stepper`, what an attempt gives
//! (`Attempt`), and the settings every attempt is handed (`Control`).

use super::State;
use super::constrained::{PARTITION_CLOSURE, PARTITION_MATRIX};
use super::newton::NewtonTol;
use super::problem::Problem;
use super::step_control::{PiController, Tolerances};
use crate::charts::Recentring;
use crate::error::Failure;
use crate::stats::ErrorTest;

/// What one attempted step gave.
pub(crate) enum Attempt {
    /// `next` holds the state at t + h
    Accepted { h_next: f64 },
    /// the local error test failed
    RejectedError { h_next: f64 },
    /// Newton did not converge (or an evaluation failed inside the step)
    RejectedNewton {
        h_next: f64,
        iterations: usize,
        correction: f64,
        cause: Option<Failure>,
    },
}

impl Attempt {
    /// An evaluation inside an explicit step failed with `e`: with adaptive steps a
    /// non-finite stage, or a stage whose dependent coordinates (partitioning) would not
    /// close or whose B over them is singular, is a step too large, retried at a quarter of
    /// h (`pi` told, so that the step does not grow right after; at h_min the failure is
    /// reported as the cause); anything else, or with a fixed step, is fatal. The accepted
    /// state's own completion is not a stage: its failures stay fatal.
    pub(crate) fn after_stage_failure(
        e: Failure,
        adaptive: bool,
        h: f64,
        pi: &mut PiController,
    ) -> Result<Attempt, Failure> {
        let too_large = match &e {
            Failure::NonFinite { .. } => true,
            Failure::ClosureFailed { what, .. } => *what == PARTITION_CLOSURE,
            Failure::SingularMatrix { matrix, .. } => *matrix == PARTITION_MATRIX,
            _ => false,
        };
        if adaptive && too_large {
            pi.rejected_otherwise();
            return Ok(Attempt::RejectedNewton {
                h_next: 0.25 * h,
                iterations: 0,
                correction: f64::INFINITY,
                cause: Some(e),
            });
        }
        Err(e)
    }
}

/// Step control and Newton settings handed to the schemes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Control {
    /// the local error's tolerances when adaptive
    pub adaptive: Option<Tolerances>,
    pub newton: NewtonTol,
    /// explicit fixed-step schemes check h·ρ against their stability region
    pub stability_check: bool,
}

/// One attempted step, as the driver hands it to a scheme: the model, the state the step
/// starts from, its size, the controls, and the state to fill when it is accepted.
/// A scheme takes it apart as `let Step(p, cur, h, ctl, next) = step;`.
pub(crate) struct Step<'a>(
    pub &'a mut Problem,
    pub &'a State,
    pub f64,
    pub &'a Control,
    pub &'a mut State,
);

/// A scheme, as the driver sees it.
pub(crate) trait Stepper {
    /// Called once with the consistent initial state.
    fn start(&mut self, _p: &mut Problem, _s: &State, _ctl: &Control) -> Result<(), Failure> {
        Ok(())
    }
    /// Attempts a step of size `step.h` from `step.cur`; on acceptance fills `step.next`.
    fn attempt(&mut self, step: Step<'_>) -> Result<Attempt, Failure>;
    /// The components the local error test measures with adaptive steps (after `start`).
    fn error_test(&self, _p: &Problem) -> ErrorTest {
        ErrorTest::PositionsVelocities
    }
    /// The relative tolerance the local error test holds for the user's `rtol` when the
    /// scheme's floor set it, not its transformation of rtol (`Stats::tolerance_floor`).
    fn tolerance_floor(&self, _rtol: f64) -> Option<f64> {
        None
    }
    /// Called after the driver re-centred the charts of rotation joints at the accepted
    /// state `s` (`moved` says which, and maps accelerations of the old charts into the new
    /// ones; `evaluated`: the model asked for its accelerations anew, so `s.qdd` was
    /// evaluated in the new charts, and the map covers only the joints' own coordinates). The
    /// step size stays the driver's; by default the scheme starts again from `s`. A scheme
    /// that keeps matrices or history in the coordinates drops or maps them.
    fn rechart(
        &mut self,
        p: &mut Problem,
        s: &State,
        ctl: &Control,
        moved: &[Recentring],
        evaluated: bool,
    ) -> Result<(), Failure> {
        let _ = (moved, evaluated);
        self.start(p, s, ctl)
    }
    /// The last error test (none for a scheme without one): whether it raised some
    /// component's weight to its rounding floor (`Stats::floored_steps`) and the component
    /// that weighed most (`Failure::StepTooSmall`, `Stats::held_most`).
    fn last_test(&self) -> super::step_control::ErrorNorm {
        Default::default()
    }
    /// The component of Newton's last correction with the largest weighted term, (block,
    /// index) as [`super::step_control::Argmax`] gives it (none for an explicit scheme):
    /// `Failure::NewtonDiverged` names it.
    fn newton_largest(&self) -> Option<(usize, usize)> {
        None
    }
    /// Called once the driver has accepted the step from `prev` to `cur`.
    fn accepted(&mut self, _p: &mut Problem, _prev: &State, _cur: &State) {}
    /// Dense output on [prev.t, cur.t]: by default the quintic Hermite interpolant of
    /// (q, qd, qdd) at both ends, accurate beyond every scheme's order here.
    fn interpolate(&mut self, prev: &State, cur: &State, t: f64, out: &mut State) {
        super::dense::hermite5(prev, cur, t, out);
    }
    /// The scheme as explicit stages, when it is one ([`Staged`]): an ensemble evaluates the
    /// stages of several runs together.
    fn staged(&mut self) -> Option<&mut dyn Staged> {
        None
    }
}

/// An explicit scheme's step taken apart at its evaluations, so that the stages of several
/// runs may be evaluated together ([`super::ensemble`]): [`Staged::begin`], then for each
/// stage s = 1..=[`Staged::stages`] its point, whose accelerations go into
/// [`Staged::accel_mut`], then [`Staged::complete`] — what [`Stepper::attempt`] does with one
/// evaluation at a time.
pub(crate) trait Staged {
    /// The evaluations of a step after the first (the state's own accelerations).
    fn stages(&self) -> usize;
    /// Starts an attempt of size h from `cur` (with a fixed step, its check against the
    /// scheme's stability region first).
    fn begin(&mut self, p: &mut Problem, cur: &State, h: f64, ctl: &Control)
    -> Result<(), Failure>;
    /// Stage `s`'s time as a fraction of h, and its positions and velocities, of a step of
    /// size h from `cur` (the stages before it evaluated); a point that is not finite is the
    /// failure `p` names.
    fn point(
        &mut self,
        p: &Problem,
        cur: &State,
        h: f64,
        s: usize,
    ) -> Result<(f64, &[f64], &[f64]), Failure>;
    /// Where stage `s`'s accelerations go.
    fn accel_mut(&mut self, s: usize) -> &mut [f64];
    /// The attempt, after the evaluation of a stage failed with `e`.
    fn stage_failed(&mut self, e: Failure, ctl: &Control, h: f64) -> Result<Attempt, Failure>;
    /// The attempt, every stage evaluated: error test, step size, dense output.
    fn complete(&mut self, step: Step<'_>) -> Result<Attempt, Failure>;
}
