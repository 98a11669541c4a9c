//! `mbs::cli`: the per-system programs' command line, run as a program would run it.

use clap::Parser;
use mbs::ConstraintMethod;
use mbs::cli::{RunArgs, RunError, parse_constraint_method};

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
