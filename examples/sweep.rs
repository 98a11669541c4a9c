//! A Monte-Carlo sweep of the double pendulum with `mbs::sweep`, and what running it on every
//! core buys: 1,000 runs (bar length, start angle and rate drawn at random; dopri5 at
//! rtol 1e-8 over 10 s), made
//!
//! 1. one after another by plain `simulate` calls (no sweep machinery): the single-run time,
//! 2. by the sweep on one thread,
//! 3. by the sweep on every core,
//!
//! and the ratio of (3) to the ideal time, single-run time × runs / cores (the single-run time the
//! faster of (1) and (2)). Then a few lines of
//! the table it wrote. Each figure is the best of `--repeat` rounds (default 7: timings on a shared
//! machine vary by more than the sweep's overhead).
//!
//! ```text
//! cargo run --release --example sweep -- [--runs 1000] [--repeat 7] [--out DIR]
//! ```

use mbs::sweep::{Metrics, Plan, Sweep, Value};
use mbs::{Kinematics, Model, Options, Scheme, StepControl, simulate};
use mbs_models::dpend::DoublePendulum;
use std::time::{Duration, Instant};

fn plan(runs: usize) -> Plan {
    Plan::from_toml(&format!(
        r#"
        [sweep]
        design = "monte-carlo"
        runs = {runs}
        seed = 2026

        [simulation]
        scheme = "dopri5"
        t_end = 10.0
        rtol = 1e-8

        [[vary]]
        name = "l"
        uniform = [0.8, 1.2]

        [[vary]]
        name = "q0[0]"
        normal = [1.5, 0.1]

        [[vary]]
        name = "qd0[1]"
        uniform = [-0.5, 0.5]
        "#
    ))
    .expect("the plan is valid")
}

/// Where the tip is at the end, and how high it went.
fn metrics() -> Metrics<DoublePendulum> {
    Metrics::new(["tip_x_end", "tip_y_end", "tip_y_max"], metric_values)
}

/// The value after `name` among the arguments, if it is there.
fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

/// A whole number of 1 or more after `name`, or `default`.
fn count(name: &str, default: usize) -> usize {
    match arg(name).map(|s| s.parse::<usize>()) {
        None => default,
        Some(Ok(n)) if n > 0 => n,
        _ => fail(&format!("{name} takes a whole number of 1 or more")),
    }
}

const USAGE: &str = "usage: sweep [--runs 1000] [--repeat 7] [--out DIR]";

fn fail(message: &str) -> ! {
    eprintln!("error: {message}\n{USAGE}");
    std::process::exit(1);
}

fn main() {
    // every argument an option with its value (a misspelt one would run the defaults)
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--help" || a == "-h") {
        println!("{USAGE}");
        return;
    }
    for pair in args.chunks(2) {
        match pair {
            [name, _] if ["--runs", "--repeat", "--out"].contains(&name.as_str()) => {}
            [name] if ["--runs", "--repeat", "--out"].contains(&name.as_str()) => {
                fail(&format!("{name} takes a value"))
            }
            [other, ..] => fail(&format!("unknown argument `{other}`")),
            [] => {}
        }
    }
    let runs = count("--runs", 1000);
    let repeat = count("--repeat", 7);
    let out = arg("--out").map_or_else(
        || std::env::temp_dir().join(format!("mbs-sweep-example-{}", std::process::id())),
        std::path::PathBuf::from,
    );
    // the folder is emptied before each round: only a new one or one of this program's
    // (with its runs.csv), never a folder of other files
    let ours = out.join("runs.csv").is_file();
    let empty = std::fs::read_dir(&out).is_ok_and(|mut d| d.next().is_none());
    if out.exists() && !ours && !empty {
        fail(&format!(
            "{} exists and is not a sweep's folder: the program empties its --out folder, so name a new one",
            out.display()
        ));
    }
    let plan = plan(runs);
    let list = plan
        .runs(std::path::Path::new("."))
        .unwrap_or_else(|e| fail(&format!("--runs: {e}")));
    let base = Options {
        step: StepControl::Adaptive {
            rtol: 1e-8,
            atol: 1e-10,
            h0: None,
        },
        ..Options::default()
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());

    // 1. plain calls, the same runs and metrics, on threads of their own (not the main
    // thread: there glibc's main heap returns the trajectories' memory to the system after
    // each run and takes it back at the next, measured 1.75x slower)
    let plain = |threads: usize| {
        let mut best = Duration::MAX;
        for _ in 0..repeat {
            let start = Instant::now();
            let chunk = list.rows.len().div_ceil(threads.max(1));
            std::thread::scope(|sc| {
                for rows in list.rows.chunks(chunk) {
                    sc.spawn(|| plain_runs(rows, &base));
                }
            });
            best = best.min(start.elapsed());
        }
        best
    };
    let single = plain(1);

    // 2. and 3. the sweep on one thread, then on every core (a fresh folder each time); the
    // best round's wall time and the CPU time its runs took, summed over threads
    let timed = |threads: usize| {
        let mut best = (Duration::MAX, Duration::ZERO);
        for _ in 0..repeat {
            let _ = std::fs::remove_dir_all(&out);
            let s = Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base.clone())
                .and_then(|s| s.metrics(metrics()).threads(threads).run(&out, &list))
                .unwrap_or_else(|e| fail(&e.to_string()));
            assert_eq!(s.ran, runs);
            if s.wall < best.0 {
                best = (s.wall, s.cpu);
            }
        }
        best
    };
    let (one, one_cpu) = timed(1);
    let (all, all_cpu) = timed(cores);

    let secs = |d: Duration| d.as_secs_f64();
    // the single-run time: the faster of the plain calls and the sweep on one thread, so
    // that a slow measurement of the baseline cannot flatter the ratio
    let ideal = secs(single.min(one)) / cores as f64;
    println!("dpend, {runs} runs (dopri5, rtol 1e-8, 10 s each), best of {repeat}:");
    println!(
        "  plain simulate calls, one after another  {:>7.3} s  ({:.0} µs per run)",
        secs(single),
        secs(single) / runs as f64 * 1e6
    );
    println!(
        "  sweep on 1 thread                        {:>7.3} s  ({:.2}x the plain calls; its runs took {:.3} s CPU)",
        secs(one),
        secs(one) / secs(single),
        secs(one_cpu)
    );
    println!(
        "  sweep on {cores} threads                       {:>7.3} s  ({:.2}x ideal = single-run time x runs / {cores} cores = {:.3} s)",
        secs(all),
        secs(all) / ideal,
        ideal
    );
    println!(
        "    its runs took {:.3} s CPU ({:.2}x their CPU time on one thread), the threads were busy running them {:.0} % of the wall time",
        secs(all_cpu),
        secs(all_cpu) / secs(one_cpu),
        100.0 * secs(all_cpu) / (cores as f64 * secs(all))
    );
    let table = out.join("results.csv");
    println!("\nthe table ({}), first rows:", table.display());
    if let Ok(text) = std::fs::read_to_string(&table) {
        for line in text.lines().take(4) {
            println!("  {line}");
        }
    }
    if arg("--out").is_none() {
        let _ = std::fs::remove_dir_all(&out);
    }
}

/// The runs of `rows` by plain `simulate` calls, with the metrics.
fn plain_runs(rows: &[Vec<Value>], base: &Options) {
    let num = |v: &Value| match v {
        Value::Num(x) => *x,
        Value::Text(_) => f64::NAN,
    };
    for row in rows {
        let mut model = DoublePendulum::default();
        let mut p = model.params().clone();
        p.l = num(&row[0]);
        model.set_params(p).expect("parameters");
        let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
        model.initial_state(&mut q, &mut qd);
        q[0] = num(&row[1]);
        qd[1] = num(&row[2]);
        let options = Options {
            t_end: 10.0,
            q0: Some(q.to_vec()),
            qd0: Some(qd.to_vec()),
            ..base.clone()
        };
        let (tr, _) = simulate(model.clone(), Scheme::Dopri5, options).expect("run");
        std::hint::black_box(metric_values(&model, &tr));
    }
}

/// The metrics' values (the plain calls compute them too).
fn metric_values(model: &DoublePendulum, tr: &mbs::Trajectory) -> Vec<f64> {
    let mut k = Kinematics::new::<DoublePendulum>();
    let mut y_max = f64::NEG_INFINITY;
    let mut last = [0.0; 2];
    for i in 0..tr.len() {
        model.kinematics(tr.t[i], tr.q(i), tr.qd(i), &mut k);
        let p = k.points[0].position;
        y_max = y_max.max(p[1]);
        last = [p[0], p[1]];
    }
    vec![last[0], last[1], y_max]
}
