//! Analyses from the generated exact tangents: static equilibrium, linearisation, poles and
//! modes, inverse dynamics along a motion (EasyDyn's StaticEquilibrium, SaveLinearizedSystem,
//! ComputePoles; here without finite differences when the model has `option tangents`).

mod inverse;
mod linearize;
mod modes;
mod statics;

pub use inverse::{Efforts, inverse_dynamics_along, inverse_dynamics_of};
pub use linearize::{Linearization, linearize};
pub use modes::{Mode, Modes, modes};
pub use statics::{Equilibrium, Stability, StaticsOptions, static_equilibrium};

use crate::error::Failure;
use thiserror::Error;

/// Why an analysis failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// invalid input, singular matrix or non-finite value, as in simulations
    #[error(transparent)]
    Failure(#[from] Failure),
    #[error(
        "no static equilibrium found in {iterations} iterations: the largest free force is still {residual:e} at q = {q:?} (start closer, lock the coordinates that have no stiffness, or check that an equilibrium exists)"
    )]
    NotConverged {
        iterations: usize,
        residual: f64,
        q: Vec<f64>,
    },
}
