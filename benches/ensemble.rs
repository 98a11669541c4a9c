//! Many runs at once: an ensemble of 16 members (starts spread about the test state) of the
//! 16-bar chain and of the 12-joint arm, DOPRI5 at rtol 1e-6 and RK4 at h = 1 ms over 0.5 s, run by
//! `simulate_ensemble` (four members at a time on the lanes of `option batch;`) against the
//! same 16 members run one after another by `simulate`, in the same run (criterion).
//!
//! ```text
//! cargo bench -p mbs-benches --bench ensemble
//! ```
//!
//! Prints criterion's figures, then a table of medians: ms for the 16 runs each way, the
//! ensemble's throughput relative to the runs one by one, its steps and how busy its lanes
//! were. Then two sweeps (`mbs::sweep`) of 256 runs of the 16-bar chain, over starts and over
//! its bars' length and mass drawn at random (each run its own model, its lanes' parameters
//! its own), on one thread, one run at a time and on lanes (`Sweep::ensembles`), the best of
//! three rounds each way.

mod common;
#[path = "scaling/models.rs"]
mod models;

use common::{median_ns, test_state};
use criterion::Criterion;
use mbs::sweep::{Plan, Sweep};
use mbs::{Inputs, Member, Model, Options, Output, Scheme, simulate_ensemble, simulate_with};
use std::hint::black_box;

use models::{Arm3d12, Chain16};

/// Members of each ensemble.
const MEMBERS: usize = 16;

/// The members' starts: the test state, its angles moved by up to 0.2 rad and its rates by
/// up to 0.5 rad/s.
fn starts(n: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
    (0..MEMBERS)
        .map(|k| {
            let (mut q, mut qd) = test_state(n);
            for (i, (a, b)) in q.iter_mut().zip(qd.iter_mut()).enumerate() {
                *a += 0.2 * ((i * 3 + 7 * k) as f64).sin();
                *b += 0.5 * ((i * 5 + 11 * k) as f64).cos();
            }
            (q, qd)
        })
        .collect()
}

fn options() -> Options {
    Options {
        output: Output::Last,
        ..Options::adaptive(0.5, 1e-6)
    }
}

/// RK4 at a fixed step of 1 ms over the same 0.5 s.
fn fixed() -> Options {
    Options {
        output: Output::Last,
        ..Options::fixed(0.5, 1e-3)
    }
}

fn members(n: usize) -> Vec<Member> {
    starts(n)
        .into_iter()
        .map(|(q, qd)| Member::at(q, qd))
        .collect()
}

/// The schemes measured: DOPRI5 adaptive, RK4 at a fixed step.
fn configurations() -> [(&'static str, Scheme, Options); 2] {
    [
        ("dopri5", Scheme::Dopri5, options()),
        ("rk4", Scheme::Rk4, fixed()),
    ]
}

/// The runs one by one: total steps.
fn one_by_one<M: Model + Clone + 'static>(model: &M, scheme: Scheme, opts: &Options) -> usize {
    starts(M::NQ)
        .into_iter()
        .map(|(q, qd)| {
            let o = Options {
                q0: Some(q),
                qd0: Some(qd),
                ..opts.clone()
            };
            let (_, stats) =
                simulate_with(model.clone(), scheme, o, Inputs::default()).expect("the run ends");
            stats.steps
        })
        .sum()
}

/// The ensemble: total steps and the occupancy of its lanes.
fn ensemble<M: Model + Clone + 'static>(model: &M, scheme: Scheme, opts: &Options) -> (usize, f64) {
    let r = simulate_ensemble(model, scheme, opts, members(M::NQ)).expect("an ensemble it runs");
    let steps = r
        .runs
        .iter()
        .map(|x| x.as_ref().expect("the run ends").1.steps)
        .sum();
    (steps, r.occupancy())
}

/// Both ways, each configuration: (group, steps alone, steps in the ensemble, occupancy).
fn bench_model<M: Model + Clone + 'static>(
    c: &mut Criterion,
    name: &'static str,
    model: M,
) -> Vec<(String, usize, usize, f64)> {
    assert!(M::BATCH_GENERATED, "{name} has `option batch;`");
    let mut rows = Vec::new();
    for (label, scheme, opts) in configurations() {
        let steps_alone = one_by_one(&model, scheme, &opts);
        let (steps, occupancy) = ensemble(&model, scheme, &opts);
        let group = format!("ensemble_{name}_{label}");
        let mut g = c.benchmark_group(&group);
        g.sample_size(10);
        g.bench_function("one_by_one", |b| {
            b.iter(|| one_by_one(black_box(&model), scheme, &opts))
        });
        g.bench_function("ensemble", |b| {
            b.iter(|| ensemble(black_box(&model), scheme, &opts))
        });
        g.finish();
        rows.push((group, steps_alone, steps, occupancy));
    }
    rows
}

/// The variables of the sweeps: two of the start, then the bars' length and mass.
const OVER_STARTS: &str = r#"
[[vary]]
name = "q0[0]"
uniform = [0.0, 0.6]
[[vary]]
name = "qd0[5]"
uniform = [-1.0, 1.0]
"#;
const OVER_PARAMETERS: &str = r#"
[[vary]]
name = "l"
uniform = [0.3, 0.7]
[[vary]]
name = "m"
uniform = [0.5, 2.0]
"#;

/// A sweep of 256 runs of chain16 over `vary` drawn at random, on one thread, one run at a
/// time and on lanes: the best wall time of three rounds each way, in s.
fn sweep_rounds(vary: &str) -> (f64, f64) {
    let plan = Plan::from_toml(&format!(
        "[sweep]\ndesign = \"monte-carlo\"\nruns = 256\nseed = 7\n{vary}"
    ))
    .expect("the plan is valid");
    let out = std::env::temp_dir().join(format!("mbs-bench-ensemble-{}", std::process::id()));
    let list = plan.runs(&out).expect("its runs");
    let mut best = [f64::INFINITY; 2];
    for _ in 0..3 {
        for (on, best) in [false, true].into_iter().zip(best.iter_mut()) {
            let _ = std::fs::remove_dir_all(&out);
            let s = Sweep::new(Chain16::default, &plan, Scheme::Dopri5, options())
                .expect("the sweep is valid")
                .ensembles(on)
                .threads(1)
                .run(&out, &list)
                .expect("the sweep runs");
            assert_eq!(s.on_lanes, if on { 256 } else { 0 });
            *best = best.min(s.wall.as_secs_f64());
        }
    }
    let _ = std::fs::remove_dir_all(&out);
    (best[0], best[1])
}

fn main() {
    let since = std::time::SystemTime::now();
    let mut c = Criterion::default().configure_from_args();
    let mut rows = bench_model(&mut c, "chain16", Chain16::default());
    rows.extend(bench_model(&mut c, "arm3d_12", Arm3d12::default()));
    c.final_summary();
    println!("\nprocessor: {}", common::processor());
    println!(
        "{MEMBERS} runs over 0.5 s (DOPRI5 rtol 1e-6; RK4 h = 1 ms)   steps alone / ensemble   lanes busy   ms one by one   ms ensemble   throughput"
    );
    for (group, alone, steps, occupancy) in rows {
        let name = group.trim_start_matches("ensemble_");
        let (Some(o), Some(e)) = (
            median_ns(&group, "one_by_one", since),
            median_ns(&group, "ensemble", since),
        ) else {
            println!("{name:<16} steps {alone} / {steps}, lanes busy {occupancy:.2}");
            continue;
        };
        println!(
            "{name:<48} {alone:>7} / {steps:<7}   {occupancy:>10.2}   {:>13.2}   {:>11.2}   {:>9.2}×",
            o * 1e-6,
            e * 1e-6,
            o / e
        );
    }
    for (over, vary) in [
        ("starts", OVER_STARTS),
        ("length and mass", OVER_PARAMETERS),
    ] {
        let (alone, lanes) = sweep_rounds(vary);
        println!(
            "sweep of 256 runs of chain16 over {over}, one thread, best of 3: one at a time {:.1} ms, on lanes {:.1} ms ({:.2}×)",
            alone * 1e3,
            lanes * 1e3,
            alone / lanes
        );
    }
}
