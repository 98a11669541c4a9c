//! The double pendulum of `tests/reference/MODELS.md` (dpend) in Cartesian coordinates: each
//! bar free in the plane (x, y of its centre, θ its absolute angle), the two hinges as four
//! constraints, `top` (bar 1's top at the origin) and `knee` (bar 2's top at bar 1's bottom).
//! The model is in `models/src/dpend_cartesian.rs`.
//!
//! Prints the model, then runs it as asked (`--scheme`, `--h` or `--rtol`, `--constraints`,
//! `--t-end`, default 10 s): the assembly report, the work done, the energy error, the hinge
//! multipliers at a few times (−λ of `top.x`, `top.y` is the force of the hinge on bar 1;
//! λ of `knee.x`, `knee.y` the force of bar 2 on bar 1), the drift max |Φ|, and how far the
//! tip of bar 2 is from that of the two-angle dpend (`models/src/dpend.rs`) run with the
//! same scheme at the same times. dpend is chaotic: the two agree to 1e-7 up to about 8 s at
//! rtol 1e-10, over 10 s at rtol 1e-12 (`tests/loops.rs`).
//!
//! Run with `cargo run --release --example dpend_cartesian -- --rtol 1e-10` or
//! `-- --scheme gen-alpha --h 1e-4 --t-end 2`.

#[path = "common/mod.rs"]
mod common;
use mbs_models::dpend;
use mbs_models::dpend_cartesian as model;

use clap::Parser;
use mbs::Output;

fn main() {
    let args = mbs::cli::RunArgs::parse();
    let t_end = 10.0;
    args.sweep_if_asked(&model::DoublePendulumCartesian::default(), t_end);
    if !args.quiet {
        common::show(&model::DoublePendulumCartesian::default());
        println!();
    }
    let report = match args.run(model::DoublePendulumCartesian::default(), t_end) {
        Ok(report) => report,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let tr = &report.trajectory;
    // the two-angle dpend at the same times
    let mut options = args.options(t_end);
    options.output = Output::Times(tr.t.clone());
    let angles = match mbs::simulate(dpend::DoublePendulum::default(), report.scheme, options) {
        Ok((angles, _)) => angles,
        Err(e) => {
            eprintln!(
                "error in the two-angle dpend: {}",
                mbs::cli::RunError::Simulation(Box::new(e))
            );
            std::process::exit(1);
        }
    };
    if args.quiet {
        return;
    }
    common::print_multipliers(tr);
    println!(
        "\nconstraint drift: max |Φ| = {:.2e} over {} outputs",
        tr.constraint_residual(&model::DoublePendulumCartesian::default()),
        tr.len()
    );
    let mut gap = 0.0f64;
    for i in 0..tr.len() {
        let (x, y) = model::tip(tr.q(i));
        let q = angles.q(i);
        let (xa, ya) = (
            q[0].sin() + (q[0] + q[1]).sin(),
            -q[0].cos() - (q[0] + q[1]).cos(),
        );
        gap = gap.max((x - xa).abs().max((y - ya).abs()));
    }
    println!(
        "tip of bar 2 against the two-angle dpend ({}, same times): max |Δ| = {gap:.3e} m",
        report.scheme.name()
    );
}
