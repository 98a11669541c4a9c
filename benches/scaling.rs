//! Forward dynamics at every size: qdd = M⁻¹h by the generated `forward_dynamics`
//! (articulated bodies or sparse LᵀDL) against the dense path (M and h, then Cholesky and two
//! triangular solves), in the same run, for planar chains of 2 to 32 bars and spatial arms of
//! 6 to 24 joints (criterion).
//!
//! ```text
//! cargo bench -p mbs-benches --bench scaling
//! ```
//!
//! Prints the op counts of both paths and criterion's figures per model, then a table of
//! medians: ns per call, the ratio forward/dense and the goal it is held to
//! (≤ 0.55× at 2 dof, ≤ 0.6× at 4–16, ≤ 0.45× at 24–32), and the same ratio measured in
//! pairs (blocks of each path back to back, `common::ROUNDS` rounds: its quartiles and the
//! verdict on their median, which a change of the machine's speed between criterion's
//! measurements of the two paths does not move; and the ratio of each path's fastest block,
//! with its verdict, where a busy moment slows one path more than the other).

mod common;
#[path = "scaling/models.rs"]
mod models;

use common::{Paired, ROUNDS, median_ns, paired_if_measured, test_state};
use criterion::Criterion;
use mbs::Model;
use std::hint::black_box;
use std::time::SystemTime;

use mbs_models::arm3d_6::Arm3d6;
use mbs_models::chain8::Chain8;
use mbs_models::chain24::Chain24;
use models::{Arm3d12, Arm3d24, Chain2, Chain4, Chain16, Chain32};

/// Flops of a generated function, by the start of its op-count row, and the row's label.
fn flops<M: Model>(model: &M, row: &str) -> (String, usize) {
    model
        .info()
        .ops
        .iter()
        .find(|(name, _)| name.starts_with(row))
        .map(|(name, c)| (name.to_string(), c.flops()))
        .expect("generated models count their functions")
}

/// Flops of the dense Cholesky factorisation (n³/3 + n²/2 multiply-adds counted as 2, n
/// square roots) and of its two triangular solves (2n²).
fn dense_flops(n: usize) -> usize {
    (n * n * n) / 3 * 2 + n * n + n + 2 * n * n
}

fn op_counts<M: Model>(name: &str, model: &M) {
    let n = M::NQ;
    let (_, mh) = flops(model, "dynamics");
    let (label, fwd) = flops(model, "forward_dynamics");
    println!(
        "{name:<9} {n:>3} dof  dense: M + h {mh:>6} + Cholesky and solves {:>6} = {:>6} flops; {label}: {fwd:>6} flops, {:>4.0} per dof",
        dense_flops(n),
        mh + dense_flops(n),
        fwd as f64 / n as f64
    );
}

/// A row of the summary: name, size, the goal (the largest ratio forward/dense allowed) and the
/// ratio measured in pairs (`common::paired`).
type Row = (&'static str, usize, f64, Paired);

/// Prints the op counts of `model`, measures both paths (criterion, then in pairs) and returns
/// its row of the summary.
fn bench_model<M: Model>(
    c: &mut Criterion,
    since: SystemTime,
    name: &'static str,
    goal: f64,
    model: M,
) -> Row {
    op_counts(name, &model);
    let n = M::NQ;
    let (q, qd) = test_state(n);
    let u = vec![0.0; M::NU];
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    let (mut qdd, mut pivots) = (vec![0.0; n], vec![0.0; n]);
    let mut dense = || {
        model.dynamics(0.0, black_box(&q), black_box(&qd), &u, &mut m, &mut h);
        mbs::linalg::cholesky(&mut m, n).expect("M positive definite");
        mbs::linalg::cholesky_solve(&m, n, &mut h);
        black_box(&h);
    };
    let mut forward = || {
        let (q, qd) = (black_box(&q), black_box(&qd));
        model.forward_dynamics(0.0, q, qd, &u, &mut qdd, &mut pivots);
        black_box(&qdd);
    };
    let group = format!("scaling_{name}");
    let mut g = c.benchmark_group(&group);
    g.bench_function("dense", |b| b.iter(&mut dense));
    g.bench_function("forward", |b| b.iter(&mut forward));
    g.finish();
    let pairs = paired_if_measured((&group, "forward"), since, &mut dense, &mut forward);
    (name, n, goal, pairs)
}

fn main() {
    let since = SystemTime::now();
    let mut c = Criterion::default().configure_from_args();
    let rows = [
        bench_model(&mut c, since, "chain2", 0.55, Chain2::default()),
        bench_model(&mut c, since, "chain4", 0.6, Chain4::default()),
        bench_model(&mut c, since, "chain8", 0.6, Chain8::default()),
        bench_model(&mut c, since, "chain16", 0.6, Chain16::default()),
        bench_model(&mut c, since, "chain24", 0.45, Chain24::default()),
        bench_model(&mut c, since, "chain32", 0.45, Chain32::default()),
        bench_model(&mut c, since, "arm3d_6", 0.6, Arm3d6::default()),
        bench_model(&mut c, since, "arm3d_12", 0.6, Arm3d12::default()),
        bench_model(&mut c, since, "arm3d_24", 0.45, Arm3d24::default()),
    ];
    c.final_summary();
    // criterion's medians exist after a measuring run (`cargo bench`), not in test mode; a
    // filter leaves rows out
    let medians: Vec<_> = rows
        .iter()
        .filter_map(|row| {
            let group = format!("scaling_{}", row.0);
            Some((
                row,
                median_ns(&group, "dense", since)?,
                median_ns(&group, "forward", since)?,
            ))
        })
        .collect();
    if medians.is_empty() {
        return;
    }
    println!("\nprocessor: {}", common::processor());
    println!(
        "medians (ns per call)      dense   forward   ratio   goal          in pairs ({ROUNDS} rounds): quartiles of forward / dense, fastest blocks"
    );
    for ((name, n, goal, pairs), d, f) in medians {
        let verdict = |r: f64| if r <= *goal { "met" } else { "MISSED" };
        let [lo, mid, hi] = pairs.quartiles;
        println!(
            "{name:<9} {n:>3} dof  {d:>10.1} {f:>9.1}   {:>5.2}×  ≤ {goal:.2}× {:<6}  {lo:.2} {mid:.2} {hi:.2} {:<6}  {:.2} {}",
            f / d,
            verdict(f / d),
            verdict(mid),
            pairs.fastest,
            verdict(pairs.fastest)
        );
    }
}
