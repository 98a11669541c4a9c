//! The hexapod of `tests/reference/MODELS.md` (the model of `examples/hexapod.rs`): no reference
//! data, so physical checks at the test state — M symmetric positive definite, h finite, the
//! base's translational block carrying the total mass, gravity's resultant on the base. These
//! are on the contact-free scene `Free` (the type `Hexapod`), whose operation counts stay
//! those of the README; the scene `Standing` (contact, PD joints) is in `hexapod_standing.rs`.

use mbs::Model;

use mbs_models::hexapod;

use hexapod::Hexapod;

#[path = "common/quoted.rs"]
mod quoted;
use quoted::thousands;

/// The MODELS.md test state: q_i = 0.5 sin(1.3 i + 0.4), qd_i = 0.7 cos(0.9 i + 0.2).
fn test_state(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n).map(|i| 0.5 * (1.3 * i as f64 + 0.4).sin()).collect();
    let qd = (0..n).map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos()).collect();
    (q, qd)
}

/// Cholesky factor of a symmetric matrix (column-major, n × n); `None` if not positive definite.
fn cholesky(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut l = vec![0.0f64; n * n];
    for j in 0..n {
        let d = a[j + n * j] - (0..j).map(|k| l[j + n * k].powi(2)).sum::<f64>();
        if d <= 0.0 {
            return None;
        }
        l[j + n * j] = d.sqrt();
        for i in j + 1..n {
            let s = a[i + n * j] - (0..j).map(|k| l[i + n * k] * l[j + n * k]).sum::<f64>();
            l[i + n * j] = s / l[j + n * j];
        }
    }
    Some(l)
}

const TOTAL_MASS: f64 = 20.0 + 6.0 * (0.5 + 0.8 + 0.6 + 0.2 + 0.1 + 3.0 * 0.05);

#[test]
fn hexapod_sizes_and_names() {
    let model = Hexapod::default();
    let info = model.info();
    assert_eq!(Hexapod::NQ, 24);
    assert_eq!(info.is_body.iter().filter(|&&b| b).count(), 49);
    // the six feet, then the base's eight corners
    assert_eq!(Hexapod::NPOINTS, 14);
    assert_eq!(info.points[5], "foot[5]");
    assert_eq!(info.points[6], "corner[0]");
    assert_eq!(
        &info.dofs[..9],
        ["x", "y", "z", "psi", "theta", "phi", "a[0]", "b[0]", "c[0]"]
    );
    assert_eq!(info.dofs[23], "c[5]");
}

#[test]
fn hexapod_mass_matrix_and_forces_at_the_test_state() {
    let model = Hexapod::default();
    let n = Hexapod::NQ;
    let (q, qd) = test_state(n);
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    model.dynamics(0.0, &q, &qd, &[], &mut m, &mut h);

    let scale = m.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for i in 0..n {
        for j in 0..i {
            let d = (m[i + n * j] - m[j + n * i]).abs();
            assert!(d <= 1e-13 * scale, "M not symmetric at ({i}, {j}): {d:e}");
        }
    }
    assert!(cholesky(&m, n).is_some(), "M is not positive definite");
    assert!(h.iter().all(|x| x.is_finite()), "h = {h:?}");

    // The base translates in world axes: its translational block is m_total · I.
    for i in 0..3 {
        for j in 0..3 {
            let expected = if i == j { TOTAL_MASS } else { 0.0 };
            assert!(
                (m[i + n * j] - expected).abs() < 1e-12 * TOTAL_MASS,
                "M[{i}][{j}] = {}",
                m[i + n * j]
            );
        }
    }

    // inverse_dynamics(qdd) = M qdd − h.
    let qdd: Vec<f64> = (0..n).map(|i| (0.7 * i as f64 - 1.1).sin()).collect();
    let mut tau = vec![0.0; n];
    model.inverse_dynamics(0.0, &q, &qd, &qdd, &[], &mut tau);
    for i in 0..n {
        let expected = (0..n).map(|j| m[i + n * j] * qdd[j]).sum::<f64>() - h[i];
        assert!(
            (tau[i] - expected).abs() < 1e-12 * scale * 10.0,
            "τ[{i}] = {} ≠ {expected}",
            tau[i]
        );
    }

    // At rest, the only generalised force on the base's z is gravity's resultant.
    let mut h0 = vec![0.0; n];
    model.static_forces(0.0, &q, &[], &mut h0);
    let g = model.params().g;
    assert!(
        (h0[2] + TOTAL_MASS * g).abs() < 1e-12 * TOTAL_MASS * g,
        "h0[z] = {}",
        h0[2]
    );
    assert!(h0[0].abs() < 1e-12 && h0[1].abs() < 1e-12, "h0 = {h0:?}");
}

#[test]
fn hexapod_feet_hang_above_the_ground_at_the_start() {
    let model = Hexapod::default();
    let n = Hexapod::NQ;
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    let mut kin = mbs::Kinematics::new::<Hexapod>();
    model.kinematics(0.0, &q, &qd, &mut kin);
    for (k, foot) in kin.points[..6].iter().enumerate() {
        let z = foot.position[2];
        assert!((0.0..0.02).contains(&z), "foot {k} at height {z}");
    }
}

/// The contact-free scene carries no code of the `contact` and `pd` effects: its counts are
/// the README's (M+h 5,887 flops, 42 sin/cos, with the base on a free joint whose
/// translation is in world axes), as before the effects existed.
#[test]
fn hexapod_free_scene_keeps_the_contact_free_op_counts() {
    let info = Hexapod::default().info();
    assert_eq!((info.name, info.scene), ("HexapodFree", "Free"));
    let count = |f: &str| {
        info.ops
            .iter()
            .find(|(name, _)| name.starts_with(f))
            .map(|(_, ops)| *ops)
            .unwrap_or_else(|| panic!("no {f} in {:?}", info.ops))
    };
    let dynamics = count("dynamics");
    println!("Hexapod (Free) M+h: {dynamics}");
    assert_eq!((dynamics.flops(), dynamics.funcs), (5887, 42));
    assert_eq!(count("static_forces").flops(), 1020);
    assert_eq!(count("power").flops(), 0);
    let flops = thousands(dynamics.flops());
    quoted::says(
        "README.md",
        &[
            format!(
                "| M+h operations, hexapod (24 dof, 49 bodies) | {flops} flops, {} sin/cos, its base on `Tfree`",
                dynamics.funcs
            ),
            format!("hexapod {flops} on `Tfree` against"),
        ],
    );
    quoted::says(
        "docs/rotations.md",
        &[
            format!("M + h {flops} flops on `Tfree` against"),
            format!("the model the README calls the hexapod (scene `Free`, {flops})"),
        ],
    );
}
