//! A DC motor with a PI speed controller driving an arm (`models/src/dc_motor.rs`): the
//! motor current is an extra first-order state written in Rust (`WithEfforts`), the
//! controller is sampled at 1 kHz with zero-order hold (`Inputs::controller`).
//!
//! Prints the speed, current and voltage as the arm spins up to its set-point of 20 rad/s,
//! the final tracking error and the work done. The electrical time constant (L/R = 1 ms) is
//! far shorter than the mechanical one: the default scheme is Radau5.
//!
//! Run with `cargo run --release --example dc_motor` or `-- --scheme bdf --rtol 1e-8`.

use mbs_models::dc_motor as model;

use clap::Parser;
use mbs::{Inputs, Integrator, Options, Output, Scheme, Simulation, WithEfforts};

/// Simulation settings.
#[derive(Parser, Debug)]
struct Args {
    /// integration scheme
    #[arg(long, default_value = "radau5")]
    scheme: String,
    /// relative tolerance
    #[arg(long, default_value_t = 1e-8)]
    rtol: f64,
    /// end time (s)
    #[arg(long, default_value_t = 1.0)]
    t_end: f64,
}

fn main() {
    let args = Args::parse();
    let Some(scheme) = Scheme::from_name(&args.scheme) else {
        eprintln!("unknown scheme `{}`", args.scheme);
        std::process::exit(2);
    };
    let period = 1e-3;
    let model = WithEfforts::new(model::Arm::default(), model::Motor::default());
    let inputs = Inputs::new().controller(period, model::PiSpeed::new(20.0, period));
    let options = Options {
        output: Output::Every { dt: 0.05 },
        ..Options::adaptive(args.t_end, args.rtol)
    };
    let start = std::time::Instant::now();
    let mut sim = match Simulation::with_inputs(model, scheme, options, inputs) {
        Ok(sim) => sim,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    if let Err(e) = sim.integrate_to(args.t_end) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
    let cpu = start.elapsed();
    let (tr, stats) = sim.finish();
    let motor = model::Motor::default();
    println!(
        "{:>6} {:>12} {:>12} {:>12}",
        "t", "ω (rad/s)", "i (A)", "V (V)"
    );
    for i in (0..tr.len()).step_by(2) {
        let (w, current) = (tr.qd(i)[0], tr.qd(i)[1]);
        // the voltage is not recorded: back out V = L di/dt + R i + k ω_m
        let didt = tr.qdd(i)[1];
        let v = motor.l * didt + motor.r * current + motor.k * motor.gear * w;
        println!("{:>6.2} {w:>12.6} {current:>12.6} {v:>12.4}", tr.t[i]);
    }
    let w_end = tr.qd(tr.len() - 1)[0];
    println!(
        "\nspeed error at t = {}: {:.2e} rad/s; arm + motor + PI with {}, {:.1?}:\n{stats}",
        args.t_end,
        (w_end - 20.0).abs(),
        scheme.name(),
        cpu
    );
}
