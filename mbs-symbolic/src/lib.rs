//! The mbs generator.
pub mod expr;
