//! Typed errors of models and parameters.

use thiserror::Error;

/// A parameter value that no physical system has.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ParamError {
    #[error("parameter `{name}` is {value}: parameters must be finite")]
    NonFinite { name: &'static str, value: f64 },
    #[error("unknown parameter `{name}`; the parameters are: {known}")]
    Unknown { name: String, known: String },
    #[error(
        "body `{body}` has mass {value}: a body's mass must be positive (a massless part is a `frame`)"
    )]
    NonPositiveMass { body: &'static str, value: f64 },
    #[error("inertia of body `{body}` is not physical: {reason}")]
    InvalidInertia { body: &'static str, reason: String },
    #[error("spring number {index} has stiffness {value}: a stiffness must not be negative")]
    NegativeStiffness { index: usize, value: f64 },
}

/// A model asked for something it does not have.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ModelError {
    #[error(
        "model `{model}` was generated without tangents: add `option tangents;` to its multibody! block, or use an iteration matrix that needs none"
    )]
    TangentsNotGenerated { model: &'static str },
}

/// Checks an inertia tensor (xx, yy, zz, xy, xz, yz) about G; generated `validate()` calls it.
pub fn check_inertia(body: &'static str, t: [f64; 6]) -> Result<(), ParamError> {
    match crate::inertia::inertia_problem(t) {
        None => Ok(()),
        Some(reason) => Err(ParamError::InvalidInertia { body, reason }),
    }
}
