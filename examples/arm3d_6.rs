//! Spatial serial arm of six revolute joints (axes z, y, z, y, z, y), 0.3 m links of 1 kg,
//! under gravity along −z: the `arm3d_6` model of `tests/reference/MODELS.md`.
//!
//! Prints the model's sizes, M and h at the MODELS.md test state and the operation counts of
//! the generated functions. The model itself is in `examples/models/arm3d_6.rs`.
//!
//! Run with `cargo run --release --example arm3d_6`.

#[path = "common/mod.rs"]
mod common;
#[path = "models/arm3d_6.rs"]
mod model;

fn main() {
    common::show(&model::Arm3d6::default());
}
