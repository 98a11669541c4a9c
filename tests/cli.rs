//! `mbs::cli`: the per-system programs' command line, run as a program would run it.

use mbs::cli::{MAX_KEPT, Parser, RunArgs, RunError, parse_constraint_method};
use mbs::{ConstraintMethod, Failure};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::example;

mbs::multibody! {
    /// A pendulum with a damper in one scene of two.
    pub model Swing {
        param l = 1.0; param m = 1.0; param g = 9.81; param c = 0.3;
        dof q[0] = 1.0;
        body bob { mass = m; inertia = (0.01, 0.01, 0.01); }
        TOG[bob] = Trotz(q[0]) * Tdisp(0, -l, 0);
        effect gravity { gravity(0, -g, 0); }
        effect damper { torque(bob, axis = z, -c * qd[0]); }
        scene Free = [gravity];
        scene Damped = [gravity, damper];
    }
}

fn args(extra: &[&str]) -> RunArgs {
    let mut all = vec!["program", "--quiet"];
    all.extend_from_slice(extra);
    RunArgs::parse_from(all)
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("mbs-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn a_run_writes_every_output_with_named_columns() {
    let dir = scratch("outputs");
    let out = dir.to_string_lossy().to_string();
    let a = args(&[
        "--scheme", "radau5", "--rtol", "1e-8", "--t-end", "2", "--dt", "0.1", "--out", &out,
    ]);
    let report = a.run(SwingFree::default(), 10.0).unwrap();
    // --t-end overrides the program's default; --dt samples every 0.1 s
    assert_eq!(report.trajectory.len(), 21);
    assert!((report.trajectory.t[20] - 2.0).abs() < 1e-12);
    assert!(report.conservative);
    let e = report.energy_error().unwrap();
    assert!(e > 0.0 && e < 1e-6, "{e:e}");
    let csv = std::fs::read_to_string(dir.join("trajectory.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.starts_with("t,q[0],qd[0],qdd[0]"), "{header}");
    assert_eq!(csv.lines().count(), 22);
    for file in ["coordinates.svg", "energy.svg"] {
        let svg = std::fs::read_to_string(dir.join(file)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("</svg>"), "{file}");
    }
    let html = std::fs::read_to_string(dir.join("animation.html")).unwrap();
    assert!(html.contains("<canvas") && !html.contains("http://") && !html.contains("https://"));
    let gltf: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("motion.gltf")).unwrap()).unwrap();
    assert_eq!(gltf["asset"]["version"], "2.0");
    let summary = report.summary("SwingFree");
    assert!(summary.contains("radau5") && summary.contains("max|ΔE|/E"));
    assert!(!summary.contains("not an error"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_damped_scene_says_its_energy_change_is_not_an_error() {
    let a = args(&["--t-end", "1"]);
    let report = a.run(SwingDamped::default(), 10.0).unwrap();
    assert!(!report.conservative);
    assert!(report.summary("SwingDamped").contains("not an error"));
}

#[test]
fn bad_arguments_are_refused_with_what_is_known() {
    // a scene the model is not
    let e = args(&["--scene", "Damped"])
        .run(SwingFree::default(), 1.0)
        .err()
        .unwrap();
    assert!(matches!(e, RunError::UnknownScene { .. }), "{e}");
    assert!(
        e.to_string().contains("`Damped`") && e.to_string().contains("Free"),
        "{e}"
    );
    // in a sweep too (it once ran the model it was given, whatever the scene asked)
    let e = args(&[
        "--scene",
        "Damped",
        "--sweep",
        "plan.toml",
        "--out",
        "sweep",
    ])
    .sweep(SwingFree::default(), 1.0)
    .err()
    .unwrap();
    assert!(matches!(e, RunError::UnknownScene { .. }), "{e}");
    // the right one runs
    assert!(
        args(&["--scene", "Damped", "--t-end", "0.1"])
            .run(SwingDamped::default(), 1.0)
            .is_ok()
    );
    // an unknown scheme names the known ones
    let e = args(&["--scheme", "rk45"])
        .run(SwingFree::default(), 1.0)
        .err()
        .unwrap();
    assert!(
        e.to_string().contains("`rk45`") && e.to_string().contains("dopri5"),
        "{e}"
    );
    // invalid options are the runtime's typed errors, before any step
    let e = args(&["--h=-0.1"])
        .run(SwingFree::default(), 1.0)
        .err()
        .unwrap();
    assert!(matches!(e, RunError::Simulation(_)), "{e}");
    assert!(e.to_string().starts_with("--h -0.1 is invalid"), "{e}");
    // constraint methods
    assert_eq!(
        parse_constraint_method("index3"),
        Ok(ConstraintMethod::Index3)
    );
    assert_eq!(
        parse_constraint_method("baumgarte:5,10"),
        Ok(ConstraintMethod::Baumgarte {
            alpha: 5.0,
            beta: 10.0
        })
    );
    assert!(
        parse_constraint_method("baumgarte:5")
            .unwrap_err()
            .contains("baumgarte:ALPHA,BETA")
    );
    assert!(RunArgs::try_parse_from(["program", "--constraints", "magic"]).is_err());
}

/// The last row's time and the number of rows of a CSV file the command line wrote.
fn csv_rows(path: &std::path::Path) -> (f64, usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    let last = rows.last().map_or(f64::NAN, |r| {
        r.split(',').next().unwrap().parse::<f64>().unwrap()
    });
    (last, rows.len())
}

#[test]
fn negative_numbers_reach_the_option_check() {
    // clap would take `-1` for a flag; the run's own check answers, naming the flag
    for (flag, value) in [("--t-end", "-1"), ("--rtol", "-1e-6"), ("--h", "-0.01")] {
        let a = RunArgs::try_parse_from(["program", "--quiet", flag, value])
            .unwrap_or_else(|e| panic!("{flag} {value}: {e}"));
        let e = a.run(SwingFree::default(), 1.0).err().unwrap();
        assert!(matches!(e, RunError::Simulation(_)), "{e}");
        assert!(e.to_string().starts_with(&format!("{flag} -")), "{e}");
        assert!(e.to_string().contains("is invalid"), "{e}");
    }
}

#[test]
fn advice_names_flags_not_rust_types() {
    // a fixed-step scheme without --h
    let e = args(&["--scheme", "rk4"])
        .run(SwingFree::default(), 1.0)
        .err()
        .unwrap();
    let text = e.to_string();
    assert!(text.contains("--h 1e-3"), "{text}");
    assert!(!text.contains("StepControl"), "{text}");
    // the library's own message keeps naming its API
    let RunError::Simulation(sim) = &e else {
        panic!("{e}")
    };
    assert!(sim.to_string().contains("StepControl::Fixed"), "{sim}");
    // RK4 past its stability limit (ω ≈ 3.1 rad/s, ωh must stay below 2.8)
    let e = args(&["--scheme", "rk4", "--h", "1.5"])
        .run(SwingFree::default(), 10.0)
        .err()
        .unwrap();
    let text = e.to_string();
    assert!(
        text.contains("take --h ") && text.contains("--scheme radau5"),
        "{text}"
    );
    // Newton failing at a fixed step: a smaller --h to type, not h_min (the double
    // pendulum at h = 0.3 s under Radau5)
    let e = args(&["--scheme", "radau5", "--h", "0.3"])
        .run(mbs_models::dpend::DoublePendulum::default(), 10.0)
        .err()
        .unwrap();
    let text = e.to_string();
    assert!(
        text.contains("at the fixed step") && text.contains("e.g. --h 7.5e-2"),
        "{text}"
    );
    assert!(
        !text.contains("h_min") && !text.contains("StepControl"),
        "{text}"
    );
    // an index-3 request of a scheme that cannot
    let e = args(&["--scheme", "dopri5", "--constraints", "index3"])
        .run(Pendulum3::default(), 1.0)
        .err()
        .unwrap();
    assert!(e.to_string().contains("--constraints projection"), "{e}");
    assert!(
        e.to_string().contains("--constraints index3 or index2"),
        "{e}"
    );
    // trapezoidal Newmark (no numerical damping) asked to control its step at index 3 or 2:
    // a fixed step or a damped member, not a list of schemes that names it as one that can
    for method in ["index3", "index2"] {
        let e = args(&["--scheme", "newmark", "--constraints", method])
            .run(Pendulum3::default(), 1.0)
            .err()
            .unwrap();
        let text = e.to_string();
        assert!(
            text.contains("--h 1e-3") && text.contains("--scheme gen-alpha or hht"),
            "{text}"
        );
        assert!(!text.contains("newmark, radau3"), "{text}");
    }
}

mbs::multibody! {
    /// A pendulum in Cartesian coordinates closed by a rod: one constraint.
    pub model Pendulum3 {
        param l = 1.0; param m = 1.0; param g = 9.81;
        dof x = 1.0; dof y = 0.0;
        body bob { mass = m; inertia = (0.01, 0.01, 0.01); }
        TOG[bob] = Tdisp(x, y, 0);
        gravity(0, -g, 0);
        constraint rod = x * x + y * y - l * l;
    }
}

#[test]
fn a_failing_run_writes_what_it_computed() {
    let dir = scratch("failing");
    let out = dir.to_string_lossy().to_string();
    // 100 steps of 1 ms are allowed, 1000 are needed
    let a = args(&[
        "--scheme",
        "rk4",
        "--h",
        "1e-3",
        "--t-end",
        "1",
        "--max-steps",
        "100",
        "--out",
        &out,
    ]);
    let e = a.run(SwingFree::default(), 1.0).err().unwrap();
    let RunError::Stopped {
        failure: Some(failure),
        report,
    } = &e
    else {
        panic!("{e}")
    };
    assert!(
        matches!(failure.kind, Failure::TooMuchWork { max_steps: 100, .. }),
        "{failure}"
    );
    assert!(e.to_string().contains("--max-steps"), "{e}");
    assert!(!e.to_string().contains("max_steps"), "{e}");
    // a fixed step's run says how many steps it needs, not that it may be stiff
    assert!(e.to_string().contains("needs 1000 steps"), "{e}");
    assert!(e.to_string().contains("a larger --h"), "{e}");
    assert!(!e.to_string().contains("stiff"), "{e}");
    assert_eq!(report.stats.steps, 100);
    assert_eq!(report.outputs, 101);
    let (last, rows) = csv_rows(&dir.join("trajectory.csv"));
    assert_eq!(rows, 101);
    assert!((last - 0.1).abs() < 1e-12, "{last}");
    assert_eq!(report.trajectory.t.last(), Some(&last));
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("stats.json")).unwrap()).unwrap();
    assert!(
        stats["status"].as_str().unwrap().starts_with("failed"),
        "{stats}"
    );
    assert_eq!(stats["stats"]["steps"], 100);
    assert_eq!(stats["outputs"], 101);
    for file in [
        "coordinates.svg",
        "energy.svg",
        "animation.html",
        "motion.gltf",
    ] {
        assert!(dir.join(file).exists(), "{file}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_long_run_holds_a_bounded_number_of_outputs() {
    let dir = scratch("long");
    let out = dir.to_string_lossy().to_string();
    // 200,000 steps, each an output
    let a = args(&[
        "--scheme", "rk4", "--h", "1e-4", "--t-end", "20", "--out", &out,
    ]);
    let report = a.run(SwingFree::default(), 1.0).unwrap();
    assert_eq!(report.stats.steps, 200_000);
    assert_eq!(report.outputs, 200_001);
    let (last, rows) = csv_rows(&dir.join("trajectory.csv"));
    assert_eq!(rows, 200_001);
    assert!((last - 20.0).abs() < 1e-9, "{last}");
    // 60 outputs per simulated second, the first and the last
    let kept = report.trajectory.len();
    assert!((1200..=1202).contains(&kept), "{kept}");
    assert_eq!(report.trajectory.t.last(), Some(&last));
    assert!(
        report.peak_held <= kept + 2,
        "{} held for {kept} kept",
        report.peak_held
    );
    // the energy error is over every output, not the kept ones
    let e = report.energy_error().unwrap();
    assert!(e > 0.0 && e < 1e-9, "{e:e}");
    // a run longer than MAX_KEPT / 60 s keeps MAX_KEPT outputs, evenly spaced
    let report = args(&["--scheme", "rk4", "--h", "1e-2", "--t-end", "1000"])
        .run(SwingFree::default(), 1.0)
        .unwrap();
    assert_eq!(report.outputs, 100_001);
    let kept = report.trajectory.len();
    assert!((MAX_KEPT..=MAX_KEPT + 2).contains(&kept), "{kept}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(unix)]
#[test]
fn ctrl_c_stops_a_program_which_keeps_its_outputs() {
    let dir = scratch("sigint");
    let program = example("dpend");
    // a million seconds at fixed steps of 1 ms, an output every second: hours (every 10 ms,
    // the outputs would take 26 GB, which the run refuses up front)
    let mut child = Command::new(&program)
        .args([
            "--scheme", "rk4", "--h", "1e-3", "--dt", "1", "--t-end", "1e6",
        ])
        .args(["--max-steps", "2000000000", "--out"])
        .arg(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // wait (bounded) for the line that says the run started
    let stdout = child.stdout.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            if line.starts_with("running ") {
                let _ = tx.send(());
            }
        }
    });
    let started = rx.recv_timeout(Duration::from_secs(120));
    if started.is_err() {
        let _ = child.kill();
        panic!("{} did not start its run within 120 s", program.display());
    }
    // let it write some rows (the file grows by buffers of several kB), then Ctrl-C
    let csv = dir.join("trajectory.csv");
    let deadline = Instant::now() + Duration::from_secs(120);
    while std::fs::metadata(&csv).map_or(0, |m| m.len()) == 0 {
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("{} wrote no rows within 120 s", csv.display());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let deadline = Instant::now() + Duration::from_secs(120);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("the program did not stop within 120 s of SIGINT");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let mut stderr = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
    assert!(!status.success(), "{status:?}: {stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    let (last, rows) = csv_rows(&csv);
    assert!(rows > 1, "{rows} rows");
    assert!(last > 0.0 && last < 1e6, "{last}");
    let stats = std::fs::read_to_string(dir.join("stats.json")).unwrap();
    assert!(stats.contains("interrupted"), "{stats}");
    let _ = std::fs::remove_dir_all(&dir);
}

mbs::multibody! {
    /// A pendulum pushed by an input torque.
    pub model Pushed {
        param l = 1.0; param m = 1.0; param g = 9.81;
        dof q[0] = 0.0;
        input push;
        body bob { mass = m; inertia = (0.01, 0.01, 0.01); }
        TOG[bob] = Trotz(q[0]) * Tdisp(0, -l, 0);
        gravity(0, -g, 0);
        generalized_force(q[0], u[0]);
    }
}

#[test]
fn a_model_with_inputs_runs_with_the_programs_defaults() {
    let defaults = [("scheme", "radau5"), ("rtol", "1e-9"), ("dt", "0.5")];
    let a = RunArgs::try_parse_with_defaults(["program", "--quiet", "--t-end", "2"], &defaults)
        .unwrap();
    assert_eq!(
        (a.scheme.as_str(), a.rtol, a.dt),
        ("radau5", 1e-9, Some(0.5))
    );
    // what is typed wins over the program's defaults
    let b = RunArgs::try_parse_with_defaults(["program", "--scheme", "bdf"], &defaults).unwrap();
    assert_eq!(b.scheme, "bdf");
    // a torque held at m g l / 2 from t = 0 by a controller sampled every 0.1 s: the
    // pendulum swings about the angle where gravity balances it, asin(1/2), up to where
    // 1 − cos q = q / 2 (1.109 rad); unpushed it would stay at q = 0
    let inputs = mbs::Inputs::new().controller(0.1, |_t: f64, _s: &mbs::State, u: &mut [f64]| {
        u[0] = 0.5 * 9.81
    });
    let report = a.run_with(Pushed::default(), 10.0, inputs).unwrap();
    assert_eq!(report.trajectory.len(), 5);
    assert_eq!(report.stats.samples, 21);
    let peak = (0..5)
        .map(|i| report.trajectory.q(i)[0])
        .fold(0.0, f64::max);
    assert!(peak > 0.3 && peak < 1.11, "{peak}");
    // a model without inputs refuses them
    assert!(matches!(
        args(&[]).run_with(
            SwingFree::default(),
            1.0,
            mbs::Inputs::new().function(|_, u| u[0] = 1.0)
        ),
        Err(RunError::Simulation(_))
    ));
    // the matrices of a linearisation are named through mbs
    let lin = mbs::linearize(
        &SwingFree::default(),
        0.0,
        &[0.0],
        &[0.0],
        &[],
        mbs::IterationMatrix::Auto,
    )
    .unwrap();
    let k: &mbs::DMatrix<f64> = &lin.k;
    assert!((k[(0, 0)] - 9.81).abs() < 1e-9, "{k}");
}

/// `--global-error`: the run is repeated at tighter tolerances until the estimated error of
/// the trajectory is within --rtol; the outputs are those asked (--dt), the report holds the
/// runs and its stats their work, and the result is within rtol of a run at rtol 1e-12.
/// A fixed step conflicts with it; a model with inputs driven by Rust code is refused; a bad
/// option is refused before any file is written.
#[test]
fn global_error_control_from_the_command_line() {
    let dir = scratch("global");
    let out = dir.to_string_lossy().to_string();
    let rtol = 1e-6;
    let a = args(&[
        "--rtol",
        "1e-6",
        "--t-end",
        "5",
        "--dt",
        "0.1",
        "--global-error",
        "--out",
        &out,
    ]);
    let report = a.run(SwingFree::default(), 10.0).unwrap();
    let g = report
        .global
        .as_ref()
        .expect("the runs of the global control");
    assert!(g.estimate <= 1.0 && g.runs.len() >= 2, "{g}");
    assert_eq!(
        report.stats.steps,
        g.runs.iter().map(|r| r.steps).sum::<usize>()
    );
    assert_eq!(report.trajectory.len(), 51);
    let csv = std::fs::read_to_string(dir.join("trajectory.csv")).unwrap();
    assert_eq!(csv.lines().count(), 52);
    let tight = args(&["--rtol", "1e-12", "--t-end", "5", "--dt", "0.1"])
        .run(SwingFree::default(), 10.0)
        .unwrap();
    for i in 0..51 {
        let (q, r) = (report.trajectory.q(i)[0], tight.trajectory.q(i)[0]);
        let (qd, rd) = (report.trajectory.qd(i)[0], tight.trajectory.qd(i)[0]);
        let bound = |r: f64| rtol * (0.01 + r.abs());
        assert!(
            (q - r).abs() <= bound(r) && (qd - rd).abs() <= bound(rd),
            "at {i}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(RunArgs::try_parse_from(["program", "--global-error", "--h", "0.01"]).is_err());
    let e = args(&["--global-error"])
        .run_with(SwingFree::default(), 1.0, mbs::Inputs::new())
        .err()
        .unwrap();
    assert!(matches!(e, RunError::GlobalWithInputs), "{e}");
    // a bad option is refused before anything is run or written, as without the flag
    let dir = scratch("global-refused");
    let out = dir.to_string_lossy().to_string();
    let e = args(&["--global-error", "--rtol", "-1e-6", "--out", &out])
        .run(SwingFree::default(), 1.0)
        .err()
        .unwrap();
    assert!(matches!(e, RunError::Simulation(_)), "{e}");
    assert!(!dir.exists());
}

/// Programs refuse what they would get wrong: the sweep benchmark a folder of other files (it
/// empties its folder before each round: it once deleted them), the walker options it does
/// not act on and a speed that is not a number.
#[test]
fn programs_refuse_folders_and_options_they_would_get_wrong() {
    let dir = scratch("foreign");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("thesis.txt"), "keep").unwrap();
    let out = Command::new(example("sweep"))
        .args(["--runs", "2", "--repeat", "1", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("is not a sweep's folder"), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(dir.join("thesis.txt")).unwrap(),
        "keep"
    );
    let _ = std::fs::remove_dir_all(&dir);

    let walk = example("hexapod_walk");
    for args in [&["--threads", "2"][..], &["--speed", "nan"]] {
        let out = Command::new(&walk).args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(args[0]), "{args:?}: {stderr}");
    }
}

/// The report's thinned trajectory keeps its rotation joints: their names were left out, so
/// that its orientations, chart numbers and charts read as empty and a re-centred run was
/// read in the identity chart.
#[test]
fn a_report_keeps_the_rotation_joints_of_its_trajectory() {
    let a = args(&["--t-end", "10", "--rtol", "1e-6"]);
    let report = a
        .run(mbs_models::tumble::TumbleBall::default(), 10.0)
        .unwrap();
    let tr = &report.trajectory;
    assert_eq!(tr.joint_names.len(), 1);
    let last = tr.len() - 1;
    assert_eq!(tr.orientation(last).len(), 4);
    assert!(
        tr.chart_numbers(last)[0] > 0,
        "the tumble re-centres its chart"
    );
    tr.check_fits(tr.q(0).len(), 1).unwrap();
}
