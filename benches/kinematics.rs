//! The two forms of the Jacobians of `kinematics` and `point_kinematics`, and of M in
//! `dynamics` (`option jacobians = generated | assembled;`) at run time: a 32-bar planar chain
//! and a 24-joint spatial arm, each compiled both ways (criterion).
//!
//! ```text
//! cargo bench -p mbs-benches --bench kinematics
//! ```
//!
//! Prints the generated op counts of both forms, criterion's figures, then a table of medians
//! in ns per call. The assembled form generates O(n) code (the coordinates' twists, the
//! composite inertias) and sums the O(n²) columns and entries of M at run time in a generic
//! loop, where the generated form writes each with the model's zeros folded.

mod common;

mod models {
    include!("scaling/shapes.rs");
    chain!(Chain32Generated, 32, jacobians = generated);
    chain!(Chain32Assembled, 32, jacobians = assembled);
    arm!(Arm24Generated, 24, 11, 23, 22, jacobians = generated);
    arm!(Arm24Assembled, 24, 11, 23, 22, jacobians = assembled);
}

use common::{median_ns, test_state};
use criterion::Criterion;
use mbs::{Kinematics, Model};
use models::*;
use std::hint::black_box;

fn flops<M: Model>(model: &M, function: &str) -> usize {
    let row = model
        .info()
        .ops
        .iter()
        .find(|(name, _)| name.starts_with(function));
    row.expect("generated models count their functions")
        .1
        .flops()
}

/// Measures `kinematics` (and `point_kinematics` when the model has points) and `dynamics`
/// of `model` in the group `name`, under the id `form` (`{form}_points`, `{form}_dynamics`).
fn bench<M: Model + Default>(c: &mut Criterion, name: &str, form: &str) {
    let model = M::default();
    println!(
        "{name:<9} {form:<9} kinematics: {:>6} flops generated, dynamics: {:>6}",
        flops(&model, "kinematics"),
        flops(&model, "dynamics")
    );
    let (q, qd) = test_state(M::NQ);
    let mut out = Kinematics::new::<M>();
    let mut g = c.benchmark_group(format!("kinematics_{name}"));
    g.bench_function(form, |b| {
        b.iter(|| model.kinematics(0.0, black_box(&q), black_box(&qd), &mut out))
    });
    let n = M::NQ;
    let u = vec![0.0; M::NU];
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    g.bench_function(format!("{form}_dynamics"), |b| {
        b.iter(|| model.dynamics(0.0, black_box(&q), black_box(&qd), &u, &mut m, &mut h))
    });
    if M::NPOINTS > 0 {
        g.bench_function(format!("{form}_points"), |b| {
            b.iter(|| model.point_kinematics(0.0, black_box(&q), black_box(&qd), &mut out))
        });
    }
    g.finish();
}

fn main() {
    let since = std::time::SystemTime::now();
    let mut c = Criterion::default().configure_from_args();
    bench::<Chain32Generated>(&mut c, "chain32", "generated");
    bench::<Chain32Assembled>(&mut c, "chain32", "assembled");
    bench::<Arm24Generated>(&mut c, "arm3d_24", "generated");
    bench::<Arm24Assembled>(&mut c, "arm3d_24", "assembled");
    c.final_summary();
    let rows = [
        ("chain32", "generated"),
        ("chain32", "assembled"),
        ("chain32", "generated_dynamics"),
        ("chain32", "assembled_dynamics"),
        ("arm3d_24", "generated"),
        ("arm3d_24", "assembled"),
        ("arm3d_24", "generated_dynamics"),
        ("arm3d_24", "assembled_dynamics"),
    ];
    // criterion's medians exist after a measuring run (`cargo bench`), not in test mode
    let medians: Vec<_> = rows
        .iter()
        .filter_map(|&(name, id)| {
            Some((
                name,
                id,
                median_ns(&format!("kinematics_{name}"), id, since)?,
            ))
        })
        .collect();
    if medians.is_empty() {
        return;
    }
    println!("\nmedians (ns per call)");
    for (name, id, t) in medians {
        println!("{name:<9} {id:<19} {t:>9.1}");
    }
}
