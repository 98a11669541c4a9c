//! The four-bar of `tests/reference/MODELS.md`: a Grashof crank-rocker under gravity, three
//! absolute angles (crank `a`, coupler `b`, rocker `c`) and one closure,
//! `close: coincide(coupler_end, rocker_tip, along = [x, y])`. The model is in
//! `examples/models/fourbar.rs`.
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
#[path = "models/fourbar.rs"]
mod model;

use clap::Parser;
use mbs::{Model, Trajectory};

/// The multipliers of the named constraints at six times of the run.
fn print_multipliers(tr: &Trajectory) {
    print!("\n{:>8}", "t");
    for name in &tr.constraint_names {
        print!(" {:>14}", format!("λ {name}"));
    }
    println!();
    for k in 0..6 {
        let i = k * (tr.len() - 1) / 5;
        print!("{:>8.4}", tr.t[i]);
        for l in tr.lambda(i) {
            print!(" {l:>14.6}");
        }
        println!();
    }
}

/// max |Φ_i| over the outputs (the integrator's own states with `Output::Steps`; with
/// `--dt`, interpolated between them).
fn max_phi<M: Model>(model: &M, tr: &Trajectory) -> f64 {
    let mut phi = vec![0.0; M::NC];
    let mut worst = 0.0f64;
    for i in 0..tr.len() {
        model.constraints(tr.t[i], tr.q(i), &mut phi);
        worst = phi.iter().fold(worst, |w, p| w.max(p.abs()));
    }
    worst
}

fn main() {
    let args = mbs::cli::RunArgs::parse();
    let model = model::FourBar::default();
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
    print_multipliers(tr);
    println!(
        "\nconstraint drift: max |Φ| = {:.2e} over {} outputs; the crank turned {:.1} times",
        max_phi(&model::FourBar::default(), tr),
        tr.len(),
        (tr.q(tr.len() - 1)[0] - q[0]) / std::f64::consts::TAU
    );
}
