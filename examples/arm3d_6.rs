//! Spatial serial arm of six revolute joints (axes z, y, z, y, z, y), 0.3 m links of 1 kg,
//! under gravity along −z: the `arm3d_6` model of `tests/reference/MODELS.md`.
//!
//! Prints the model's sizes, M and h at the MODELS.md test state and the operation counts of
//! the generated functions. The model itself is in `models/src/arm3d_6.rs`.
//!
//! Then the inverse dynamics of a smooth joint path (`mbs::analysis::inverse_dynamics_along`):
//! q_i(t) = q0_i + A (1 − cos(π t / T)) with q0_i = 0.2 rad, A = 0.5 rad, T = 2 s, i.e. every
//! joint turns by 1 rad, starting and ending at rest. The joint torques τ = M qdd − h are
//! sampled every 10 ms; prints them every 0.2 s and the peak |τ| of each joint, and writes
//! them all to `DIR/arm3d_6_torques.csv` with `--out DIR`.
//!
//! Then, unactuated, the arm falls from its declared pose under gravity: simulated as asked
//! (`--scheme`, `--h` or `--rtol`, `--t-end`, default 2 s; `--help` for all), with CSV, plots,
//! the animation and the glTF file in `--out DIR`.
//!
//! Run with `cargo run --release --example arm3d_6 -- --out out`.

#[path = "common/mod.rs"]
mod common;
use mbs_models::arm3d_6 as model;

use clap::Parser;
use mbs::Model;
use mbs::analysis::inverse_dynamics_along;
use model::Arm3d6;
use std::f64::consts::PI;

fn main() {
    let args = mbs::cli::RunArgs::parse();
    let model = Arm3d6::default();
    args.sweep_if_asked(&model, 2.0);
    if !args.quiet {
        common::show(&model);
    }
    if let Err(e) = torques_along_a_path(&model, &args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
    if let Err(e) = args.run(model, 2.0) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

/// Inverse dynamics along the path; the table unless `--quiet`, the CSV with `--out`.
fn torques_along_a_path(
    model: &Arm3d6,
    args: &mbs::cli::RunArgs,
) -> Result<(), Box<dyn std::error::Error>> {
    // the path and its derivatives
    let (amplitude, period) = (0.5, 2.0);
    let n = Arm3d6::NQ;
    let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q0, &mut qd0);
    let w = PI / period;
    let path = |t: f64| {
        let (c, s) = ((w * t).cos(), (w * t).sin());
        let q = q0.iter().map(|q0| q0 + amplitude * (1.0 - c)).collect();
        (
            q,
            vec![amplitude * w * s; n],
            vec![amplitude * w * w * c; n],
        )
    };
    let times: Vec<f64> = (0..=200).map(|k| k as f64 * 0.01).collect();
    let efforts = inverse_dynamics_along(model, &times, &[], path)?;
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)?;
        let path = dir.join("arm3d_6_torques.csv");
        efforts.write_csv(std::io::BufWriter::new(std::fs::File::create(&path)?))?;
        if !args.quiet {
            println!("wrote {}", path.display());
        }
    }
    if args.quiet {
        return Ok(());
    }

    println!("joint torques (N·m) along q_i(t) = 0.2 + 0.5 (1 − cos(π t / 2)):");
    print!("{:>6}", "t (s)");
    for name in &efforts.dof_names {
        print!(" {name:>9}");
    }
    println!();
    for i in (0..times.len()).step_by(20) {
        print!("{:>6.2}", times[i]);
        for tau in efforts.at(i) {
            print!(" {tau:>9.4}");
        }
        println!();
    }
    print!("{:>6}", "peak");
    for j in 0..n {
        let peak = (0..times.len())
            .map(|i| efforts.at(i)[j].abs())
            .fold(0.0, f64::max);
        print!(" {peak:>9.4}");
    }
    println!("\nthe arm, unactuated, falling from its declared pose:");
    Ok(())
}
