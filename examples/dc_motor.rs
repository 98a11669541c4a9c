//! A DC motor with a PI speed controller driving an arm (`models/src/dc_motor.rs`): the
//! motor current is an extra first-order state written in Rust (`WithEfforts`), the
//! controller is sampled at 1 kHz with zero-order hold (`Inputs::controller`).
//!
//! Prints the speed, current and voltage as the arm spins up to its set-point of 20 rad/s,
//! the final tracking error and the work done. The electrical time constant (L/R = 1 ms) is
//! far shorter than the mechanical one: the default scheme is Radau5.
//!
//! The shared command line (`mbs::cli`, `--help` for all) runs it with the controller as its
//! input, Radau5 at rtol 1e-8 and outputs every 50 ms unless told otherwise: `cargo run
//! --release --example dc_motor` or `-- --scheme bdf --rtol 1e-6 --out out`.

use mbs_models::dc_motor as model;

use mbs::cli::{RunArgs, RunError};
use mbs::{Inputs, WithEfforts};

fn main() {
    let args =
        RunArgs::parse_with_defaults(&[("scheme", "radau5"), ("rtol", "1e-8"), ("dt", "0.05")]);
    let period = 1e-3;
    let model = WithEfforts::new(model::Arm::default(), model::Motor::default());
    let inputs = Inputs::new().controller(period, model::PiSpeed::new(20.0, period));
    let report = match args.run_with(model, 1.0, inputs) {
        Ok(report) => report,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(match e {
                RunError::UnknownScheme(_) => 2,
                _ => 1,
            });
        }
    };
    if args.quiet {
        return;
    }
    let tr = &report.trajectory;
    let motor = model::Motor::default();
    println!(
        "\n{:>6} {:>12} {:>12} {:>12}",
        "t", "ω (rad/s)", "i (A)", "V (V)"
    );
    for i in (0..tr.len()).step_by(2) {
        let (w, current) = (tr.qd(i)[0], tr.qd(i)[1]);
        // the voltage is not recorded: back out V = L di/dt + R i + k ω_m
        let didt = tr.qdd(i)[1];
        let v = motor.l * didt + motor.r * current + motor.k * motor.gear * w;
        println!("{:>6.2} {w:>12.6} {current:>12.6} {v:>12.4}", tr.t[i]);
    }
    let last = tr.len() - 1;
    println!(
        "\nspeed error at t = {}: {:.2e} rad/s",
        tr.t[last],
        (tr.qd(last)[0] - 20.0).abs()
    );
}
