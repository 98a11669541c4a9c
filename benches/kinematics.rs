//! The two forms of the Jacobians of `kinematics` and `point_kinematics` (`option jacobians
//! = generated | assembled;`) at run time: a 32-bar planar chain and a 24-joint spatial arm,
//! each compiled both ways, and the walking hexapod's feet (assembled) (criterion).
//!
//! ```text
//! cargo bench -p mbs-benches --bench kinematics
//! ```
//!
//! Prints the generated op counts of both forms, criterion's figures, then a table of medians
//! in ns per call. The assembled form generates O(n) code (the coordinates' twists) and sums
//! the O(n²) columns at run time in a generic loop, where the generated form writes each
//! column with the model's zeros folded.

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
use mbs_models::hexapod_walker::HexapodWalker;
use models::*;
use std::hint::black_box;

fn flops<M: Model>(model: &M) -> usize {
    let row = model
        .info()
        .ops
        .iter()
        .find(|(name, _)| *name == "kinematics");
    row.expect("generated models count kinematics").1.flops()
}

/// Measures `kinematics` (and `point_kinematics` when the model has points) of `model` in
/// the group `name`, under the id `form`.
fn bench<M: Model + Default>(c: &mut Criterion, name: &str, form: &str) {
    let model = M::default();
    println!(
        "{name:<9} {form:<9} kinematics: {:>6} flops generated",
        flops(&model)
    );
    let (q, qd) = test_state(M::NQ);
    let mut out = Kinematics::new::<M>();
    let mut g = c.benchmark_group(format!("kinematics_{name}"));
    g.bench_function(form, |b| {
        b.iter(|| model.kinematics(0.0, black_box(&q), black_box(&qd), &mut out))
    });
    if M::NPOINTS > 0 {
        g.bench_function(format!("{form}_points"), |b| {
            b.iter(|| model.point_kinematics(0.0, black_box(&q), black_box(&qd), &mut out))
        });
    }
    g.finish();
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    bench::<Chain32Generated>(&mut c, "chain32", "generated");
    bench::<Chain32Assembled>(&mut c, "chain32", "assembled");
    bench::<Arm24Generated>(&mut c, "arm3d_24", "generated");
    bench::<Arm24Assembled>(&mut c, "arm3d_24", "assembled");
    bench::<HexapodWalker>(&mut c, "walker", "assembled");
    c.final_summary();
    let rows = [
        ("chain32", "generated"),
        ("chain32", "assembled"),
        ("arm3d_24", "generated"),
        ("arm3d_24", "assembled"),
        ("walker", "assembled"),
        ("walker", "assembled_points"),
    ];
    // criterion's medians exist after a measuring run (`cargo bench`), not in test mode
    if median_ns("kinematics_chain32", "generated").is_none() {
        return;
    }
    println!("\nmedians (ns per call)");
    for (name, id) in rows {
        if let Some(t) = median_ns(&format!("kinematics_{name}"), id) {
            println!("{name:<9} {id:<17} {t:>9.1}");
        }
    }
}
