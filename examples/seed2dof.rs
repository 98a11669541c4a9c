//! The 2-dof system of the seed course: two 1 kg masses on a line, ground —k1— mass 1 —k2—
//! mass 2 (k1 = 79.15 N/m, k2 = 1961 N/m), no gravity, q = displacements from rest: the
//! `seed2dof` model of `tests/reference/MODELS.md`, eigenfrequencies 0.996 Hz and 10.018 Hz.
//!
//! Prints the model's sizes, M and h at the MODELS.md test state and the operation counts of
//! the generated functions. The model itself is in `examples/models/seed2dof.rs`.
//!
//! Then its two modes, from the linearisation at rest (`mbs::analysis::linearize` and
//! `modes`): frequency, damping ratio, eigenvalue, modal mass and shape of each.
//!
//! Then simulates it (`--scheme`, `--h` or `--rtol`, `--t-end`; `--help` for all), prints the
//! work done and the energy error, and writes a CSV with `--out DIR`.
//!
//! Run with `cargo run --release --example seed2dof -- --scheme newmark --rtol 1e-8 --out out`.

#[path = "common/mod.rs"]
mod common;
#[path = "models/seed2dof.rs"]
mod model;

use clap::Parser;
use mbs::IterationMatrix;
use mbs::analysis::{AnalysisError, linearize, modes};

/// Prints the modes of the linearisation at rest (q = 0, qd = 0).
fn print_modes(model: &model::Seed2dof) -> Result<(), AnalysisError> {
    let lin = linearize(model, 0.0, &[0.0; 2], &[0.0; 2], &[], IterationMatrix::Auto)?;
    println!("modes about rest:\n{}", modes(&lin, None)?);
    Ok(())
}

fn main() {
    let args = mbs::cli::RunArgs::parse();
    let model = model::Seed2dof::default();
    if !args.quiet {
        common::show(&model);
        if let Err(e) = print_modes(&model) {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
    if let Err(e) = args.run(model, 10.0) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
