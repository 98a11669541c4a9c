//! Planar double pendulum of two uniform bars (1 m, 1 kg), hinged at the origin and end to end
//! about +z, under gravity: the `dpend` model of `tests/reference/MODELS.md`.
//!
//! Prints the model's sizes, M and h at the MODELS.md test state and the operation counts of
//! the generated functions. The model itself is in `examples/models/dpend.rs`.
//!
//! Run with `cargo run --release --example dpend`.

#[path = "common/mod.rs"]
mod common;
#[path = "models/dpend.rs"]
mod model;

fn main() {
    common::show(&model::DoublePendulum::default());
}
