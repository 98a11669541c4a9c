//! The `multibody!` language: `repeat` (loops and parts unrolled, indexed names folded),
//! `parse` (tokens → syntax tree with spans), then `check`
//! (names, shapes, constants → a [`System`](crate::mech::System)), collecting every error.

pub mod ast;
pub mod check;
pub mod edit_distance;
pub mod names;
pub mod parse;
pub mod repeat;

/// The admissibility check of inertia tensors, shared with the runtime's `validate()`.
#[path = "../../../mbs-runtime/src/inertia.rs"]
pub mod inertia;
