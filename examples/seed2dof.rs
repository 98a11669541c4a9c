//! The 2-dof system of the seed course: two 1 kg masses on a line, ground —k1— mass 1 —k2—
//! mass 2 (k1 = 79.15 N/m, k2 = 1961 N/m), no gravity, q = displacements from rest: the
//! `seed2dof` model of `tests/reference/MODELS.md`, eigenfrequencies 0.996 Hz and 10.018 Hz.
//!
//! Prints the model's sizes, M and h at the MODELS.md test state and the operation counts of
//! the generated functions. The model itself is in `examples/models/seed2dof.rs`.
//!
//! Run with `cargo run --release --example seed2dof`.

#[path = "models/seed2dof.rs"]
mod model;

use mbs::Model;
use model::Seed2dof;

fn main() {
    let model = Seed2dof::default();
    let info = model.info();
    let n = Seed2dof::NQ;
    let bodies = info.is_body.iter().filter(|&&b| b).count();
    println!(
        "{}: {n} dof, {bodies} bodies, {} formulation",
        info.name, info.formulation
    );

    // The test state of MODELS.md: q_i = 0.5 sin(1.3 i + 0.4), qd_i = 0.7 cos(0.9 i + 0.2).
    let q: Vec<f64> = (0..n).map(|i| 0.5 * (1.3 * i as f64 + 0.4).sin()).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos()).collect();

    // M qdd = h; M is column-major: row i, column j is m[i + n * j].
    let mut m = vec![0.0; n * n];
    let mut h = vec![0.0; n];
    model.dynamics(0.0, &q, &qd, &[], &mut m, &mut h);

    println!("\nM and h at the test state:");
    for i in 0..n {
        print!("{:>6}", info.dof_label(i));
        for j in 0..n {
            print!(" {:>10.6}", m[i + n * j]);
        }
        println!("   | {:>10.6}", h[i]);
    }

    println!("\noperations per generated function:");
    println!(
        "{:<18} {:>6} {:>6} {:>6} {:>5} {:>6}",
        "function", "flops", "adds", "muls", "divs", "funcs"
    );
    for (function, ops) in info.ops {
        println!(
            "{function:<18} {:>6} {:>6} {:>6} {:>5} {:>6}",
            ops.flops(),
            ops.adds,
            ops.muls,
            ops.divs,
            ops.funcs
        );
    }
}
