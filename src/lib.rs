//! # mbs — multibody dynamics from CAGeM-style kinematic chains
//!
//! Describe each body's position with homogeneous transforms in minimal coordinates, the way
//! EasyDyn's CAGeM does (`TOG[arm] = TOG[base] * Trotz(q[1]) * Tdisp(l, 0, 0)`); at compile time
//! [`multibody!`] differentiates the positions symbolically and emits a specialised model that
//! implements [`Model`]: M, h, τ, exact tangents, Jacobians, energies, all straight-line code.
//!
//! Main types, in the order you meet them: [`multibody!`] and its [language](language),
//! [`Model`] (what a generated model computes), [`Parameters`] (its parameter struct),
//! [`ModelInfo`] (names, sizes, op counts), [`Energy`], [`Pose`], [`Kinematics`],
//! [`ParamError`] and [`ModelError`].
//!
//! ```
//! use mbs::Model;
//!
//! mbs::multibody! {
//!     /// A mass on a spring.
//!     pub model Oscillator {
//!         param k = 100.0; param m = 1.0;
//!         dof x = 0.1;
//!         body mass { mass = m; }
//!         point anchor on ground at (0, 0, 0);
//!         TOG[mass] = Tdisp(1.0 + x, 0, 0);
//!         spring(anchor, mass, k = k, l0 = 1.0);
//!     }
//! }
//!
//! let model = Oscillator::default();
//! let (mut m, mut h) = ([0.0; 1], [0.0; 1]);
//! model.dynamics(0.0, &[0.1], &[0.0], &[], &mut m, &mut h);
//! assert!((h[0] / m[0] + 10.0).abs() < 1e-12); // x'' = -k x / m
//! ```

pub mod anim;
pub mod cli;
pub mod export;
pub mod gltf;
pub mod language;
pub mod plot;
pub mod spectral;
pub mod work_precision;

pub use mbs_macros::multibody;
pub use mbs_runtime::*;

#[doc(hidden)]
pub mod __private {
    pub use serde;
}

/// The README's code blocks run as doc-tests, so the front page cannot rot.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
