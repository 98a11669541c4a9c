//! Spatial serial arm of six revolute joints (axes z, y, z, y, z, y), 0.3 m links of 1 kg,
//! under gravity along −z: the `arm3d_6` model of `tests/reference/MODELS.md`.
//!
//! Prints the model's sizes, M and h at the MODELS.md test state and the operation counts of
//! the generated functions. The model itself is in `examples/models/arm3d_6.rs`.
//!
//! Run with `cargo run --release --example arm3d_6`.

#[path = "models/arm3d_6.rs"]
mod model;

use mbs::Model;
use model::Arm3d6;

fn main() {
    let model = Arm3d6::default();
    let info = model.info();
    let n = Arm3d6::NQ;
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
