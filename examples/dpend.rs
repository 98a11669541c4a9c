//! Planar double pendulum of two uniform bars (1 m, 1 kg), hinged at the origin and end to end
//! about +z, under gravity: the `dpend` model of `tests/reference/MODELS.md`.
//!
//! Prints the model's sizes, M and h at the MODELS.md test state and the operation counts of
//! the generated functions. The model itself is in `examples/models/dpend.rs`.
//!
//! Then simulates it (`--scheme`, `--h` or `--rtol`, `--t-end`; `--help` for all), prints the
//! work done and the energy error, and writes a CSV with `--out DIR`.
//!
//! Run with `cargo run --release --example dpend -- --scheme newmark --rtol 1e-8 --out out`.

#[path = "common/mod.rs"]
mod common;
#[path = "models/dpend.rs"]
mod model;

use clap::Parser;

fn main() {
    let args = mbs::cli::RunArgs::parse();
    let model = model::DoublePendulum::default();
    if !args.quiet {
        common::show(&model);
    }
    if let Err(e) = args.run(model, 10.0) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
