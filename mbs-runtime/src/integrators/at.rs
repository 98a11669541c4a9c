//! Where the model is evaluated, as the schemes hand it over: a point (t, q, qd), the weights
//! of an iteration matrix, and a step written affine in the unknown accelerations.

/// A point of the motion: time, positions and velocities (borrowed).
#[derive(Clone, Copy, Debug)]
pub(crate) struct At<'a> {
    pub t: f64,
    pub q: &'a [f64],
    pub qd: &'a [f64],
}

impl<'a> At<'a> {
    pub fn new(t: f64, q: &'a [f64], qd: &'a [f64]) -> At<'a> {
        At { t, q, qd }
    }
}

/// The weights of an iteration matrix M + γ'·C_t + β'·K_t: β' = ∂q/∂a and γ' = ∂qd/∂a of a
/// step q = q̂ + β'a, qd = v̂ + γ'a.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Weights {
    pub beta: f64,
    pub gamma: f64,
}

/// A step as an implicit scheme writes it: q = q̂ + β'a, qd = v̂ + γ'a at time t, with the
/// accelerations a unknown.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Affine<'a> {
    pub t: f64,
    pub qhat: &'a [f64],
    pub vhat: &'a [f64],
    pub w: Weights,
}
