//! # mbs — multibody dynamics from CAGeM-style kinematic chains
//!
//! Describe each body's position with homogeneous transforms in minimal coordinates, the way
//! EasyDyn's CAGeM does (`TOG[arm] = TOG[base] * Trotz(q[1]) * Tdisp(l, 0, 0)`); at compile time
//! [`multibody!`] differentiates the positions symbolically and emits a specialised model that
//! implements [`Model`]: M, h, τ, exact tangents, Jacobians, energies, all straight-line code.
//!
//! Main types, in the order you meet them: [`multibody!`] and its [language],
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
//!
//! ## Cargo features
//!
//! The tools around the models are behind features, all but `parquet` on by default:
//!
//! | feature | what | brings in |
//! |---|---|---|
//! | `plot` | `mbs::plot`, SVG line charts | plotters |
//! | `anim` | `mbs::anim`, the motion as one HTML page | — |
//! | `gltf` | `mbs::gltf`, the motion as a glTF 2.0 file | gltf-json, serde_json |
//! | `spectral` | `mbs::spectral`, amplification of one step of each scheme | `plot` |
//! | `work_precision` | `mbs::work_precision`, work–precision studies | `plot`, cpu-time |
//! | `cli` | `mbs::cli`, the per-system programs' command line | `plot`, `anim`, `gltf`, clap, indicatif, cpu-time |
//! | `expand` | the `mbs` program (`mbs expand`) | mbs-symbolic, syn, prettyplease, clap |
//! | `sweep` | `mbs::sweep`, many runs on every core or a Slurm job array | rayon, toml, csv, rand, indicatif, cpu-time, serde_json |
//! | `parquet` (not default) | a sweep's table also as Parquet (`mbs::sweep::parquet`) | `sweep`, parquet |
//! | `urdf` | `mbs::urdf`, URDF robots as `multibody!` source (`mbs import urdf` with `expand`) | roxmltree |
//!
//! With `default-features = false` you get [`multibody!`], the runtime ([`Model`], the schemes,
//! [`simulate`], [`analysis`], CSV and JSON output) and this documentation, nothing else:
//!
//! ```toml
//! [dependencies]
//! mbs = { version = "0.1", default-features = false }
//! ```

#[cfg(feature = "anim")]
pub mod anim;
#[cfg(feature = "cli")]
pub mod cli;
#[cfg(any(feature = "anim", feature = "gltf"))]
pub mod export;
#[cfg(feature = "gltf")]
pub mod gltf;
pub mod language;
#[cfg(feature = "plot")]
pub mod plot;
#[cfg(feature = "spectral")]
pub mod spectral;
#[cfg(feature = "sweep")]
pub mod sweep;
#[cfg(feature = "urdf")]
pub mod urdf;
#[cfg(feature = "work_precision")]
pub mod work_precision;

pub use mbs_macros::multibody;
pub use mbs_runtime::*;

#[doc(hidden)]
pub mod __private {
    pub use mbs_runtime::model::TwistTree;
    pub use mbs_runtime::tape;
    pub use serde;

    /// The `N` elements of `s` as an array, for the generated code's stores of runs of
    /// consecutive outputs (`*array_mut(&mut m[4..8]) = [a, b, c, d];`: one statement for
    /// the compiler's front end, written in place).
    #[inline(always)]
    pub fn array_mut<T, const N: usize>(s: &mut [T]) -> &mut [T; N] {
        s.try_into().expect("a range of N elements")
    }
}

/// The README's code blocks run as doc-tests, so the front page cannot rot.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
