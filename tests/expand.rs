//! `mbs expand` prints exactly what `multibody!` emits: the macro stamps each type with a hash
//! of its code, and expanding this very file must give the same code and the same hash.

use mbs::Model;
use std::process::Command;

/// A knee whose slider follows a curve of the joint angle (user function and derivatives).
mod knee {
    pub fn bend(x: f64) -> f64 {
        0.1 * x.sin() + 0.02 * x * x
    }
    pub fn bend_d(x: f64) -> f64 {
        0.1 * x.cos() + 0.04 * x
    }
    pub fn bend_dd(x: f64) -> f64 {
        -0.1 * x.sin() + 0.04
    }
    pub fn bend_ddd(x: f64) -> f64 {
        -0.1 * x.cos()
    }
}

mbs::multibody! {
    /// A leg with a knee slider driven by a user function.
    pub model Leg {
        param l = 0.4; param m = 3.0; param g = 9.81;
        dof hip = 0.3; dof knee_angle = -0.2, qd = 0.5;
        input motor;
        extern fn bend = [knee::bend, knee::bend_d, knee::bend_dd, knee::bend_ddd];
        body thigh { mass = m; inertia = (m*l*l/12, 0.001, m*l*l/12); }
        body shank { mass = m / 2; inertia = (0.01, 0.002, 0.01, 0.0001, 0, 0); }
        point foot on shank at (0, -l/2, 0);
        TOG[thigh] = Trotz(hip) * Tdisp(0, -l/2, 0);
        TOG[shank] = TOG[thigh] * Tdisp(bend(knee_angle), -l/2, 0) * Trotz(knee_angle) * Tdisp(0, -l/2, 0);
        effect gravity { gravity(0, -g, 0); }
        effect actuation { torque(shank, relative_to = thigh, axis = z, motor); }
        scene Passive = [gravity]; scene Driven = [gravity, actuation];
        option tangents;
    }
}

fn this_file() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/tests/expand.rs").to_string()
}

#[test]
fn expansion_is_byte_identical_to_the_macro() {
    let src = std::fs::read_to_string(this_file()).unwrap();
    let mut blocks = mbs_symbolic::expand::multibody_blocks(&syn::parse_file(&src).unwrap());
    assert_eq!(blocks.len(), 1);
    let mut expansions = mbs_symbolic::expand::expand_models(blocks.remove(0)).unwrap();
    let mbs_symbolic::expand::Expansion::Ok { generated, .. } = expansions.remove(0) else {
        panic!("the model has errors")
    };
    assert_eq!(generated.hash, LegPassive::GENERATED_HASH);
    assert_eq!(generated.hash, LegDriven::GENERATED_HASH);

    // the command-line tool prints the same code, pretty-printed, then the op counts
    let out = Command::new(env!("CARGO_BIN_EXE_mbs"))
        .args(["expand", &this_file()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let pretty = prettyplease::unparse(&syn::parse_str(&generated.code).unwrap());
    assert!(stdout.starts_with(&pretty));
    assert!(stdout.contains(&format!("GENERATED_HASH: u64 = {}", generated.hash)));
    for f in [
        "dynamics (M, h)",
        "tangents (K, C)",
        "kinematics",
        "generation",
    ] {
        assert!(stdout.contains(f), "missing `{f}` in the report");
    }
    // --scene keeps the parameter struct and that scene's type only
    let out = Command::new(env!("CARGO_BIN_EXE_mbs"))
        .args(["expand", &this_file(), "--scene", "Driven"])
        .output()
        .unwrap();
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.contains("pub struct LegDriven") && stdout.contains("pub struct LegParams"));
    assert!(!stdout.contains("pub struct LegPassive"));
}

#[test]
fn user_functions_and_inputs_reach_the_generated_code() {
    let model = LegDriven::default();
    let (q, qd, qdd) = ([0.3, -0.2], [0.4, 0.5], [0.0, 0.0]);
    let mut m = [0.0; 4];
    let mut h0 = [0.0; 2];
    let mut h1 = [0.0; 2];
    model.dynamics(0.0, &q, &qd, &[0.0], &mut m, &mut h0);
    model.dynamics(0.0, &q, &qd, &[2.0], &mut m, &mut h1);
    // the motor torque acts on the knee only (its reaction on the thigh cancels on the hip)
    assert!((h1[1] - h0[1] - 2.0).abs() < 1e-12, "{h0:?} {h1:?}");
    assert!((h1[0] - h0[0]).abs() < 1e-12, "{h0:?} {h1:?}");
    // the input matrix ∂h/∂u says the same: the knee only
    let mut b = [f64::NAN; 2];
    model.input_matrix(0.0, &q, &qd, &[2.0], &mut b);
    assert_eq!(b, [0.0, 1.0]);
    let mut tau = [0.0; 2];
    model.inverse_dynamics(0.0, &q, &qd, &qdd, &[2.0], &mut tau);
    assert!((tau[0] + h1[0]).abs() < 1e-12 && (tau[1] + h1[1]).abs() < 1e-12);
    let mut k = [0.0; 4];
    let mut c = [0.0; 4];
    model
        .tangents(0.0, &q, &qd, &qdd, &[2.0], &mut k, &mut c)
        .unwrap();
    assert!(k.iter().all(|x| x.is_finite()) && c.iter().any(|&x| x != 0.0));
    assert_eq!(model.info().dof_label(1), "q[1] (knee_angle)");
    let mut q0 = [0.0; 2];
    let mut qd0 = [0.0; 2];
    model.initial_state(&mut q0, &mut qd0);
    assert_eq!((q0, qd0), ([0.3, -0.2], [0.0, 0.5]));
}

/// Writes `files` (path relative to a fresh folder, text) and returns the folder.
fn fixture(name: &str, files: &[(&str, &str)]) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    for (path, text) in files {
        let p = dir.join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    dir
}

fn run(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mbs"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

const GOOD: &str = "dof q[0] = 0.1; body bar { mass = 1.0; inertia_z = 0.1; } TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);";

/// `mod name;` (name.rs next to a crate root, in a folder of its name below a plain file),
/// `name/mod.rs` and `#[path]` (whose file finds its modules next to it) are followed; every model is expanded, an error in one is
/// reported with file:line:col and the others still come; the exit status says there was one.
#[test]
fn expand_follows_modules_and_reports_every_error_with_its_place() {
    let dir = fixture(
        "expand_modules",
        &[
            (
                "main.rs",
                "mod legs;\nmod arms;\n#[path = \"extra/base.rs\"]\nmod base;\nfn main() {}\n",
            ),
            (
                "legs.rs",
                &format!(
                    "mod foot;\nmbs::multibody! {{\n    model Leg {{ {GOOD} }}\n    model Bad {{\n        dof q[0] = 0.1;\n        body bar {{ mass = 1.0; }}\n        TOG[bar] = TOG[bra] * Trotz(q[0]);\n    }}\n}}\n"
                ),
            ),
            (
                "legs/foot.rs",
                &format!("mbs::multibody! {{ model Foot {{ {GOOD} }} }}\n"),
            ),
            (
                "arms/mod.rs",
                &format!(
                    "mbs::multibody! {{ model Arm {{ {GOOD} scene Up = []; scene Down = []; }} }}\n"
                ),
            ),
            (
                "extra/base.rs",
                &format!("mod wheel;\nmbs::multibody! {{ model Base {{ {GOOD} }} }}\n"),
            ),
            (
                "extra/wheel.rs",
                &format!("mbs::multibody! {{ model Wheel {{ {GOOD} }} }}\n"),
            ),
        ],
    );
    let main = dir.join("main.rs");
    let (ok, stdout, stderr) = run(&["expand", main.to_str().unwrap(), "--counts-only"]);
    assert!(!ok, "errors make the exit status non-zero");
    for m in [
        "model Leg:",
        "model Foot:",
        "model Arm:",
        "model Base:",
        "model Wheel:",
    ] {
        assert!(stdout.contains(m), "missing {m} in\n{stdout}");
    }
    let legs = dir.join("legs.rs");
    assert!(
        stderr.contains(&format!(
            "error: {}:7:24: model `Bad`: unknown body `bra`; did you mean `bar`?",
            legs.display()
        )),
        "{stderr}"
    );
    assert_eq!(stderr.lines().count(), 1, "{stderr}");

    // a module whose file is missing is reported where it is declared
    let dir = fixture(
        "expand_missing",
        &[(
            "main.rs",
            &format!("mbs::multibody! {{ model Alone {{ {GOOD} }} }}\nmod gone;\n"),
        )],
    );
    let (ok, stdout, stderr) = run(&["expand", dir.join("main.rs").to_str().unwrap()]);
    assert!(!ok && stdout.contains("struct Alone {"));
    assert!(
        stderr.starts_with(&format!(
            "error: {}:2:5: file not found for module `gone`",
            dir.join("main.rs").display()
        )),
        "{stderr}"
    );

    // a module of a crate's `src` given alone finds its modules in a folder of its name
    let dir = fixture(
        "expand_module_alone",
        &[
            (
                "src/legs.rs",
                &format!("mod foot;\nmbs::multibody! {{ model Leg {{ {GOOD} }} }}\n"),
            ),
            (
                "src/legs/foot.rs",
                &format!("mbs::multibody! {{ model Foot {{ {GOOD} }} }}\n"),
            ),
        ],
    );
    let (ok, stdout, stderr) = run(&[
        "expand",
        dir.join("src/legs.rs").to_str().unwrap(),
        "--counts-only",
    ]);
    assert!(ok && stdout.contains("model Foot:"), "{stderr}");

    // --scene: a scene of one of the models is shown alone; an unknown one is an error that
    // lists the scenes
    let (ok, stdout, _) = run(&[
        "expand",
        main.to_str().unwrap(),
        "--model",
        "Arm",
        "--scene",
        "Up",
    ]);
    assert!(ok && stdout.contains("struct ArmUp {") && !stdout.contains("struct ArmDown {"));
    let (ok, stdout, stderr) = run(&[
        "expand",
        main.to_str().unwrap(),
        "--model",
        "Arm",
        "--scene",
        "Sideways",
    ]);
    assert!(!ok && stdout.is_empty());
    assert_eq!(
        stderr.trim(),
        "error: no scene `Sideways` in model `Arm`: its scenes are `Up` and `Down`"
    );
    let (ok, _, stderr) = run(&["expand", &this_file(), "--scene", "Drivn"]);
    assert!(!ok);
    assert_eq!(
        stderr.trim(),
        "error: no scene `Drivn` in model `Leg`: its scenes are `Passive` and `Driven`"
    );
}

/// A module file that is not a regular file (here a FIFO named by `#[path]`, which nothing
/// writes to: reading it would block for ever) is an error where it is named, not a hang.
#[cfg(unix)]
#[test]
fn expand_refuses_a_module_that_is_not_a_regular_file() {
    let dir = fixture(
        "expand_fifo",
        &[(
            "main.rs",
            &format!(
                "mbs::multibody! {{ model Alone {{ {GOOD} }} }}\n#[path = \"pipe.rs\"]\nmod pipe;\n"
            ),
        )],
    );
    let made = Command::new("mkfifo")
        .arg(dir.join("pipe.rs"))
        .status()
        .unwrap();
    assert!(made.success());
    let mut child = Command::new(env!("CARGO_BIN_EXE_mbs"))
        .args([
            "expand",
            dir.join("main.rs").to_str().unwrap(),
            "--counts-only",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > std::time::Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("`mbs expand` still reads the FIFO after 60 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    let (stdout, stderr) = (
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    );
    assert!(
        !out.status.success() && stdout.contains("model Alone:"),
        "{stderr}"
    );
    assert!(
        stderr.starts_with(&format!("error: {}:3:5", dir.join("main.rs").display()))
            && stderr.contains("not a regular file"),
        "{stderr}"
    );
}

/// The examples keep their models in `mbs-models`: `mbs expand examples/hexapod.rs` finds the
/// model through `use mbs_models::hexapod`.
#[test]
fn expand_finds_the_models_an_example_uses() {
    let example = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/hexapod.rs");
    let (ok, stdout, stderr) = run(&["expand", example, "--counts-only"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("// model Hexapod:") && stdout.contains("HexapodStanding"));
}
