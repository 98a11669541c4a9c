//! The slider-crank of `tests/reference/MODELS.md`, a closed loop with one degree of freedom,
//! written twice (the models are in `models/src/slidercrank.rs`):
//!
//! - form (a): three coordinates (crank angle θ, rod angle ψ, slider position s) and the
//!   loop closed at the slider's pin by two constraints, `pin.x` and `pin.y`;
//! - form (b): θ alone, the rod angle in closed form ψ = −asin(r sin θ / l).
//!
//! Prints both models, then runs form (a) as asked (`--scheme`, `--h` or `--rtol`,
//! `--constraints`, `--t-end`, default 2 s: the crank passes three dead centres): the
//! assembly of its start, the work done, the energy error, the pin's multipliers at a few
//! times (λ of `pin.x` is the x force the rod applies to the slider), and the drift max |Φ|
//! over the outputs. Then runs form (b) with the same scheme at the same output times and
//! prints how far apart the two are in θ and in s.
//!
//! Run with `cargo run --release --example slidercrank -- --scheme gen-alpha --h 1e-4` or
//! `-- --scheme dopri5 --rtol 1e-10 --constraints partitioning`.

#[path = "common/mod.rs"]
mod common;
use mbs_models::slidercrank as model;

use clap::Parser;
use mbs::Output;

fn main() {
    let args = mbs::cli::RunArgs::parse();
    let t_end = 2.0;
    args.sweep_if_asked(&model::SliderCrank::default(), t_end);
    if !args.quiet {
        println!("form (a):");
        common::show(&model::SliderCrank::default());
        println!("\nform (b):");
        common::show(&model::SliderCrankClosed::default());
        println!("\nform (a), {} constraints:", args.constraints.name());
    }
    let a = match args.run(model::SliderCrank::default(), t_end) {
        Ok(report) => report,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let ta = &a.trajectory;
    // form (b) at the same times: same scheme and steps, no constraints
    let mut options = args.options(t_end);
    options.output = Output::Times(ta.t.clone());
    let scheme = a.scheme;
    let (tb, sb) = match mbs::simulate(model::SliderCrankClosed::default(), scheme, options) {
        Ok(run) => run,
        Err(e) => {
            // in the command line's words (its flags, not the library's options)
            eprintln!(
                "error in form (b): {}",
                mbs::cli::RunError::Simulation(Box::new(e))
            );
            std::process::exit(1);
        }
    };
    if args.quiet {
        return;
    }
    common::print_multipliers(ta);
    println!(
        "\nconstraint drift: max |Φ| = {:.2e} over {} outputs",
        ta.constraint_residual(&model::SliderCrank::default()),
        ta.len()
    );
    let (mut dth, mut ds) = (0.0f64, 0.0f64);
    for i in 0..ta.len() {
        let theta = tb.q(i)[0];
        dth = dth.max((ta.q(i)[0] - theta).abs());
        ds = ds.max((ta.q(i)[2] - model::closed_loop(theta).1).abs());
    }
    let e0 = tb.energy[0].total();
    println!(
        "\nform (b) with {}: {} steps, energy error {:.3e} (relative)",
        scheme.name(),
        sb.steps,
        tb.energy_drift().unwrap_or(0.0) / e0
    );
    println!(
        "form (a) − form (b) at the {} outputs: max |Δθ| = {dth:.3e} rad, max |Δs| = {ds:.3e} m",
        ta.len()
    );
}
