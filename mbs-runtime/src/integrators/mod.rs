//! Integration of `M(q,t) qdd = h(q, qd, t)` with the scheme the user picks. One driver
//! ([`Simulation`], the [`Integrator`] trait) runs every scheme: it validates options, starts
//! consistently (qdd(0) from M qdd = h), chooses steps, samples outputs, and turns every
//! failure into a typed [`SimError`] that keeps the trajectory computed so far. Schemes live
//! one per file and implement the internal `Stepper` trait.
//!
//! | scheme | file | order | steps |
//! |---|---|---|---|
//! | explicit Euler, RK4 | `explicit.rs` | 1, 4 | fixed (with a stability check) |
//! | Runge–Kutta–Chebyshev | `chebyshev.rs` | 2 | fixed or adaptive, stages from the fastest modes |
//! | Dormand–Prince 5(4) | `dopri5.rs` | 5 | adaptive or fixed, dense output |
//! | Newmark, HHT-α, generalized-α | `newmark.rs` | 2 | fixed or adaptive |
//! | implicit midpoint | `midpoint.rs` | 2 | fixed |
//! | BDF 1–5 | `bdf.rs` | 1–5 | adaptive, variable order |
//! | Radau IIA 3, 5 | `radau/` | 3, 5 | adaptive or fixed |
//!
//! The driver's parts: `driver.rs` (`Simulation`, `simulate`), `sim_error.rs` (`SimError`),
//! `stepper.rs` (the `Stepper` trait, `Attempt`, `Control`), `step_control.rs` (tolerances,
//! error norm, controllers, the first step), `dense.rs` (the default dense output),
//! `inputs.rs` (input functions and sampled controllers), `dispatch.rs` (the scheme's
//! `Stepper` and constraint method), `at.rs` (evaluation points, iteration-matrix weights,
//! affine steps), `problem/` (the model as the schemes see it), `constrained.rs` (closed
//! loops).

mod at;
mod bdf;
mod chebyshev;
pub(crate) mod constrained;
mod dense;
mod dispatch;
mod dopri5;
mod driver;
mod ensemble;
mod explicit;
mod global;
mod inputs;
mod midpoint;
mod newmark;
pub(crate) mod newton;
pub(crate) mod problem;
mod radau;
mod sim_error;
pub(crate) mod step_control;
mod stepper;

pub use constrained::{Assembly, assemble};
pub use driver::{Simulation, simulate, simulate_with};
pub use ensemble::{
    EnsembleReport, Member, ensemble_supported, simulate_ensemble, simulate_ensemble_each,
    simulate_ensemble_of,
};
pub use global::{GlobalControl, GlobalReport, GlobalRun, simulate_global};
pub use inputs::{Controller, Inputs};
pub use newmark::index3_iteration_matrix;
pub use sim_error::SimError;

pub(crate) use constrained::least_correction;
pub(crate) use dense::lerp_lambda;
pub(crate) use inputs::InputFn;
pub(crate) use problem::model_error_reason;
pub(crate) use stepper::{Attempt, Control, Step, Stepper};

use crate::stats::Stats;
use crate::trajectory::Trajectory;

/// A state of the motion.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub t: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    /// accelerations consistent with M qdd = h (or the scheme's own at this step)
    pub qdd: Vec<f64>,
    /// Lagrange multipliers of the constraints, one per named constraint (empty without)
    pub lambda: Vec<f64>,
}

impl State {
    pub(crate) fn zeros(n: usize, nc: usize) -> State {
        State {
            t: 0.0,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            lambda: vec![0.0; nc],
        }
    }

    pub(crate) fn copy_from(&mut self, o: &State) {
        self.t = o.t;
        self.q.copy_from_slice(&o.q);
        self.qd.copy_from_slice(&o.qd);
        self.qdd.copy_from_slice(&o.qdd);
        self.lambda.copy_from_slice(&o.lambda);
    }
}

/// One integrator interface for every scheme.
pub trait Integrator {
    /// Advances by one accepted step (retrying rejected attempts); records outputs it passes.
    fn step(&mut self) -> Result<(), SimError>;
    /// Advances until `t` (≤ t_end), recording outputs on the way.
    fn integrate_to(&mut self, t: f64) -> Result<(), SimError>;
    /// The current state.
    fn state(&self) -> &State;
    /// Work so far.
    fn stats(&self) -> &Stats;
    /// Outputs so far.
    fn trajectory(&self) -> &Trajectory;
}
