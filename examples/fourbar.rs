//! The four-bar of `tests/reference/MODELS.md`: a Grashof crank-rocker under gravity, three
//! absolute angles (crank `a`, coupler `b`, rocker `c`) and one closure,
//! `close: coincide(coupler_end, rocker_tip, along = [x, y])`. The model is in
//! `models/src/fourbar.rs`.
//!
//! The model gives only rough values of `b` and `c`; the start is assembled: Newton moves
//! `b` and `c` (the crank, marked `independent`, stays at π/3) until the loop closes on the
//! branch of the guess, and the velocities follow from the crank's 5 rad/s. Prints the model,
//! the assembly report and the assembled angles (against the closed-form loop), then runs it
//! as asked (`--scheme`, `--h` or `--rtol`, `--constraints`, `--t-end`, default 10 s) and
//! prints the work done, the energy error, the multipliers of `close.x` and `close.y` (the
//! force the coupler applies to the rocker) at a few times and the drift max |Φ|.
//!
//! Run with `cargo run --release --example fourbar -- --scheme gen-alpha --h 1e-3` or
//! `-- --scheme dopri5 --rtol 1e-8 --constraints projection --t-end 100`.

#[path = "common/mod.rs"]
mod common;
use mbs_models::fourbar as model;

use clap::Parser;
use mbs::Model;

fn main() {
    let args = mbs::cli::RunArgs::parse();
    let model = model::FourBar::default();
    args.sweep_if_asked(&model, 10.0);
    if !args.quiet {
        common::show(&model);
        let (mut q, mut qd) = ([0.0; 3], [0.0; 3]);
        model.initial_state(&mut q, &mut qd);
        println!(
            "\ndeclared start: a = {:.6}, b = {:.6}, c = {:.6} (rough), a' = {}",
            q[0], q[1], q[2], qd[0]
        );
    }
    let report = match args.run(model::FourBar::default(), 10.0) {
        Ok(report) => report,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    if args.quiet {
        return;
    }
    let tr = &report.trajectory;
    let (q, qd) = (tr.q(0), tr.qd(0));
    let (b, c) = model::closed_loop(q[0]);
    println!(
        "\nassembled start: b = {:.9}, c = {:.9} (closed form {b:.9}, {c:.9}); b' = {:.6}, c' = {:.6}",
        q[1], q[2], qd[1], qd[2]
    );
    common::print_multipliers(tr);
    println!(
        "\nconstraint drift: max |Φ| = {:.2e} over {} outputs; the crank turned {:.1} times",
        tr.constraint_residual(&model::FourBar::default()),
        tr.len(),
        (tr.q(tr.len() - 1)[0] - q[0]) / std::f64::consts::TAU
    );
}
