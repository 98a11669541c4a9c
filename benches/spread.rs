//! The spread of timings over fresh copies of one binary: the time of a large straight-line
//! function depends on where its pages land in memory, so identical copies of a benchmark
//! measure the same code at different speeds. This program copies itself to several fresh
//! files, runs the copies in turns, twice (each run measures the medians of the 16-bar chain's
//! and the 12-joint arm's M + h, dense path, forward dynamics and batch forward dynamics) and
//! prints every copy's figures with their minimum, median, maximum and max/min over the
//! copies (each copy by its better run).
//!
//! ```text
//! cargo bench -p mbs-benches --bench spread
//! ```
//!
//! Under `cargo test` it runs two copies briefly, so that it cannot rot. Copies share their
//! layout (every function at the same address); `benches/layout.sh` measures the same cases
//! over builds whose functions the linker placed in different orders.

mod common;
#[path = "scaling/models.rs"]
mod models;

use common::test_state;
use mbs::{F64x4, Model};
use models::{Arm3d12, Chain16};
use std::hint::black_box;
use std::process::Command;
use std::time::{Duration, Instant};

/// A case of the measurement: its name and one call.
type Case = (String, Box<dyn FnMut()>);

/// What each copy measures: M + h, the dense path (M + h, Cholesky and two triangular
/// solves), forward dynamics and batch forward dynamics of the 16-bar chain and of the
/// 12-joint arm (whose batch forward dynamics measured 2× apart from one file to a copy of
/// it).
fn cases() -> Vec<Case> {
    let mut v = model_cases("chain16", Chain16::default());
    v.extend(model_cases("arm3d_12", Arm3d12::default()));
    v
}

/// The four cases of one model.
fn model_cases<M: Model + 'static>(name: &str, model: M) -> Vec<Case> {
    let model: &'static M = Box::leak(Box::new(model));
    let n = M::NQ;
    let (q, qd) = test_state(n);
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    let (mut a, mut p) = (vec![0.0; n], vec![0.0; n]);
    let (q4, qd4): (Vec<F64x4>, Vec<F64x4>) = (
        q.iter().map(|&v| F64x4::splat(v)).collect(),
        qd.iter().map(|&v| F64x4::splat(v)).collect(),
    );
    let (mut a4, mut p4) = (vec![F64x4::ZERO; n], vec![F64x4::ZERO; n]);
    let (q1, qd1) = (q.clone(), qd.clone());
    let (q2, qd2) = (q.clone(), qd.clone());
    let (mut m2, mut h2) = (m.clone(), h.clone());
    let label = |what: &str| format!("{name} {what}");
    vec![
        (
            label("dynamics (M + h)"),
            Box::new(move || {
                model.dynamics(0.0, black_box(&q), black_box(&qd), &[], &mut m, &mut h)
            }),
        ),
        (
            label("dense (M + h, Cholesky)"),
            Box::new(move || {
                model.dynamics(0.0, black_box(&q2), black_box(&qd2), &[], &mut m2, &mut h2);
                mbs::linalg::cholesky(&mut m2, n).expect("M positive definite");
                mbs::linalg::cholesky_solve(&m2, n, &mut h2);
            }),
        ),
        (
            label("forward_dynamics"),
            Box::new(move || {
                model.forward_dynamics(0.0, black_box(&q1), black_box(&qd1), &[], &mut a, &mut p)
            }),
        ),
        (
            label("forward_dynamics_x4"),
            Box::new(move || {
                model.forward_dynamics_x4(
                    F64x4::ZERO,
                    black_box(&q4),
                    black_box(&qd4),
                    &[],
                    &mut a4,
                    &mut p4,
                )
            }),
        ),
    ]
}

/// Median ns per call of `f` over `samples` samples of about `sample` each.
fn timed_ns(f: &mut dyn FnMut(), samples: usize, sample: Duration) -> f64 {
    // calls per sample, from a first estimate after a warm-up
    let start = Instant::now();
    let mut calls = 0u64;
    while start.elapsed() < sample {
        f();
        calls += 1;
    }
    let mut times: Vec<f64> = (0..samples)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..calls {
                f();
            }
            t.elapsed().as_nanos() as f64 / calls as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[samples / 2]
}

fn child(brief: bool) {
    let (samples, sample) = if brief {
        (3, Duration::from_millis(2))
    } else {
        (31, Duration::from_millis(20))
    };
    for (name, mut f) in cases() {
        println!("{name}\t{:.1}", timed_ns(&mut *f, samples, sample));
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let brief = !args.iter().any(|a| a == "--bench");
    if args.iter().any(|a| a == "--copy") {
        return child(brief);
    }
    let (copies, rounds) = if brief { (2, 1) } else { (6, 2) };
    let exe = std::env::current_exe().expect("the benchmark knows its own path");
    // fresh files: new pages for the code
    let paths: Vec<_> = (0..copies)
        .map(|k| {
            let path = std::env::temp_dir().join(format!("mbs-spread-{}-{k}", std::process::id()));
            std::fs::copy(&exe, &path).expect("copy of the benchmark");
            path
        })
        .collect();
    // rows[case][copy][round]: the copies take turns, so that a copy slow in every round is
    // told from a moment when the machine was slow
    let mut rows: Vec<(String, Vec<Vec<f64>>)> = Vec::new();
    for _ in 0..rounds {
        for (k, path) in paths.iter().enumerate() {
            let mut cmd = Command::new(path);
            cmd.arg("--copy");
            if !brief {
                cmd.arg("--bench");
            }
            let out = cmd.output().expect("a copy runs");
            assert!(
                out.status.success(),
                "copy {k} failed: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            for (i, line) in String::from_utf8_lossy(&out.stdout).lines().enumerate() {
                let (name, ns) = line.split_once('\t').expect("name and figure");
                let ns: f64 = ns.parse().expect("a number");
                if rows.len() <= i {
                    rows.push((name.to_string(), vec![Vec::new(); copies]));
                }
                rows[i].1[k].push(ns);
            }
        }
    }
    for path in &paths {
        let _ = std::fs::remove_file(path);
    }
    println!("processor: {}", common::processor());
    println!(
        "ns per call: each of {copies} fresh copies of this binary (its {rounds} runs, taking turns with the others), then over the copies' best"
    );
    for (name, per_copy) in rows {
        let each: Vec<String> = per_copy
            .iter()
            .map(|r| {
                r.iter()
                    .map(|x| format!("{x:.0}"))
                    .collect::<Vec<_>>()
                    .join("/")
            })
            .collect();
        let mut v: Vec<f64> = per_copy
            .iter()
            .map(|r| r.iter().copied().fold(f64::INFINITY, f64::min))
            .collect();
        v.sort_by(f64::total_cmp);
        let (min, med, max) = (v[0], v[v.len() / 2], v[v.len() - 1]);
        println!(
            "{name:<32} {}  min {min:.0}  median {med:.0}  max {max:.0}  max/min {:.2}",
            each.join(" "),
            max / min
        );
    }
}
