//! The models the examples, tests and benchmarks of mbs share, one module per model, so that
//! each `multibody!` block is expanded and compiled once rather than in every program that
//! uses it. The canonical models of `tests/reference/MODELS.md` and the hard cases' models:
//!
//! | module | model |
//! |---|---|
//! | [`seed2dof`] | two masses and two springs on a line, with its exact solution |
//! | [`dpend`] | planar double pendulum of two uniform bars |
//! | [`dpend_cartesian`] | the same pendulum in 6 Cartesian coordinates and 4 constraints |
//! | [`arm3d_6`] | spatial arm of six revolute joints |
//! | [`chain8`], [`chain24`] | planar chains of 8 and 24 uniform bars |
//! | [`chain16_stiff`] | a chain of 16 bars with torsional springs of 1e6 N·m/rad in its joints |
//! | [`chain30_stiff`] | a swinging chain of 30 light bars with undamped stiff torsional springs |
//! | [`damped_chain`] | a chain of six bars with a viscous damper in every joint: fast modes that decay |
//! | [`hexapod`] | 24-dof walking robot, free and standing on its feet |
//! | [`hexapod_walker`] | the hexapod built to walk: outward legs, DC motors, gait generator, leg inverse kinematics, 1 kHz PIDs, terrain |
//! | [`human`] | human lower limbs for walking: 14 bodies, 23 coordinates, spline knee, patella, six contact ellipsoids per foot |
//! | [`pendulum3`] | Cash's index-3 pendulum in Cartesian coordinates |
//! | [`fourbar`] | a crank-rocker four-bar loop |
//! | [`fastlink`] | a fast two-loop linkage of five light bodies thrown by a stiff spring |
//! | [`slidercrank`] | a slider-crank, with its loop as constraints and in closed form |
//! | [`dc_motor`] | an arm driven by a DC motor under a sampled PI controller |
//! | [`sprung_arm`] | a double pendulum on rotational springs, three parameters marked `sensitive` |
//! | [`springpend`] | a point mass on a stiff spring (polar coordinates) |
//! | [`tumble`] | a free body tumbling about its intermediate axis, on two sets of Euler angles and on a spherical joint |
//! | [`top`] | a fast symmetric top on its tip whose axis passes through the vertical, on a spherical joint and on Euler angles |
//! | [`spherical_pendulum`] | a ball on a rod swinging through the bottom, on a spherical joint and on Euler angles |
//! | [`structural`] | models whose mass matrix is singular by construction |
//! | [`conserved`] | (not a model) energy and angular momentum of the rotation models, without charts |
//! | [`undefined_force`] | a pendulum whose generalized force is undefined after, or from, t = 0.5 |

pub mod arm3d_6;
pub mod chain16_stiff;
pub mod chain24;
pub mod chain30_stiff;
pub mod chain8;
pub mod conserved;
pub mod damped_chain;
pub mod dc_motor;
pub mod dpend;
pub mod dpend_cartesian;
pub mod fastlink;
pub mod fourbar;
pub mod hexapod;
pub mod hexapod_walker;
pub mod human;
pub mod pendulum3;
pub mod seed2dof;
pub mod slidercrank;
pub mod spherical_pendulum;
pub mod springpend;
pub mod sprung_arm;
pub mod structural;
pub mod top;
pub mod tumble;
pub mod undefined_force;
