//! Four states at once: the batch functions of `option batch;` (`dynamics_x4`,
//! `forward_dynamics_x4`, SIMD on `F64x4` lanes) against four calls of the one-state functions,
//! in the same run, on a 16-bar chain and a 12-joint spatial arm (criterion).
//!
//! ```text
//! cargo bench -p mbs-benches --bench batch
//! ```
//!
//! Prints criterion's figures, then a table of medians: ns for four states each way and the
//! throughput of the batch relative to the one-state path (goal ≥ 3×), with the same
//! throughput measured in pairs (blocks of each way back to back, `common::ROUNDS` rounds:
//! its quartiles and the verdict on their median, and the ratio of each way's fastest block
//! with its verdict); then the batch forward
//! dynamics of four models, each lane its own model's parameters (`forward_dynamics_lanes`,
//! an ensemble's members), against one model's in every lane.

mod common;
#[path = "scaling/models.rs"]
mod models;

use common::{Paired, ROUNDS, median_ns, paired_if_measured, test_state};
use criterion::Criterion;
use mbs::{F64x4, LANES, Model};
use std::hint::black_box;
use std::time::SystemTime;

use models::{Arm3d12, Chain16};

/// Throughput goal of the batch: states per second relative to the one-state path.
const GOAL: f64 = 3.0;

/// Four states near the test state, one slice per state.
fn four_states(n: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
    (0..LANES)
        .map(|k| {
            let (mut q, mut qd) = test_state(n);
            for (i, (a, b)) in q.iter_mut().zip(qd.iter_mut()).enumerate() {
                *a += 0.05 * ((i + 3 * k) as f64).sin();
                *b -= 0.1 * ((2 * i + k) as f64).cos();
            }
            (q, qd)
        })
        .collect()
}

fn pack(states: &[&[f64]]) -> Vec<F64x4> {
    let mut out = vec![F64x4::ZERO; states[0].len()];
    mbs::lanes::pack([states[0], states[1], states[2], states[3]], &mut out);
    out
}

/// A model's name and the throughput of the batch measured in pairs (`common::paired`), of
/// `dynamics` and of `forward_dynamics`.
type Row = (&'static str, Paired, Paired);

/// Measures both functions both ways on `model` (criterion, then in pairs).
fn bench_model<M: Model + Clone>(
    c: &mut Criterion,
    since: SystemTime,
    name: &'static str,
    model: M,
) -> Row {
    assert!(M::BATCH_GENERATED, "{name} has `option batch;`");
    let n = M::NQ;
    let states = four_states(n);
    let qs: Vec<&[f64]> = states.iter().map(|s| s.0.as_slice()).collect();
    let qds: Vec<&[f64]> = states.iter().map(|s| s.1.as_slice()).collect();
    let (q4, qd4) = (pack(&qs), pack(&qds));
    let u = vec![0.0; M::NU];
    let u4 = vec![F64x4::ZERO; M::NU];
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    let (mut a, mut p) = (vec![0.0; n], vec![0.0; n]);
    let (mut m4, mut h4) = (vec![F64x4::ZERO; n * n], vec![F64x4::ZERO; n]);
    let (mut a4, mut p4) = (vec![F64x4::ZERO; n], vec![F64x4::ZERO; n]);
    let t4 = F64x4::ZERO;
    let mut dynamics_one = || {
        for (q, qd) in black_box(&states) {
            model.dynamics(0.0, q, qd, &u, &mut m, &mut h);
        }
        black_box(&h);
    };
    let mut dynamics_lanes = || {
        model.dynamics_x4(t4, black_box(&q4), black_box(&qd4), &u4, &mut m4, &mut h4);
        black_box(&h4);
    };
    let mut forward_one = || {
        for (q, qd) in black_box(&states) {
            model.forward_dynamics(0.0, q, qd, &u, &mut a, &mut p);
        }
        black_box(&a);
    };
    let mut forward_lanes = || {
        model.forward_dynamics_x4(t4, black_box(&q4), black_box(&qd4), &u4, &mut a4, &mut p4);
        black_box(&a4);
    };
    let group = format!("batch_{name}");
    let mut g = c.benchmark_group(&group);
    g.bench_function("dynamics_one_state_x4", |b| b.iter(&mut dynamics_one));
    g.bench_function("dynamics_lanes", |b| b.iter(&mut dynamics_lanes));
    g.bench_function("forward_one_state_x4", |b| b.iter(&mut forward_one));
    g.bench_function("forward_lanes", |b| b.iter(&mut forward_lanes));
    // four models (equal here, which the code does not know: it reads each lane's values)
    let models = [model.clone(), model.clone(), model.clone(), model.clone()];
    let each = [&models[0], &models[1], &models[2], &models[3]];
    let (mut a4, mut p4) = (vec![F64x4::ZERO; n], vec![F64x4::ZERO; n]);
    g.bench_function("forward_four_models", |b| {
        b.iter(|| {
            M::forward_dynamics_lanes(
                black_box(each),
                t4,
                black_box(&q4),
                black_box(&qd4),
                &u4,
                &mut a4,
                &mut p4,
            )
        })
    });
    g.finish();
    let d = paired_if_measured(
        (&group, "dynamics_lanes"),
        since,
        &mut dynamics_lanes,
        &mut dynamics_one,
    );
    let f = paired_if_measured(
        (&group, "forward_lanes"),
        since,
        &mut forward_lanes,
        &mut forward_one,
    );
    (name, d, f)
}

fn main() {
    let since = SystemTime::now();
    let mut c = Criterion::default().configure_from_args();
    let rows = [
        bench_model(&mut c, since, "chain16", Chain16::default()),
        bench_model(&mut c, since, "arm3d_12", Arm3d12::default()),
    ];
    c.final_summary();
    // criterion's medians exist after a measuring run (`cargo bench`), not in test mode
    println!("\nprocessor: {}", common::processor());
    println!(
        "medians, ns for {LANES} states   one state ×{LANES}    lanes   throughput   goal          in pairs ({ROUNDS} rounds): quartiles of the throughput, fastest blocks"
    );
    let verdict = |x: f64| if x >= GOAL { "met" } else { "MISSED" };
    for (name, d, f) in rows {
        let group = format!("batch_{name}");
        for (f, one, lanes, pairs) in [
            ("dynamics", "dynamics_one_state_x4", "dynamics_lanes", d),
            (
                "forward_dynamics",
                "forward_one_state_x4",
                "forward_lanes",
                f,
            ),
        ] {
            let (Some(o), Some(l)) = (
                median_ns(&group, one, since),
                median_ns(&group, lanes, since),
            ) else {
                continue;
            };
            let [lo, mid, hi] = pairs.quartiles;
            println!(
                "{name:<9} {f:<17} {o:>12.1} {l:>9.1}   {:>8.2}×   ≥ {GOAL:.0}× {:<6}  {lo:.2} {mid:.2} {hi:.2} {:<6}  {:.2} {}",
                o / l,
                verdict(o / l),
                verdict(mid),
                pairs.fastest,
                verdict(pairs.fastest)
            );
        }
    }
    println!(
        "batch forward dynamics, ns: one model in every lane / four models, each lane its own"
    );
    for (name, ..) in rows {
        let group = format!("batch_{name}");
        if let (Some(one), Some(four)) = (
            median_ns(&group, "forward_lanes", since),
            median_ns(&group, "forward_four_models", since),
        ) {
            println!("{name:<9} {one:>8.1} / {four:>8.1}   ({:.2}×)", four / one);
        }
    }
}
