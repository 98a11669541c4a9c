//! The error of a simulation: why it stopped, where, and what it had computed until then.

use crate::error::{Failure, short};
use crate::stats::Stats;
use crate::trajectory::Trajectory;
use thiserror::Error;

/// A simulation that stopped early, with what it had computed until then: every recorded
/// output before the failure (never a non-finite value) and the work counters.
#[derive(Debug, Clone, Error)]
#[error("{kind} (at t = {}, h = {})", short(*.t), short(*.h))]
pub struct SimError {
    pub kind: Failure,
    /// time of the last accepted state
    pub t: f64,
    /// step being attempted
    pub h: f64,
    pub stats: Box<Stats>,
    pub trajectory: Box<Trajectory>,
}
