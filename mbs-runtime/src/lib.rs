//! The mbs runtime: the [`Model`] trait that `multibody!` implements, the integrators that
//! run it, their options, statistics and typed failures.
//!
//! Main types, in the order a user meets them: [`Model`] (what a generated model computes),
//! [`Scheme`] and [`Options`] (how to integrate it), [`simulate`] and [`Simulation`] (the
//! [`Integrator`]), [`Trajectory`] (outputs, CSV, JSON), [`Stats`] (the work done),
//! [`SimError`] and [`Failure`] (why a run stopped, with what it computed until then);
//! [`Parameters`], [`ModelInfo`], [`Energy`], [`Pose`], [`Kinematics`] describe models;
//! [`analysis`] finds equilibria, linearises, computes poles and modes and inverse dynamics.

// Matrix code reads best with explicit indices; `!(x > 0.0)` is meant to reject NaN too.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod analysis;
pub mod charts;
pub mod efforts;
pub mod elements;
pub(crate) mod erased;
pub mod error;
pub mod inertia;
pub mod integrators;
pub mod lanes;
pub mod linalg;
pub mod model;
pub mod muscle;
mod op_count;
pub mod options;
pub mod sensitivity;
pub mod spline;
pub mod stats;
pub mod tape;
pub mod terrain;
pub mod trajectory;

pub use analysis::{
    AnalysisError, Equilibrium, Linearization, Modes, Stability, StaticsOptions, linearize, modes,
    static_equilibrium,
};
pub use efforts::{Effort, Efforts, WithEfforts};
pub use error::{
    Failure, FlooredTolerance, GlobalFloor, GlobalLimit, HeldBy, HeldMost, LoopMatrix, ModelError,
    NearChangePoint, OutOfSteps, ParamError, check_inertia,
};
pub use integrators::{
    Assembly, Controller, EnsembleReport, GlobalControl, GlobalReport, GlobalRun, Inputs,
    Integrator, Member, SimError, Simulation, State, assemble, ensemble_supported, simulate,
    simulate_ensemble, simulate_ensemble_each, simulate_ensemble_of, simulate_global,
    simulate_with,
};
pub use lanes::{F64x4, LANES};
pub use model::{
    ConstraintTangents, DifferenceBuffers, Energy, FrameKinematics, IDENTITY3, Kinematics, Model,
    ModelInfo, OpCount, OpsTable, Parameters, PointKinematics, Pose, RotationJoint, ShapeInfo,
    ShapeKind, differenced_iteration_matrix, differenced_tangents,
};
/// The matrices of [`Linearization`] (nalgebra's), named without a dependency of one's own.
pub use nalgebra::DMatrix;
pub use options::{
    BdfParams, ConstraintMethod, ConstraintOptions, GenAlphaParams, HhtParams, IterationMatrix,
    NewmarkParams, NewtonOptions, Options, Output, Scheme, StepControl,
};
pub use sensitivity::Sensitivities;
pub use spline::Spline;
pub use stats::{ErrorTest, Stats};
pub use terrain::Terrain;
pub use trajectory::{CsvWriter, Observer, Trajectory, state_size};
