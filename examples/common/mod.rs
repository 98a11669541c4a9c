//! What the per-system examples share: the MODELS.md test state and the printing of a model's
//! sizes, M and h, and op counts.

use mbs::Model;

/// The test state of MODELS.md: q_i = 0.5 sin(1.3 i + 0.4), qd_i = 0.7 cos(0.9 i + 0.2).
pub fn test_state(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n).map(|i| 0.5 * (1.3 * i as f64 + 0.4).sin()).collect();
    let qd = (0..n).map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos()).collect();
    (q, qd)
}

/// Prints the model's sizes, M and h at the test state (whole for small models, the diagonal
/// and a summary for big ones) and the op counts of its generated functions.
pub fn show<M: Model>(model: &M) {
    let info = model.info();
    let n = M::NQ;
    println!(
        "{}: {n} dof, {} bodies, {} points, {} formulation",
        info.name,
        info.body_count(),
        info.points.len(),
        info.formulation
    );
    let (q, qd) = test_state(n);
    // M qdd = h; M is column-major: row i, column j is m[i + n * j]
    let mut m = vec![0.0; n * n];
    let mut h = vec![0.0; n];
    let u = vec![0.0; M::NU];
    model.dynamics(0.0, &q, &qd, &u, &mut m, &mut h);
    if n <= 8 {
        println!("\nM and h at the test state:");
        for i in 0..n {
            print!("{:>6}", info.dof_label(i));
            for j in 0..n {
                print!(" {:>10.6}", m[i + n * j]);
            }
            println!("   | {:>10.6}", h[i]);
        }
    } else {
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
        let asymmetry = (0..n * n)
            .map(|k| (m[k] - m[(k % n) * n + k / n]).abs())
            .fold(0.0, f64::max);
        let min = m.iter().copied().fold(f64::INFINITY, f64::min);
        let max = m.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        println!("max |M - Mᵀ| = {asymmetry:.1e}, entries of M in [{min:.6}, {max:.6}]");
    }
    println!("\noperations per generated function:\n{}", info.ops_table());
}

/// The multipliers of the named constraints at six times of a run.
#[allow(dead_code)]
pub fn print_multipliers(tr: &mbs::Trajectory) {
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
