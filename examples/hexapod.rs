//! A walking robot in the spirit of the seed's AMRU5: a 20 kg floating base and six 3-dof legs
//! with pantograph links and geared motor rotors, 24 dof and 49 bodies, under gravity, without
//! ground contact yet: the `hexapod` model of `tests/reference/MODELS.md`.
//!
//! Prints the model's sizes, a summary of M and h at the MODELS.md test state, the feet's
//! heights at the initial state and the operation counts of the generated functions. The
//! model itself is in `examples/models/hexapod.rs`.
//!
//! Run with `cargo run --release --example hexapod`.

#[path = "models/hexapod.rs"]
mod model;

use mbs::{Kinematics, Model};
use model::Hexapod;

fn main() {
    let model = Hexapod::default();
    let info = model.info();
    let n = Hexapod::NQ;
    let bodies = info.is_body.iter().filter(|&&b| b).count();
    println!(
        "{}: {n} dof, {bodies} bodies, {} points, {} formulation",
        info.name,
        info.points.len(),
        info.formulation
    );

    // The test state of MODELS.md: q_i = 0.5 sin(1.3 i + 0.4), qd_i = 0.7 cos(0.9 i + 0.2).
    let q: Vec<f64> = (0..n).map(|i| 0.5 * (1.3 * i as f64 + 0.4).sin()).collect();
    let qd: Vec<f64> = (0..n).map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos()).collect();

    // M qdd = h; M is column-major: row i, column j is m[i + n * j].
    let mut m = vec![0.0; n * n];
    let mut h = vec![0.0; n];
    model.dynamics(0.0, &q, &qd, &[], &mut m, &mut h);

    // 24 × 24 is too big to print: the diagonal and h, then a few global figures.
    println!(
        "\nat the test state:\n{:>14} {:>12} {:>12}",
        "dof", "M[i][i]", "h[i]"
    );
    for i in 0..n {
        println!(
            "{:>14} {:>12.6} {:>12.6}",
            info.dof_label(i),
            m[i + n * i],
            h[i]
        );
    }
    let asymmetry = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| (m[i + n * j] - m[j + n * i]).abs())
        .fold(0.0, f64::max);
    let min = m.iter().copied().fold(f64::INFINITY, f64::min);
    let max = m.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    println!("max |M - Mᵀ| = {asymmetry:.1e}, entries of M in [{min:.6}, {max:.6}]");

    // Feet at the initial state (base at z = 0.5 m, every leg at (a, b, c) = (0, 0.3, −0.3)).
    let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q0, &mut qd0);
    let mut kinematics = Kinematics::new::<Hexapod>();
    model.kinematics(0.0, &q0, &qd0, &mut kinematics);
    print!("\nfoot heights at the start (m):");
    for foot in &kinematics.points {
        print!(" {:.4}", foot.position[2]);
    }
    println!();

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
