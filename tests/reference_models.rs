//! The canonical models of `tests/reference/MODELS.md`, written with `multibody!`, against the
//! reference data in `tests/reference/*.json`: M and h at the test state to 1e-14 relative, the
//! identities tying `inverse_dynamics` and `static_forces` to M and h, and the initial energy.
//!
//! seed2dof, dpend and arm3d_6 are the models of the examples (`models/`, crate
//! `mbs-models`), so the examples run exactly what is checked here.

use mbs::Model;
use serde_json::Value;

#[path = "common/quoted.rs"]
mod quoted;

use mbs_models::arm3d_6;
use mbs_models::dpend;
use mbs_models::seed2dof;

mbs::multibody! {
    /// chain4: four uniform bars of 0.5 m and 1 kg hinged end to end, relative angles.
    pub model Chain4 {
        param l = 0.5; param m = 1.0; param g = 9.81;
        let i_bar = m * l * l / 12;
        dof q[0] = 0.3; dof q[1] = 0.3; dof q[2] = 0.3; dof q[3] = 0.3;
        body bar0 { mass = m; inertia = (i_bar, 0, i_bar); }
        body bar1 { mass = m; inertia = (i_bar, 0, i_bar); }
        body bar2 { mass = m; inertia = (i_bar, 0, i_bar); }
        body bar3 { mass = m; inertia = (i_bar, 0, i_bar); }
        TOG[bar0] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
        TOG[bar1] = TOG[bar0] * Tdisp(0, -l / 2, 0) * Trotz(q[1]) * Tdisp(0, -l / 2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l / 2, 0) * Trotz(q[2]) * Tdisp(0, -l / 2, 0);
        TOG[bar3] = TOG[bar2] * Tdisp(0, -l / 2, 0) * Trotz(q[3]) * Tdisp(0, -l / 2, 0);
        gravity(0, -g, 0);
    }
}

/// What a reference file says about one model.
struct Reference {
    q: Vec<f64>,
    qd: Vec<f64>,
    /// M, row-major
    m: Vec<f64>,
    /// F = our h
    f: Vec<f64>,
    q0: Vec<f64>,
    qd0: Vec<f64>,
    kinetic0: f64,
    potential0: f64,
    energy_scale: f64,
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("a JSON array")
        .iter()
        .flat_map(|x| match x {
            Value::Array(_) => numbers(x),
            _ => vec![x.as_f64().expect("a number")],
        })
        .collect()
}

fn reference(model: &str) -> Reference {
    let path = format!(
        "{}/tests/reference/{model}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let json: Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"));
    let ts = &json["test_state"];
    let energy = &json["energy"];
    Reference {
        q: numbers(&ts["q"]),
        qd: numbers(&ts["qd"]),
        m: numbers(&ts["M"]),
        f: numbers(&ts["F"]),
        q0: numbers(&json["q0"]),
        qd0: numbers(&json["qd0"]),
        kinetic0: energy["T0"].as_f64().unwrap(),
        potential0: energy["V0"].as_f64().unwrap(),
        energy_scale: energy["scale"].as_f64().unwrap(),
    }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, x| a.max(x.abs()))
}

/// max |a − b| / max |b|
fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let d = a
        .iter()
        .zip(b)
        .fold(0.0f64, |e, (x, y)| e.max((x - y).abs()));
    d / max_abs(b)
}

/// y = M x, M column-major n × n
fn mat_vec(m: &[f64], x: &[f64]) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|i| (0..n).map(|j| m[i + n * j] * x[j]).sum())
        .collect()
}

/// Relative tolerance of every comparison (worst measured: 1.4e-15, M of dpend).
const TOL: f64 = 1e-14;

/// Checks `model` against `tests/reference/{name}.json`; returns the relative errors of M and h.
fn check<Mo: Model>(model: &Mo, name: &str) -> (f64, f64) {
    let r = reference(name);
    let n = Mo::NQ;
    assert_eq!(r.q.len(), n, "{name}: number of coordinates");

    // Initial state as declared in the DSL.
    let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q0, &mut qd0);
    assert!(
        rel_err(&q0, &r.q0) < TOL && qd0 == r.qd0,
        "{name}: initial state {q0:?}"
    );

    // M and h at the test state. Ours is column-major, the reference's row-major: read ours
    // row by row.
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    model.dynamics(0.0, &r.q, &r.qd, &[], &mut m, &mut h);
    let m_rows: Vec<f64> = (0..n * n).map(|k| m[(k / n) + n * (k % n)]).collect();
    let (err_m, err_h) = (rel_err(&m_rows, &r.m), rel_err(&h, &r.f));
    assert!(
        err_m < TOL,
        "{name}: M rel. error {err_m:e}\nours {m_rows:?}\nref  {:?}",
        r.m
    );
    assert!(
        err_h < TOL,
        "{name}: h rel. error {err_h:e}\nours {h:?}\nref  {:?}",
        r.f
    );

    // mass_matrix alone gives the same M.
    let mut m_only = vec![0.0; n * n];
    model.mass_matrix(0.0, &r.q, &mut m_only);
    assert!(
        rel_err(&m_only, &m) < TOL,
        "{name}: mass_matrix ≠ dynamics' M"
    );

    // inverse_dynamics(qdd) = M qdd − h, for an arbitrary qdd.
    let qdd: Vec<f64> = (0..n).map(|i| (0.7 * i as f64 - 1.1).sin()).collect();
    let mut tau = vec![0.0; n];
    model.inverse_dynamics(0.0, &r.q, &r.qd, &qdd, &[], &mut tau);
    let expected: Vec<f64> = mat_vec(&m, &qdd)
        .iter()
        .zip(&h)
        .map(|(a, b)| a - b)
        .collect();
    let scale = max_abs(&h).max(max_abs(&mat_vec(&m, &qdd)));
    let err_tau = tau
        .iter()
        .zip(&expected)
        .fold(0.0f64, |e, (a, b)| e.max((a - b).abs()));
    assert!(
        err_tau < TOL * scale,
        "{name}: τ {tau:?} ≠ M qdd − h {expected:?}"
    );

    // static_forces = h at qd = 0.
    let zero = vec![0.0; n];
    let (mut h_static, mut h_rest) = (vec![0.0; n], vec![0.0; n]);
    model.static_forces(0.0, &r.q, &[], &mut h_static);
    model.dynamics(0.0, &r.q, &zero, &[], &mut m, &mut h_rest);
    let err_static = h_static
        .iter()
        .zip(&h_rest)
        .fold(0.0f64, |e, (a, b)| e.max((a - b).abs()));
    assert!(
        err_static <= TOL * max_abs(&h_rest),
        "{name}: static_forces {h_static:?} ≠ h(qd = 0) {h_rest:?}"
    );

    // Energy at the initial state. The reference measures V from the first joint, we from the
    // world origin: the same point for every model here.
    let e = model.energy(0.0, &q0, &qd0);
    let tol_e = TOL * r.energy_scale;
    assert!(
        (e.kinetic - r.kinetic0).abs() < tol_e,
        "{name}: T0 {} vs {}",
        e.kinetic,
        r.kinetic0
    );
    assert!(
        (e.potential - r.potential0).abs() < tol_e,
        "{name}: V0 {} vs {}",
        e.potential,
        r.potential0
    );
    println!(
        "{name}: M rel. error {err_m:.1e}, h rel. error {err_h:.1e}, τ {:.1e}, static {:.1e}, T0 {:.1e}, V0 {:.1e}, q0 {:.1e}, mass_matrix {:.1e}",
        err_tau / scale,
        err_static / max_abs(&h_rest),
        (e.kinetic - r.kinetic0).abs() / r.energy_scale,
        (e.potential - r.potential0).abs() / r.energy_scale,
        rel_err(&q0, &r.q0),
        rel_err(&m_only, &m)
    );
    (err_m, err_h)
}

#[test]
fn seed2dof_matches_reference() {
    check(&seed2dof::Seed2dof::default(), "seed2dof");
}

#[test]
fn dpend_matches_reference() {
    check(&dpend::DoublePendulum::default(), "dpend");
}

#[test]
fn chain4_matches_reference() {
    check(&Chain4::default(), "chain4");
}

#[test]
fn arm3d_6_matches_reference() {
    check(&arm3d_6::Arm3d6::default(), "arm3d_6");
}

/// The worst of the four models' M and h, as the README quotes it (the checks again: a few
/// microseconds).
#[test]
fn the_worst_error_is_the_one_quoted() {
    let worst = [
        check(&seed2dof::Seed2dof::default(), "seed2dof"),
        check(&dpend::DoublePendulum::default(), "dpend"),
        check(&Chain4::default(), "chain4"),
        check(&arm3d_6::Arm3d6::default(), "arm3d_6"),
    ]
    .into_iter()
    .fold(0.0f64, |w, (m, h)| w.max(m).max(h));
    quoted::says(
        "README.md",
        &[format!(
            "M and h match SymPy/Pinocchio/MuJoCo reference data to {TOL:.0e} relative to their \
             largest entry (asserted in `tests/reference_models.rs`; worst measured {worst:.1e})"
        )],
    );
}
