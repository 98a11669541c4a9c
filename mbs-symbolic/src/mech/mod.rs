//! Mechanics on the expression DAG: the system description, the frame tree, kinematics,
//! effects and the two formulations of the equations of motion.

pub mod constraints;
pub mod dynamics;
pub mod effects;
pub mod forward;
pub mod model;
pub mod recursive;
pub mod spatial;
pub mod spin;
pub mod system;
pub mod tree;
pub mod virtual_power;
pub mod world;

pub use dynamics::SceneEquations;
pub use model::{PointKin, SymbolicModel};
pub use system::System;
