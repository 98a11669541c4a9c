//! What the rotation models conserve, computed from a trajectory without charts: a rotation
//! joint's orientation (its quaternion) and its angular velocity in its own axes (from its
//! angles and rates, whatever chart they are read in). Shared by `tests/rotations.rs` and
//! `examples/rotations.rs`.

use mbs::Trajectory;
use mbs::charts::body_rates;

/// Rotation matrix (rows) of a quaternion `[x, y, z, w]`.
pub fn rotation(q: &[f64]) -> [[f64; 3]; 3] {
    mbs::charts::matrix_of([q[0], q[1], q[2], q[3]])
}

/// R · v.
pub fn apply(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

/// Angular momentum, world axes, of the single body on rotation joint 0 (angles q[0..3];
/// or, for a twin without rotation joints, on the ZYX angles q[0..3]) about the joint's
/// centre: R · I · ω, with `inertia` the body's principal moments about that centre along the
/// joint's axes.
pub fn momentum(tr: &Trajectory, i: usize, inertia: [f64; 3]) -> [f64; 3] {
    let (q, qd) = (tr.q(i), tr.qd(i));
    let w = body_rates([q[0], q[1], q[2]], [qd[0], qd[1], qd[2]]);
    let r = if tr.joint_names.is_empty() {
        mbs::charts::array(&mbs::charts::zyx([q[0], q[1], q[2]]))
    } else {
        rotation(&tr.orientation(i)[..4])
    };
    apply(&r, [0, 1, 2].map(|k| inertia[k] * w[k]))
}

/// Largest relative drift over every output of the energy and of the angular momentum (the
/// whole vector, or one world component `Some(k)`, relative to its start value).
pub fn drifts(tr: &Trajectory, inertia: [f64; 3], component: Option<usize>) -> (f64, f64) {
    let e0 = tr.energy[0].total();
    let de = tr
        .energy
        .iter()
        .map(|e| ((e.total() - e0) / e0).abs())
        .fold(0.0, f64::max);
    let l0 = momentum(tr, 0, inertia);
    let scale = match component {
        Some(k) => l0[k].abs(),
        None => l0.iter().map(|x| x * x).sum::<f64>().sqrt(),
    };
    let dl = (0..tr.len())
        .map(|i| {
            let l = momentum(tr, i, inertia);
            match component {
                Some(k) => (l[k] - l0[k]).abs(),
                None => (0..3).map(|k| (l[k] - l0[k]).powi(2)).sum::<f64>().sqrt(),
            }
        })
        .fold(0.0, f64::max);
    (de, dl / scale)
}

/// The angle (rad) between world z (or −z with `down`) and the joint's body x axis at every
/// output: how close a top's axis or a pendulum's rod comes to the vertical.
pub fn from_vertical(tr: &Trajectory, down: bool) -> Vec<f64> {
    let s = if down { -1.0 } else { 1.0 };
    (0..tr.len())
        .map(|i| (s * apply(&rotation(tr.orientation(i)), [1.0, 0.0, 0.0])[2]).acos())
        .collect()
}

/// Largest |E(t) − E(0)| over every output, relative to the larger of the start's kinetic
/// energy and |E(0)| (a body thrown with E(0) near zero).
pub fn energy_drift(tr: &Trajectory) -> f64 {
    let e0 = tr.energy[0].total();
    let scale = tr.energy[0].kinetic.max(e0.abs());
    tr.energy
        .iter()
        .map(|e| (e.total() - e0).abs() / scale)
        .fold(0.0, f64::max)
}
