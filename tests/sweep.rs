//! `mbs::sweep`: plans, parallel runs, resumed sweeps, failures as rows, shards and their merge.

use mbs::sweep::{Metrics, Plan, Shard, Sweep, SweepError, merge};
use mbs::{Kinematics, Model, Options, Scheme, StepControl, simulate};
use mbs_models::{dpend::DoublePendulum, seed2dof::Seed2dof};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

#[path = "common/lcg.rs"]
mod lcg;
#[path = "common/sweeps.rs"]
mod sweeps;
use lcg::Lcg;
#[path = "common/quoted.rs"]
mod quoted;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mbs-sweep-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn base() -> Options {
    Options {
        t_end: 2.0,
        step: StepControl::Adaptive {
            rtol: 1e-7,
            atol: 1e-9,
            h0: None,
        },
        ..Options::default()
    }
}

/// The table without its last column (CPU time, which differs from run to run).
fn without_cpu(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .map(|l| l[..l.rfind(',').unwrap()].to_string())
        .collect()
}

fn column(path: &Path, name: &str) -> Vec<String> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let i = r.headers().unwrap().iter().position(|h| h == name).unwrap();
    r.records().map(|rec| rec.unwrap()[i].to_string()).collect()
}

/// The tip of bar 2 at the last output: a metric that needs the model.
fn tip_metrics() -> Metrics<DoublePendulum> {
    Metrics::new(["tip_x", "tip_y"], |model: &DoublePendulum, tr| {
        let last = tr.len() - 1;
        let mut k = Kinematics::new::<DoublePendulum>();
        model.kinematics(tr.t[last], tr.q(last), tr.qd(last), &mut k);
        vec![k.points[0].position[0], k.points[0].position[1]]
    })
}

#[test]
fn every_row_of_a_grid_is_the_run_made_alone() {
    let plan = Plan::from_toml(
        r#"
        [sweep]
        design = "grid"
        [[vary]]
        name = "l"
        values = [0.8, 1.0, 1.3]
        [[vary]]
        name = "scheme"
        values = ["dopri5", "radau5"]
        [[vary]]
        name = "qd0[1]"
        range = [0.0, 1.0]
        count = 2
        "#,
    )
    .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    assert_eq!(runs.len(), 12);
    let dir = scratch("grid");
    let sweep = Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base())
        .unwrap()
        .metrics(tip_metrics());
    let s = sweep.run(&dir, &runs).unwrap();
    assert_eq!((s.runs, s.ran, s.failed, s.skipped), (12, 12, 0, 0));
    let table = dir.join("results.csv");
    let (tip_x, steps) = (column(&table, "tip_x"), column(&table, "steps"));
    // run 7: l = 1.3 (7 / 4 = 1), scheme dopri5 (7 / 2 % 2 = 1 → radau5), qd0[1] = 1
    for (i, (l, scheme, w)) in [(0.8, Scheme::Dopri5, 0.0), (1.0, Scheme::Radau5, 1.0)]
        .into_iter()
        .enumerate()
    {
        let run = [0, 7][i];
        let mut model = DoublePendulum::default();
        let mut p = model.params().clone();
        p.l = l;
        model.set_params(p).unwrap();
        let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
        model.initial_state(&mut q, &mut qd);
        qd[1] = w;
        let options = Options {
            q0: Some(q.to_vec()),
            qd0: Some(qd.to_vec()),
            ..base()
        };
        let (tr, stats) = simulate(model.clone(), scheme, options).unwrap();
        let last = tr.len() - 1;
        let mut k = Kinematics::new::<DoublePendulum>();
        model.kinematics(tr.t[last], tr.q(last), tr.qd(last), &mut k);
        assert_eq!(
            tip_x[run],
            format!("{:?}", k.points[0].position[0]),
            "run {run}"
        );
        assert_eq!(steps[run], stats.steps.to_string());
    }
    assert_eq!(column(&table, "scheme")[7], "radau5");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn threads_do_not_change_the_table() {
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"lhs\"\nruns = 24\nseed = 5\n[[vary]]\nname = \"l\"\nuniform = [0.5, 2]\n\
         [[vary]]\nname = \"q0.q[0]\"\nuniform = [0.1, 3]\n[[vary]]\nname = \"rtol\"\nlog_uniform = [1e-9, 1e-5]\n",
    )
    .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    let (a, b) = (scratch("threads1"), scratch("threads3"));
    let make = || Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base()).unwrap();
    make().threads(1).run(&a, &runs).unwrap();
    let s = make().threads(3).run(&b, &runs).unwrap();
    assert_eq!(s.threads, 3);
    let (ta, tb) = (
        without_cpu(&a.join("results.csv")),
        without_cpu(&b.join("results.csv")),
    );
    assert_eq!(ta.len(), 25);
    assert_eq!(ta, tb);
    // rows in run order whatever order the threads finished in
    let order: Vec<String> = (0..24).map(|i| i.to_string()).collect();
    assert_eq!(column(&b.join("results.csv"), "run"), order);
    let _ = std::fs::remove_dir_all(&a);
    let _ = std::fs::remove_dir_all(&b);
}

#[test]
fn a_sweep_started_again_makes_only_the_missing_runs() {
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"monte-carlo\"\nruns = 30\nseed = 11\n[[vary]]\nname = \"m\"\nnormal = [1, 0.1]\n",
    )
    .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    let dir = scratch("resume");
    let calls = std::sync::Arc::new(AtomicUsize::new(0));
    let counted = |calls: std::sync::Arc<AtomicUsize>| {
        Metrics::new(["q1_end"], move |_: &DoublePendulum, tr| {
            calls.fetch_add(1, Ordering::SeqCst);
            vec![tr.q(tr.len() - 1)[1]]
        })
    };
    let make = || Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base()).unwrap();
    make()
        .metrics(counted(calls.clone()))
        .run(&dir, &runs)
        .unwrap();
    assert_eq!(calls.load(Ordering::SeqCst), 30);
    let table = dir.join("results.csv");
    let full = without_cpu(&table);
    // a kill after run 9, in the middle of writing run 10's row
    let text = std::fs::read_to_string(&table).unwrap();
    let cut: usize = text.lines().take(11).map(|l| l.len() + 1).sum::<usize>() + 7;
    std::fs::write(&table, &text[..cut]).unwrap();
    let s = make()
        .metrics(counted(calls.clone()))
        .run(&dir, &runs)
        .unwrap();
    assert_eq!((s.skipped, s.ran), (10, 20));
    assert_eq!(calls.load(Ordering::SeqCst), 50);
    assert_eq!(without_cpu(&table), full);
    // a third start has nothing to do
    let s = make()
        .metrics(counted(calls.clone()))
        .run(&dir, &runs)
        .unwrap();
    assert_eq!((s.skipped, s.ran), (30, 0));
    // other metrics make other columns: that table is another sweep's
    assert!(matches!(
        make().run(&dir, &runs),
        Err(SweepError::Table { .. })
    ));
    // another plan in the same folder is refused
    let other = Plan::from_toml(
        "[sweep]\ndesign = \"monte-carlo\"\nruns = 30\nseed = 12\n[[vary]]\nname = \"m\"\nnormal = [1, 0.1]\n",
    )
    .unwrap();
    let err = Sweep::new(DoublePendulum::default, &other, Scheme::Dopri5, base())
        .unwrap()
        .run(&dir, &other.runs(Path::new(".")).unwrap())
        .unwrap_err();
    assert!(matches!(err, SweepError::OtherSweep { .. }), "{err}");
    // the same runs with other settings are refused too: the table would mix two sweeps
    let longer = Options {
        t_end: 3.0,
        ..base()
    };
    let err = Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, longer)
        .unwrap()
        .run(&dir, &runs)
        .unwrap_err();
    assert!(matches!(err, SweepError::OtherSettings { .. }), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn failed_runs_are_rows_that_say_why() {
    // seed2dof's fast mode (ω ≈ 45 rad/s) at rk4 steps of 0.1 s is unstable; k1 < 0 is
    // refused by the parameter check
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"list\"\nfile = \"runs.csv\"\n[simulation]\nscheme = \"rk4\"\nt_end = 1.0\n",
    )
    .unwrap();
    let dir = scratch("failures");
    std::fs::create_dir_all(&dir).unwrap();
    let list = dir.join("list");
    std::fs::create_dir_all(&list).unwrap();
    std::fs::write(
        list.join("runs.csv"),
        "h,k1\n0.001,79.15\n0.1,79.15\n0.001,-5\n",
    )
    .unwrap();
    let runs = plan.runs(&list).unwrap();
    let out = dir.join("out");
    let s = Sweep::new(Seed2dof::default, &plan, Scheme::Dopri5, base())
        .unwrap()
        .run(&out, &runs)
        .unwrap();
    assert_eq!((s.ran, s.failed), (3, 2));
    let table = out.join("results.csv");
    assert_eq!(column(&table, "status"), ["ok", "failed", "failed"]);
    assert_eq!(
        column(&table, "failure"),
        ["", "UnstableStep", "InvalidRun"]
    );
    assert!(
        column(&table, "message")[2].contains("k1"),
        "{:?}",
        column(&table, "message")
    );
    // the unstable run stopped early, its work counted; the refused one did no work
    let t: f64 = column(&table, "t_reached")[1].parse().unwrap();
    assert!(t < 1.0);
    assert_ne!(column(&table, "steps")[1], "");
    assert_eq!(column(&table, "steps")[2], "");
    assert_eq!(column(&table, "t_last")[1], "");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_panicking_metric_fails_its_row_not_the_sweep() {
    let plan =
        Plan::from_toml("[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"l\"\nvalues = [1, 2]\n")
            .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    let dir = scratch("panic");
    let metrics = Metrics::new(["x"], |m: &DoublePendulum, _| {
        assert!(m.params().l < 1.5, "too long");
        vec![1.0]
    });
    let s = Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base())
        .unwrap()
        .metrics(metrics)
        .run(&dir, &runs)
        .unwrap();
    assert_eq!(s.failed, 1);
    let table = dir.join("results.csv");
    assert_eq!(column(&table, "failure"), ["", "Panic"]);
    assert!(column(&table, "message")[1].contains("too long"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unknown_variables_are_refused_before_any_run() {
    let plan =
        Plan::from_toml("[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"length\"\nvalues = [1]\n")
            .unwrap();
    let Err(e) = Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base()) else {
        panic!("`length` accepted")
    };
    let text = e.to_string();
    assert!(
        text.contains("`length`") && text.contains("l, m, g") && text.contains("q[0]"),
        "{text}"
    );
    let plan =
        Plan::from_toml("[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"q0[2]\"\nvalues = [1]\n")
            .unwrap();
    assert!(Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base()).is_err());
}

/// Plans and settings at the edges: refused up front, or values the plan wrote, never NaN.
#[test]
fn settings_at_the_edges_are_refused_or_kept_finite() {
    // bounds near ±f64::MAX: their difference overflows, the values must not
    for vary in [
        "uniform = [-1e308, 1e308]",
        "range = [-1e308, 1e308]\ncount = 3",
    ] {
        let design = if vary.starts_with("range") {
            "\"grid\""
        } else {
            "\"monte-carlo\"\nruns = 5"
        };
        let plan = Plan::from_toml(&format!(
            "[sweep]\ndesign = {design}\n[[vary]]\nname = \"l\"\n{vary}\n"
        ))
        .unwrap();
        let runs = plan.runs(Path::new(".")).unwrap();
        for row in &runs.rows {
            let mbs::sweep::Value::Num(v) = row[0] else {
                panic!("{vary}: not a number")
            };
            assert!(v.is_finite() && v.abs() <= 1e308, "{vary}: {v}");
        }
    }
    // settings every run starts from, invalid: refused once, not a failed row per run
    let plan =
        Plan::from_toml("[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"l\"\nvalues = [1]\n[simulation]\nt_end = -1.0\n")
            .unwrap();
    let Err(e) = Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base()) else {
        panic!("t_end = -1 accepted")
    };
    assert!(e.to_string().contains("t_end"), "{e}");
    // more job-array tasks than runs
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"l\"\nvalues = [1, 2]\n[slurm]\ntasks = 3\n",
    )
    .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    let dir = scratch("edges");
    let e = Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base())
        .unwrap()
        .write_slurm(&dir, &runs, &["program".to_string()])
        .unwrap_err();
    assert!(e.to_string().contains("tasks = 3 is more than"), "{e}");
    // far more threads than runs: as many as there are runs
    let s = Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base())
        .unwrap()
        .threads(1_000_000)
        .run(&dir, &runs)
        .unwrap();
    assert_eq!((s.ran, s.threads), (2, 2));
    // shards of a count near usize::MAX: index·n would wrap
    let last = Shard {
        index: usize::MAX - 1,
        count: usize::MAX,
    };
    assert_eq!(last.range(4), 3..4);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn shards_merge_into_the_table_of_the_whole_sweep() {
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"monte-carlo\"\nruns = 17\nseed = 2\n[[vary]]\nname = \"l\"\nuniform = [0.5, 1.5]\n\
         [slurm]\ntasks = 3\n",
    )
    .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    let (whole, parts) = (scratch("whole"), scratch("parts"));
    let make = || Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base()).unwrap();
    make().run(&whole, &runs).unwrap();
    let script = make()
        .write_slurm(&parts, &runs, &["program".to_string()])
        .unwrap();
    let text = std::fs::read_to_string(&script).unwrap();
    assert!(
        text.contains("#SBATCH --array=0-2") && text.contains("--shard \"$SLURM_ARRAY_TASK_ID/3\"")
    );
    // shards 0 and 2 only: the merge lists the runs of shard 1 (runs 5..11)
    for k in [0, 2] {
        let shard = Shard { index: k, count: 3 };
        make().run_shard(&parts, &runs, shard).unwrap();
    }
    let err = merge(&parts).unwrap_err();
    assert!(
        matches!(&err, SweepError::Missing { missing: 6, tasks, .. } if tasks == "1"),
        "{err}"
    );
    let missing = std::fs::read_to_string(parts.join("missing.csv")).unwrap();
    assert_eq!(missing.lines().nth(1), Some("5,1"));
    make()
        .run_shard(&parts, &runs, Shard::parse("1/3").unwrap())
        .unwrap();
    let m = merge(&parts).unwrap();
    assert_eq!((m.runs, m.parts), (17, 3));
    assert!(!parts.join("missing.csv").exists());
    assert_eq!(
        without_cpu(&parts.join("results.csv")),
        without_cpu(&whole.join("results.csv"))
    );
    assert!(Shard::parse("3/3").is_err() && Shard::parse("1").is_err());
    // a shard made by hand is checked too: 1-based task numbers, or no shards at all
    for (index, count) in [(3, 3), (0, 0)] {
        let e = make()
            .run_shard(&parts, &runs, Shard { index, count })
            .unwrap_err();
        assert!(
            matches!(&e, SweepError::Shard(s) if *s == format!("{index}/{count}")),
            "{e}"
        );
    }
    // an empty table is refused, not read as one without columns
    let empty = parts.join("empty.csv");
    std::fs::write(&empty, "").unwrap();
    let e = mbs::sweep::parquet::write(&empty, &parts.join("empty.parquet")).unwrap_err();
    assert!(
        matches!(&e, SweepError::Table { .. }) && e.to_string().contains("no header"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&whole);
    let _ = std::fs::remove_dir_all(&parts);
}

/// The Parquet file of a complete sweep holds the CSV table, typed, with nulls where the CSV
/// is empty (a failed run's metrics).
#[test]
fn a_complete_sweep_is_also_a_parquet_file_of_the_same_table() {
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"scheme\"\nvalues = [\"dopri5\", \"rk4\"]\n\
         [[vary]]\nname = \"h\"\nvalues = [0.001, 0.5]\n",
    )
    .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    let dir = scratch("parquet");
    let s = Sweep::new(Seed2dof::default, &plan, Scheme::Dopri5, base())
        .unwrap()
        .run(&dir, &runs)
        .unwrap();
    assert_eq!(s.failed, 2, "dopri5 and rk4 at h = 0.5 are unstable");
    let csv_rows: Vec<csv::StringRecord> = csv::Reader::from_path(dir.join("results.csv"))
        .unwrap()
        .records()
        .map(Result::unwrap)
        .collect();
    let file = std::fs::File::open(dir.join("results.parquet")).unwrap();
    let reader = SerializedFileReader::new(file).unwrap();
    assert_eq!(reader.metadata().file_metadata().num_rows(), 4);
    for (row, rec) in reader.get_row_iter(None).unwrap().zip(&csv_rows) {
        let row = row.unwrap();
        let fields: Vec<(String, Field)> = row
            .get_column_iter()
            .map(|(n, f)| (n.clone(), f.clone()))
            .collect();
        assert_eq!(fields.len(), rec.len());
        for ((name, field), text) in fields.iter().zip(rec.iter()) {
            match field {
                Field::Null => assert_eq!(text, "", "{name}"),
                Field::Long(i) => assert_eq!(i.to_string(), text, "{name}"),
                Field::Double(x) => assert_eq!(*x, text.parse::<f64>().unwrap(), "{name}"),
                Field::Str(s) => assert_eq!(s, text, "{name}"),
                other => panic!("{name}: {other:?}"),
            }
        }
        // the failure's columns are strings, numbers are numbers
        assert!(matches!(fields[2].1, Field::Str(_) | Field::Null));
        assert!(matches!(fields[0].1, Field::Long(_)));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A metric named like a varied setting or a column of the table would double that column
/// (the per-system programs' final-state metric was `t_end`, the setting's name: a plan that
/// varied t_end had two `t_end` columns); the sweep is refused before any run, and the final
/// state's time is `t_last`.
#[test]
fn a_metric_that_would_double_a_column_is_refused() {
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"t_end\"\nvalues = [1, 2]\n",
    )
    .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    let dir = scratch("doubled");
    let sweep = |name: &'static str| {
        Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base())
            .unwrap()
            .metrics(Metrics::new([name], |_: &DoublePendulum, _| vec![0.0]))
    };
    for name in ["t_end", "steps"] {
        let e = sweep(name).run(&dir, &runs).unwrap_err();
        assert!(
            e.to_string().contains(&format!("two columns `{name}`")),
            "{e}"
        );
        assert!(!dir.join("results.csv").exists());
    }
    let s = Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base()).unwrap();
    let s = s.metrics(Metrics::final_state(&DoublePendulum::default()));
    assert!(s.run(&dir, &runs).is_ok());
    assert_eq!(column(&dir.join("results.csv"), "t_last"), ["1.0", "2.0"]);
    let _ = std::fs::remove_dir_all(&dir);
}

mod batch {
    #![allow(unused_macros)]
    include!("../benches/scaling/shapes.rs");
    chain!(Chain4, 4, batch);
}

/// The tables of `plan`'s runs of the 4-bar chain with DOPRI5 made on lanes and one at a
/// time (with `metrics` where given), in `dir`, checked to have made `count` runs, `lanes` of
/// them on lanes in the first where the processor has the lanes.
fn on_lanes_and_alone(
    plan: &Plan,
    dir: &Path,
    metrics: Option<&dyn Fn() -> Metrics<batch::Chain4>>,
    (count, lanes): (usize, usize),
) -> (PathBuf, PathBuf) {
    let runs = plan.runs(dir).unwrap();
    let table = |ensembles: bool, name: &str| {
        let d = dir.join(name);
        let mut s = Sweep::new(batch::Chain4::default, plan, Scheme::Dopri5, base())
            .unwrap()
            .ensembles(ensembles)
            .threads(2);
        if let Some(m) = metrics {
            s = s.metrics(m());
        }
        let summary = s.run(&d, &runs).unwrap();
        assert_eq!(summary.ran, count);
        let on_lanes = ensembles && mbs::lanes::simd_available();
        assert_eq!(summary.on_lanes, if on_lanes { lanes } else { 0 });
        d.join("results.csv")
    };
    (table(true, "lanes"), table(false, "alone"))
}

/// A sweep over starts alone of a model with `option batch;` runs its runs four at a time on
/// the lanes (`Sweep::ensembles`, on by default): the same rows as one run at a time — status,
/// failure, steps, evaluations, metrics to the rounding of the batch functions — a run that
/// fails failing alike.
#[test]
fn a_sweep_over_starts_runs_on_lanes_and_gives_the_rows_of_runs_alone() {
    use batch::Chain4;
    let plan = Plan::from_toml(
        r#"
        [sweep]
        design = "grid"
        [[vary]]
        name = "q0[0]"
        values = [0.1, 0.4, 0.7, 1.0, 1.3]
        [[vary]]
        name = "qd0[2]"
        values = [-1.0, 0.0, 2.0, 1e200]
        "#,
    )
    .unwrap();
    let dir = scratch("lanes");
    let runs = plan.runs(&dir).unwrap();
    // the five runs started at qd0[2] = 1e200 fail at their start (a generalized force not
    // finite), before a step: not made on lanes
    let (lanes, alone) = on_lanes_and_alone(&plan, &dir, None, (20, 15));
    for name in [
        "run",
        "status",
        "failure",
        "steps",
        "rejected",
        "evaluations",
    ] {
        assert_eq!(column(&lanes, name), column(&alone, name), "{name}");
    }
    let status = column(&lanes, "status");
    assert_eq!(status.iter().filter(|s| *s == "failed").count(), 5);
    let mut worst = 0.0f64;
    let headers: Vec<String> = csv::Reader::from_path(&lanes)
        .unwrap()
        .headers()
        .unwrap()
        .iter()
        .filter(|h| h.starts_with("q_end") || h.starts_with("qd_end"))
        .map(String::from)
        .collect();
    assert_eq!(headers.len(), 8, "{headers:?}");
    for name in &headers {
        for (a, b) in column(&lanes, name).iter().zip(column(&alone, name)) {
            if let (Ok(a), Ok(b)) = (a.parse::<f64>(), b.parse::<f64>()) {
                worst = worst.max((a - b).abs() / b.abs().max(1.0));
            }
        }
    }
    println!("a sweep of 20 runs on lanes against one at a time: metrics within {worst:.1e}");
    assert!(worst < 1e-9, "{worst:e}");
    // a metric that panics for the runs started at q0[0] = 0.4 fails those rows alone
    let d = dir.join("panics");
    let metric = Metrics::new(["q0"], |_: &Chain4, tr: &mbs::Trajectory| {
        assert!(tr.q(0)[0] != 0.4, "no metric here");
        vec![tr.q(0)[0]]
    });
    let s = Sweep::new(Chain4::default, &plan, Scheme::Dopri5, base())
        .unwrap()
        .metrics(metric)
        .threads(2);
    let summary = s.run(&d, &runs).unwrap();
    assert_eq!(summary.failed, 5 + 3);
    let table = d.join("results.csv");
    let kinds = column(&table, "failure");
    for (q0, kind) in column(&table, "q0[0]").iter().zip(&kinds) {
        assert!(kind != "Panic" || q0 == "0.4", "{q0}: {kind}");
    }
    assert_eq!(kinds.iter().filter(|k| *k == "Panic").count(), 3);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A sweep over parameters and starts of a model with `option batch;` runs on the lanes too,
/// each run with its own model (`simulate_ensemble_each`): the rows of one run at a time, and
/// the metrics see the run's own model.
#[test]
fn a_sweep_over_parameters_runs_on_lanes_each_run_with_its_model() {
    use batch::Chain4;
    let plan = Plan::from_toml(
        r#"
        [sweep]
        design = "grid"
        [[vary]]
        name = "l"
        values = [0.3, 0.5, 0.8]
        [[vary]]
        name = "m"
        values = [0.5, 2.0]
        [[vary]]
        name = "q0[1]"
        values = [0.2, 0.9]
        "#,
    )
    .unwrap();
    let dir = scratch("lanes-params");
    let metrics = || {
        Metrics::new(["model_l", "q1_end"], |m: &Chain4, tr: &mbs::Trajectory| {
            vec![m.params().l, tr.q(tr.len() - 1)[1]]
        })
    };
    let (lanes, alone) = on_lanes_and_alone(&plan, &dir, Some(&metrics), (12, 12));
    for name in [
        "run",
        "status",
        "steps",
        "rejected",
        "evaluations",
        "model_l",
    ] {
        assert_eq!(column(&lanes, name), column(&alone, name), "{name}");
    }
    assert!(column(&lanes, "status").iter().all(|s| s == "ok"));
    // each run's metrics saw its own model
    assert_eq!(column(&lanes, "model_l"), column(&lanes, "l"));
    let mut worst = 0.0f64;
    for (a, b) in column(&lanes, "q1_end")
        .iter()
        .zip(column(&alone, "q1_end"))
    {
        let (a, b): (f64, f64) = (a.parse().unwrap(), b.parse().unwrap());
        worst = worst.max((a - b).abs());
    }
    let ends: Vec<f64> = column(&alone, "q1_end")
        .iter()
        .map(|x| x.parse().unwrap())
        .collect();
    let spread =
        ends.iter().fold(f64::MIN, |m, &x| m.max(x)) - ends.iter().fold(f64::MAX, |m, &x| m.min(x));
    println!(
        "a sweep of 12 runs over l, m and q0[1] on lanes against one at a time: q1 at the end within {worst:.1e} (the runs' values spread over {spread:.2})"
    );
    assert!(worst < 1e-9, "{worst:e}");
    assert!(spread > 0.1, "{ends:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

mbs::multibody! {
    /// Two hinges whose start is set by a parameter.
    model StartsFromA0 {
        param a0 = 0.3; param l = 1.0;
        dof a = a0; dof b = 2 * a0, qd = a0;
        body bob { mass = 1.0; inertia = (0.01, 0.01, 0.01); }
        body arm { mass = 1.0; inertia = (0.01, 0.01, 0.01); }
        TOG[arm] = Trotz(a) * Tdisp(l, 0, 0);
        TOG[bob] = TOG[arm] * Trotz(b) * Tdisp(l, 0, 0);
        gravity(0, -9.81, 0);
        option batch;
    }
}

/// A sweep over a parameter that sets the start and over one start value: the coordinates
/// not varied start where the run's model starts them (its parameter set), on lanes and one
/// at a time, where they started from the base model's start.
#[test]
fn coordinates_not_varied_start_from_the_run_s_own_model() {
    let plan = Plan::from_toml(
        r#"
        [sweep]
        design = "grid"
        [[vary]]
        name = "a0"
        values = [0.1, 0.4]
        [[vary]]
        name = "qd0[0]"
        values = [0.0, 0.5]
        "#,
    )
    .unwrap();
    let dir = scratch("starts");
    let runs = plan.runs(&dir).unwrap();
    for ensembles in [true, false] {
        let d = dir.join(ensembles.to_string());
        let metrics = Metrics::new(
            ["b0", "bd0", "ad0"],
            |_: &StartsFromA0, tr: &mbs::Trajectory| vec![tr.q(0)[1], tr.qd(0)[1], tr.qd(0)[0]],
        );
        let summary = Sweep::new(StartsFromA0::default, &plan, Scheme::Dopri5, base())
            .unwrap()
            .metrics(metrics)
            .ensembles(ensembles)
            .threads(1)
            .run(&d, &runs)
            .unwrap();
        assert_eq!((summary.ran, summary.failed), (4, 0));
        let table = d.join("results.csv");
        let num = |name: &str| -> Vec<f64> {
            column(&table, name)
                .iter()
                .map(|x| x.parse().unwrap())
                .collect()
        };
        let (a0, qd0) = (num("a0"), num("qd0[0]"));
        for (k, ((b0, bd0), ad0)) in num("b0")
            .into_iter()
            .zip(num("bd0"))
            .zip(num("ad0"))
            .enumerate()
        {
            assert_eq!(
                (b0, bd0),
                (2.0 * a0[k], a0[k]),
                "run {k}, ensembles {ensembles}"
            );
            assert_eq!(ad0, qd0[k], "run {k}, ensembles {ensembles}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A list design's array tasks read the list from the sweep's folder: its plan.toml named
/// the user's file, which lies beside the user's plan, so every task failed to read it (or,
/// named runs.csv, read the folder's run list as a list with a variable `run`).
#[test]
fn a_list_design_s_folder_holds_its_runs_for_the_array_tasks() {
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"list\"\nfile = \"points.csv\"\n[simulation]\nt_end = 0.1\n\
         [slurm]\ntasks = 2\n",
    )
    .unwrap();
    let dir = scratch("list_slurm");
    let study = dir.join("study");
    std::fs::create_dir_all(&study).unwrap();
    std::fs::write(study.join("points.csv"), "l,m\n1.0,1.0\n0.8,1.2\n1.1,0.9\n").unwrap();
    let runs = plan.runs(&study).unwrap();
    let out = dir.join("out");
    let make = || Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, base()).unwrap();
    make()
        .write_slurm(&out, &runs, &["program".to_string()])
        .unwrap();
    // what a task does: the plan of the folder, its runs from the folder
    let task_plan = Plan::load(&out.join("plan.toml")).unwrap();
    let task_runs = task_plan.runs(&out).unwrap();
    assert_eq!(task_runs, runs);
    let task = Sweep::new(DoublePendulum::default, &task_plan, Scheme::Dopri5, base()).unwrap();
    task.run_shard(&out, &task_runs, Shard { index: 0, count: 2 })
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scheme's parameters are settings of the sweep: resumed with other ones, the folder is
/// refused; read by a program whose scheme of that name has other ones (an array task), the
/// plan is refused. Both mixed or ran the runs with other parameters silently: the plan
/// recorded the scheme's name alone, and read back it meant the default parameters.
#[test]
fn a_scheme_s_parameters_are_settings_of_the_sweep() {
    use mbs::BdfParams;
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"l\"\nvalues = [0.9, 1.0]\n[simulation]\nt_end = 0.2\n",
    )
    .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    let dir = scratch("scheme_parameters");
    let order2 = Scheme::Bdf(BdfParams { max_order: 2 });
    let sweep =
        |scheme: Scheme, plan: &Plan| Sweep::new(DoublePendulum::default, plan, scheme, base());
    sweep(order2, &plan).unwrap().run(&dir, &runs).unwrap();
    let err = sweep(Scheme::Bdf(BdfParams::default()), &plan)
        .unwrap()
        .run(&dir, &runs)
        .unwrap_err();
    assert!(matches!(err, SweepError::OtherSettings { .. }), "{err}");
    // the folder's plan, as an array task reads it
    let recorded = Plan::load(&dir.join("plan.toml")).unwrap();
    let Err(err) = sweep(Scheme::Bdf(BdfParams::default()), &recorded) else {
        panic!("the default BDF accepted a plan made with max_order 2");
    };
    assert!(err.to_string().contains("max_order: 2"), "{err}");
    // with the scheme it was made with, the folder's plan resumes it: nothing left to run
    let s = sweep(order2, &recorded).unwrap().run(&dir, &runs).unwrap();
    assert_eq!((s.skipped, s.ran), (2, 0));
    let _ = std::fs::remove_dir_all(&dir);
}

mbs::multibody! {
    /// A spherical pendulum released 0.57 rad from hanging, where the ZYX chart it starts in
    /// locks: its runs end in charts of their own.
    model Swinging {
        dof a = 0.0; dof b = 1.0; dof c = 0.0;
        body bob { mass = 1.0; inertia = (0.01, 0.02, 0.02); }
        TOG[bob] = Tball(a, b, c) * Tdisp(1.0, 0.0, 0.2);
        gravity(0, 0, -9.81);
    }
}

/// A rotation joint's final angles and rates in a sweep's table are read in the chart the
/// start is given in, not the one each run happened to end in: the same orientation and
/// angular velocity as the run's last output.
#[test]
fn final_angles_are_read_in_the_chart_of_the_start() {
    use mbs::charts::{body_rates, zyx};
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"qd0.a\"\nvalues = [0.0, 0.7]\n",
    )
    .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    let dir = scratch("charts");
    let sweep = Sweep::new(Swinging::default, &plan, Scheme::Dopri5, base())
        .unwrap()
        .metrics(Metrics::final_state(&Swinging::default()));
    assert_eq!(sweep.run(&dir, &runs).unwrap().failed, 0);
    let table = dir.join("results.csv");
    let read = |name: &str| -> Vec<f64> {
        column(&table, name)
            .iter()
            .map(|x| x.parse().unwrap())
            .collect()
    };
    let (a, b, c) = (read("q_end.a"), read("q_end.b"), read("q_end.c"));
    let (ad, bd, cd) = (read("qd_end.a"), read("qd_end.b"), read("qd_end.c"));
    for (k, spin) in [0.0, 0.7].into_iter().enumerate() {
        let model = Swinging::default();
        let (mut q0, mut qd0) = (vec![0.0; 3], vec![0.0; 3]);
        model.initial_state(&mut q0, &mut qd0);
        qd0[0] = spin;
        let o = Options {
            q0: Some(q0),
            qd0: Some(qd0),
            ..base()
        };
        let (tr, _) = simulate(model, Scheme::Dopri5, o).unwrap();
        let last = tr.len() - 1;
        let chart = tr.chart(last, 0);
        assert_ne!(chart, mbs::IDENTITY3, "run {k} ends in another chart");
        let (q, qd) = (tr.q(last), tr.qd(last));
        let r = nalgebra::Matrix3::from_fn(|i, j| chart[i][j]) * zyx([q[0], q[1], q[2]]);
        let table_r = zyx([a[k], b[k], c[k]]);
        assert!(
            (r - table_r).amax() < 1e-9,
            "run {k}: {r} against {table_r}"
        );
        let w = body_rates([q[0], q[1], q[2]], [qd[0], qd[1], qd[2]]);
        let table_w = body_rates([a[k], b[k], c[k]], [ad[k], bd[k], cd[k]]);
        for i in 0..3 {
            assert!(
                (w[i] - table_w[i]).abs() < 1e-9,
                "run {k}: ω {w:?} against {table_w:?}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A sweep whose start is set in Rust (t0, q0) records it in its folder's `plan.toml`, so that
/// a program reading that plan with its own defaults (an array task) makes the same runs.
#[test]
fn the_folder_s_plan_records_the_start() {
    let plan = Plan::from_toml(
        "[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"qd0[1]\"\nvalues = [0.0, 0.5]\n",
    )
    .unwrap();
    let runs = plan.runs(Path::new(".")).unwrap();
    let dir = scratch("start");
    let options = Options {
        t0: 1.0,
        q0: Some(vec![0.3, -0.2]),
        ..base()
    };
    let sweep = Sweep::new(DoublePendulum::default, &plan, Scheme::Dopri5, options).unwrap();
    sweep.run(&dir, &runs).unwrap();
    let recorded = Plan::load(&dir.join("plan.toml")).unwrap();
    assert_eq!(recorded.simulation.t0, Some(1.0));
    assert_eq!(recorded.simulation.q0, Some(vec![0.3, -0.2]));
    // the recorded plan with the defaults: the same table
    let again = scratch("start-again");
    let sweep = Sweep::new(DoublePendulum::default, &recorded, Scheme::Dopri5, base()).unwrap();
    sweep.run(&again, &recorded.runs(&dir).unwrap()).unwrap();
    let table = |d: &Path| {
        let mut r = csv::Reader::from_path(d.join("results.csv")).unwrap();
        let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
        let kept: Vec<usize> = (0..header.len())
            .filter(|&i| header[i] == "t_last" || header[i].starts_with("q_end."))
            .collect();
        let rows: Vec<Vec<String>> = r
            .records()
            .map(|rec| {
                kept.iter()
                    .map(|&i| rec.as_ref().unwrap()[i].to_string())
                    .collect()
            })
            .collect();
        rows
    };
    let (first, second) = (table(&dir), table(&again));
    assert_eq!(first.len(), 2);
    assert_eq!(first, second);
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&again);
}

/// Plans changed as a user's slips would (a value replaced by an empty, negative, huge,
/// non-finite, fractional or mistyped one, or by another of the plan's values; a line deleted
/// or repeated; one to three changes): parsed, expanded into runs, checked against the model
/// and, when there are at most four runs, run — a typed `SweepError` with a message at the
/// first step that refuses, never a panic.
#[test]
fn changed_plans_are_refused_typed_or_run() {
    const VALUES: [&str; 14] = [
        "0",
        "-1",
        "1e308",
        "-1e308",
        "nan",
        "inf",
        "0.5",
        "1e12",
        "\"\"",
        "\"x\"",
        "[]",
        "[1, \"a\"]",
        "[2, 1]",
        "18446744073709551615",
    ];
    let plans = [
        "[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"l\"\nvalues = [0.8, 1.0]\n[[vary]]\nname = \"scheme\"\nvalues = [\"dopri5\", \"radau5\"]\n[[vary]]\nname = \"qd0[1]\"\nrange = [0.0, 1.0]\ncount = 1\n",
        "[sweep]\ndesign = \"lhs\"\nruns = 3\nseed = 5\n[[vary]]\nname = \"l\"\nuniform = [0.5, 2]\n[[vary]]\nname = \"q0.q[0]\"\nuniform = [0.1, 3]\n[[vary]]\nname = \"rtol\"\nlog_uniform = [1e-9, 1e-5]\n",
        "[sweep]\ndesign = \"monte-carlo\"\nruns = 3\nseed = 11\n[[vary]]\nname = \"m\"\nnormal = [1, 0.1]\n[simulation]\nt_end = 0.05\n[slurm]\ntasks = 2\n",
        "[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"scheme\"\nvalues = [\"dopri5\", \"rk4\"]\n[[vary]]\nname = \"h\"\nvalues = [0.001, 0.5]\n",
    ];
    let mut rng = Lcg(3);
    let mut tally = std::collections::BTreeMap::<&str, usize>::new();
    let mut broken = Vec::new();
    let dir = scratch("changed");
    let short = Options {
        t_end: 0.05,
        ..base()
    };
    for (p, plan) in plans.iter().enumerate() {
        for _ in 0..150 {
            let mut lines: Vec<String> = plan.lines().map(str::to_string).collect();
            let mut what = String::new();
            for _ in 0..1 + rng.below(3) {
                let l = rng.below(lines.len());
                match rng.below(4) {
                    0 => {
                        what += &format!(" line {l} deleted;");
                        lines.remove(l);
                    }
                    1 => {
                        what += &format!(" line {l} repeated;");
                        lines.insert(l, lines[l].clone());
                    }
                    _ => {
                        if let Some(i) = lines[l].find(" = ") {
                            let new = if rng.below(3) == 0 {
                                let other = plan.lines().nth(rng.below(plan.lines().count()));
                                other
                                    .and_then(|o| o.split_once(" = ").map(|x| x.1.to_string()))
                                    .unwrap_or_default()
                            } else {
                                VALUES[rng.below(VALUES.len())].to_string()
                            };
                            what += &format!(" `{}` → `{new}`;", lines[l]);
                            lines[l] = format!("{} = {new}", &lines[l][..i]);
                        }
                    }
                }
            }
            let text = lines.join("\n");
            let tag = format!("plan {p}:{what}");
            let outcome = sweeps::quiet_catch(|| -> Result<&'static str, SweepError> {
                let plan = Plan::from_toml(&text)?;
                let runs = plan.runs(Path::new("."))?;
                let sweep = Sweep::new(
                    DoublePendulum::default,
                    &plan,
                    Scheme::Dopri5,
                    short.clone(),
                )?;
                if runs.len() > 4 {
                    return Ok("checked, not run");
                }
                let _ = std::fs::remove_dir_all(&dir);
                sweep.threads(1).run(&dir, &runs)?;
                Ok("ran")
            });
            match outcome {
                Err(_) => broken.push(format!("{tag} panicked")),
                Ok(Ok(kind)) => *tally.entry(kind).or_default() += 1,
                Ok(Err(e)) => {
                    let text = e.to_string();
                    if text.trim().is_empty() {
                        broken.push(format!("{tag} an error without a message"));
                    }
                    // the reader quoted 1e308 where a list was expected as its 309 digits
                    if sweeps::longest_number(&text) > 20 {
                        broken.push(format!("{tag} a number written out in full: {text}"));
                    }
                    *tally.entry("refused").or_default() += 1;
                }
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    println!("{tally:?}");
    assert!(broken.is_empty(), "{}", broken.join("\n"));
    assert!(
        tally.contains_key("ran") && tally.contains_key("refused"),
        "{tally:?}"
    );
    quoted::says(
        "README.md",
        &[format!(
            "a line deleted or repeated; {} plans) are refused with a typed `SweepError` or run, \
             never a panic",
            quoted::thousands(tally.values().sum())
        )],
    );
}
