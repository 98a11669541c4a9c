//! fastlink (`tests/reference/MODELS.md`, `models/src/fastlink.rs`): a two-loop linkage of
//! five light bodies thrown by a stiff spring, measured against a reference computed twice —
//! outside mbs (`tests/reference/fastlink.json`: SymPy in absolute coordinates, SciPy DOP853,
//! produced by `tests/reference/fastlink.py`) and by mbs itself at extreme tolerance with two
//! schemes (the tolerance sweep of every scheme × constraint method on it is in
//! `tests/tolerance_proportionality.rs`):
//!
//! ```text
//! cargo test --release --test fastlink -- --nocapture
//! ```

mod common;

use common::reference_state;
use mbs::work_precision::{Reference, Setting, mixed_error};
use mbs::{ConstraintMethod, Integrator, Model, Options, Scheme, Simulation};
use mbs_models::fastlink::{FastLink, closed_loop};

/// The sampled times of the reference: every millisecond to 30 ms.
fn times() -> Vec<f64> {
    (1..=30).map(|k| 1e-3 * k as f64).collect()
}

/// The states of `tests/reference/fastlink.json`, (q, qd) at `times()`.
fn external() -> Vec<Vec<f64>> {
    times()
        .iter()
        .map(|&t| {
            let (q, qd) = reference_state("fastlink", t);
            q.into_iter().chain(qd).collect()
        })
        .collect()
}

/// Largest mixed error (floor 0.01) of `states` against `reference` over the sampled times.
fn distance(states: &[Vec<f64>], reference: &[Vec<f64>]) -> f64 {
    states
        .iter()
        .zip(reference)
        .map(|(y, r)| mixed_error(y, r, 0.01))
        .fold(0.0, f64::max)
}

#[test]
fn assembles_both_loops_at_rest_on_the_documented_branch() {
    let sim = Simulation::new(
        FastLink::default(),
        Scheme::Dopri5,
        Options::adaptive(0.03, 1e-8),
    )
    .unwrap();
    let (q, qd) = (&sim.state().q, &sim.state().qd);
    let (b, c, e, s) = closed_loop(0.0);
    let (q_ext, _) = {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/reference/fastlink.json");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let v = |k: &str| -> Vec<f64> {
            json["initial"][k]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        };
        (v("q"), v("qd"))
    };
    println!("assembled q0 = {q:?}, qd0 = {qd:?}");
    for (i, (x, y)) in q.iter().zip([0.0, b, c, e, s]).enumerate() {
        assert!((x - y).abs() < 1e-12, "q[{i}] = {x}, closed form {y}");
        assert!(
            (x - q_ext[i]).abs() < 1e-12,
            "q[{i}] = {x}, reference {}",
            q_ext[i]
        );
    }
    assert!(qd.iter().all(|v| v.abs() < 1e-12), "at rest: {qd:?}");
}

/// The external reference obeys mbs's own energy function: T + V − τ a (the motor's work
/// taken out) stays at its start value at every sampled state, to 1e-9 of the largest kinetic
/// energy — the two derivations describe the same mechanism, masses, spring and torque.
#[test]
fn the_external_reference_keeps_mbs_s_energy_balance() {
    let model = FastLink::default();
    let tau = 0.05;
    let balance = |q: &[f64], qd: &[f64]| {
        let e = model.energy(0.0, q, qd);
        (e.kinetic + e.potential - tau * q[0], e.kinetic)
    };
    let sim = Simulation::new(
        FastLink::default(),
        Scheme::Dopri5,
        Options::adaptive(0.03, 1e-8),
    )
    .unwrap();
    let (e0, _) = balance(&sim.state().q, &sim.state().qd);
    let (mut worst, mut t_max) = (0.0f64, 0.0f64);
    let rows: Vec<(f64, f64)> = external()
        .iter()
        .map(|y| balance(&y[..5], &y[5..]))
        .collect();
    for &(e, t) in &rows {
        worst = worst.max((e - e0).abs());
        t_max = t_max.max(t);
    }
    println!(
        "energy balance of the external reference: E0 = {e0:.6} J, largest T = {t_max:.4} J, \
         max |E − E0| = {worst:.2e} J"
    );
    assert!(t_max > 1.0, "the mechanism moves: T up to {t_max} J");
    assert!(worst < 1e-9 * t_max, "|E − E0| = {worst:e} J");
}

/// mbs at rtol 1e-13 (Radau5 with projection; DOPRI5 with projection as its check) against
/// the external reference: the two independent means share at least 8.5 digits over (q, qd)
/// at the 30 sampled times (measured: Radau5 9.1, DOPRI5 9.8; SciPy's own Radau at 1e-12
/// is 9.7 digits from its DOP853, `check_radau_max_mixed_error` in the JSON file).
#[test]
fn mbs_at_extreme_tolerance_agrees_with_the_external_reference() {
    let model = FastLink::default();
    let options = Options {
        constraints: mbs::ConstraintOptions {
            method: ConstraintMethod::Projection,
            ..Default::default()
        },
        ..Options::default()
    };
    let own = Reference::compute(
        &model,
        times(),
        (Scheme::Radau5, Setting::Rtol(1e-13)),
        Some((Scheme::Dopri5, Setting::Rtol(1e-13))),
        &options,
    )
    .unwrap();
    let ext = external();
    let radau = distance(&own.states, &ext);
    let dopri = distance(own.check.as_ref().unwrap(), &ext);
    let between = distance(&own.states, own.check.as_ref().unwrap());
    println!(
        "max mixed error over (q, qd) at 30 times, floor 0.01: Radau5 vs SciPy {radau:.2e} ({:.1} digits), \
         DOPRI5 vs SciPy {dopri:.2e} ({:.1} digits), Radau5 vs DOPRI5 {between:.2e} ({:.1} digits)",
        -radau.log10(),
        -dopri.log10(),
        -between.log10()
    );
    for (name, e) in [("Radau5", radau), ("DOPRI5", dopri)] {
        assert!(
            -e.log10() >= 8.5,
            "{name} at rtol 1e-13 vs the external reference: {e:.2e}"
        );
    }
}
