//! The mbs runtime: the [`Model`] trait that `multibody!` implements, its output records and
//! typed errors. Integrators and analyses build on it.
//!
//! Main types, in the order a user meets them: [`Model`] (what a generated model can
//! compute), [`Parameters`] (its parameter struct), [`ModelInfo`] (names, sizes, op counts),
//! [`Energy`], [`Pose`] and [`Kinematics`] (outputs), [`ParamError`] and [`ModelError`].

// Matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

pub mod error;
pub mod inertia;
pub mod model;

pub use error::{ModelError, ParamError, check_inertia};
pub use model::{
    Energy, FrameKinematics, Kinematics, Model, ModelInfo, OpCount, OpsTable, Parameters,
    PointKinematics, Pose,
};
