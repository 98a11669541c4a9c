//! Planar double pendulum of two uniform bars (1 m, 1 kg), hinged at the origin and end to end
//! about +z, under gravity: the `dpend` model of `tests/reference/MODELS.md`.
//!
//! Prints the model's sizes, M and h at the MODELS.md test state and the operation counts of
//! the generated functions. The model itself is in `models/src/dpend.rs`.
//!
//! Then the statics (`mbs::analysis::static_equilibrium`): the equilibria found from near the
//! hanging position and from near the upright one, with their stability (stable, unstable),
//! and the small-oscillation modes about the hanging position (`linearize`, `modes`).
//!
//! Then simulates it (`--scheme`, `--h` or `--rtol`, `--t-end`; `--help` for all), prints the
//! work done and the energy error, and writes a CSV with `--out DIR`.
//!
//! Run with `cargo run --release --example dpend -- --scheme newmark --rtol 1e-8 --out out`.

#[path = "common/mod.rs"]
mod common;
use mbs_models::dpend as model;

use clap::Parser;
use mbs::IterationMatrix;
use mbs::analysis::{AnalysisError, StaticsOptions, linearize, modes, static_equilibrium};
use std::f64::consts::PI;

/// Equilibria from near hanging and near upright, then the modes about the hanging one.
fn statics(model: &model::DoublePendulum) -> Result<(), AnalysisError> {
    // q[0]: bar 1 from the downward vertical; q[1]: bar 2 relative to bar 1
    let mut hanging = Vec::new();
    for (name, q0) in [("hanging", [0.1, -0.1]), ("upright", [PI - 0.1, 0.1])] {
        let options = StaticsOptions {
            q0: Some(q0.to_vec()),
            ..Default::default()
        };
        let eq = static_equilibrium(model, &options)?;
        println!(
            "{name}: from q = [{:.4}, {:.4}] to q = [{:.6}, {:.6}]: {eq}",
            q0[0], q0[1], eq.q[0], eq.q[1]
        );
        if name == "hanging" {
            hanging = eq.q;
        }
    }
    let lin = linearize(model, 0.0, &hanging, &[0.0; 2], &[], IterationMatrix::Auto)?;
    println!(
        "\nsmall oscillations about the hanging position:\n{}",
        modes(&lin, None)?
    );
    Ok(())
}

fn main() {
    let args = mbs::cli::RunArgs::parse();
    let model = model::DoublePendulum::default();
    args.sweep_if_asked(&model, 10.0);
    if !args.quiet {
        common::show(&model);
        if let Err(e) = statics(&model) {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
    if let Err(e) = args.run(model, 10.0) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
