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
