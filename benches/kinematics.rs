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
//!
//! Then the human model (`option motion;`): `kinematics` against `motion` and `transmit`, and
//! one evaluation of its gait tracking with the pelvis held (`WithEfforts::dynamics`, the
//! held runs of its residual reduction), the efforts carried through every frame's Jacobians
//! or transmitted by one inward pass (`Efforts::reads_jacobians`).

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

/// The human's gait tracking, the pelvis held, its efforts read through the Jacobians or
/// transmitted.
#[derive(Clone)]
struct Held(mbs_models::human::Tracking, bool);

impl mbs::Efforts for Held {
    fn reads_jacobians(&self) -> bool {
        self.1
    }
    fn efforts(&mut self, e: &mut mbs::Effort) -> Result<(), String> {
        self.0.efforts(e)
    }
}

fn human(c: &mut Criterion) {
    use mbs_models::human::*;
    let model = Human::default();
    let info = model.info();
    println!(
        "human     kinematics: {:>6} flops generated, motion: {:>6}, transmit: {:>6}",
        flops(&model, "kinematics"),
        flops(&model, "motion"),
        flops(&model, "transmit")
    );
    let reference = GaitReference::fit(&GaitTable::normal(), info, 1.1, FIT_HARMONICS)
        .and_then(|r| r.symmetric(info))
        .expect("the normal cycle fits");
    let (q, qd) = cycle_start(&model, &reference);
    let mut held = Tracking::new(reference, info, GAIT_KP, GAIT_KP / 100.0).expect("tracking");
    held.pelvis_kp = GAIT_PELVIS_KP;
    held.pelvis_kd = GAIT_PELVIS_KP / 10.0;
    let n = Human::NQ;
    let mut out = Kinematics::new::<Human>();
    let wrenches = vec![1.0; 6 * Human::NFRAMES + 3 * Human::NPOINTS];
    let mut qg = vec![0.0; n];
    let mut g = c.benchmark_group("kinematics_human");
    g.bench_function("kinematics", |b| {
        b.iter(|| model.kinematics(0.0, black_box(&q), black_box(&qd), &mut out))
    });
    g.bench_function("motion", |b| {
        b.iter(|| model.motion(0.0, black_box(&q), black_box(&qd), &mut out))
    });
    g.bench_function("transmit", |b| {
        b.iter(|| model.transmit(0.0, black_box(&q), black_box(&wrenches), &mut qg))
    });
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    for (id, reads) in [("held_jacobians", true), ("held_transmitted", false)] {
        let wrapped = mbs::WithEfforts::new(model.clone(), Held(held.clone(), reads));
        g.bench_function(id, |b| {
            b.iter(|| wrapped.dynamics(0.0, black_box(&q), black_box(&qd), &[], &mut m, &mut h))
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
    human(&mut c);
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
        ("human", "kinematics"),
        ("human", "motion"),
        ("human", "transmit"),
        ("human", "held_jacobians"),
        ("human", "held_transmitted"),
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
