//! Rotation joints (`Tball`, `Tfree`) and their charts: a joint's rotation is
//! `R = C · Rz(a) · Ry(b) · Rx(c)`, with ZYX angles (a, b, c) among the coordinates and the
//! chart `C` a rotation the model holds ([`Model::chart`]). The angles are singular where
//! cos b = 0; re-centring moves the chart to the joint's current rotation (C ← C·R_zyx(a, b, c))
//! and the angles to zero, mapping the rates and accelerations exactly through the joint's
//! angular velocity in its own axes, so the motion does not change. A free joint's
//! translation comes before the chart and is left as it is.
//!
//! Here: the ZYX rotation and its angular-velocity Jacobian, the quaternion of a joint, and
//! [`Recentring`], the map of one re-centring applied to a state, to any acceleration and to
//! the derivatives of a state by a parameter (`map_sensitivity`).

use crate::model::{Model, RotationJoint};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion};

/// `Rz(a) · Ry(b) · Rx(c)` (nalgebra's roll c, pitch b, yaw a).
pub fn zyx(angles: [f64; 3]) -> Matrix3<f64> {
    Rotation3::from_euler_angles(angles[2], angles[1], angles[0]).into_inner()
}

/// A matrix as rows, the layout of [`Model::chart`].
pub fn array(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|r| [m[(r, 0)], m[(r, 1)], m[(r, 2)]])
}

/// The rotation matrix (rows) of a unit quaternion `[x, y, z, w]` (the order of
/// [`crate::Pose::quaternion`] and of the trajectory's orientations); a quaternion is
/// normalised first, and one of zero norm gives NaN.
pub fn matrix_of(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [x, y, z, w] = q;
    let u = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
    array(u.to_rotation_matrix().matrix())
}

/// The ZYX angles `[a, b, c]` of a rotation given as a unit quaternion `[x, y, z, w]` (a
/// trajectory's [`orientation`](crate::Trajectory::orientation)), `R = Rz(a) · Ry(b) · Rx(c)`
/// with b in [−π/2, π/2] and a, c in (−π, π]: the yaw, pitch and roll of the rotation
/// whatever chart its coordinates were read in (singular where cos b = 0, where a and c
/// share one angle); NaN for a quaternion of zero norm.
pub fn zyx_angles_of(q: [f64; 4]) -> [f64; 3] {
    let [x, y, z, w] = q;
    let u = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
    let (roll, pitch, yaw) = u.euler_angles();
    [yaw, pitch, roll]
}

/// The angular velocity of the joint in its own (child) axes, `J(b, c) · (ȧ, ḃ, ċ)`.
pub fn body_rates(angles: [f64; 3], rates: [f64; 3]) -> [f64; 3] {
    let (sb, cb) = angles[1].sin_cos();
    let (sc, cc) = angles[2].sin_cos();
    let [ad, bd, cd] = rates;
    [
        cd - ad * sb,
        bd * cc + ad * cb * sc,
        -bd * sc + ad * cb * cc,
    ]
}

/// `J̇ · q̇`: the angular acceleration in the joint's axes when the angles' accelerations are
/// zero.
fn body_bias(angles: [f64; 3], rates: [f64; 3]) -> [f64; 3] {
    let (sb, cb) = angles[1].sin_cos();
    let (sc, cc) = angles[2].sin_cos();
    let [ad, bd, cd] = rates;
    [
        -ad * bd * cb,
        -bd * cd * sc + ad * (-bd * sb * sc + cd * cb * cc),
        -bd * cd * cc + ad * (-bd * sb * cc - cd * cb * sc),
    ]
}

/// `(∂J/∂q · s) · v`: how the angular velocity J(b, c)·v changes when the angles move by `s`
/// (`body_bias` is its value at s = v = q̇).
fn body_bias_along(angles: [f64; 3], s: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    let (sb, cb) = angles[1].sin_cos();
    let (sc, cc) = angles[2].sin_cos();
    let [va, vb, _] = v;
    let [_, s_b, s_c] = s;
    [
        -s_b * cb * va,
        -s_b * sb * sc * va + s_c * (cb * cc * va - sc * vb),
        -s_b * sb * cc * va - s_c * (cb * sc * va + cc * vb),
    ]
}

/// The rates at zero angles that give the angular velocity `w` (joint axes): at (0, 0, 0),
/// ω = (ċ, ḃ, ȧ).
fn rates_at_zero(w: [f64; 3]) -> [f64; 3] {
    [w[2], w[1], w[0]]
}

/// The joint's angles of coordinates `q`.
pub fn angles_of(joint: &RotationJoint, q: &[f64]) -> [f64; 3] {
    joint.angles.map(|k| q[k])
}

/// How far the joint's chart is from gimbal lock: |cos b|, 1 at its centre, 0 at the lock.
pub fn chart_quality(joint: &RotationJoint, q: &[f64]) -> f64 {
    q[joint.angles[1]].cos().abs()
}

/// The rotation of the joint relative to the frame before it, `C · Rz(a) · Ry(b) · Rx(c)`,
/// as a unit quaternion (NaN when an angle or the chart is not finite).
pub fn joint_rotation(
    chart: &[[f64; 3]; 3],
    joint: &RotationJoint,
    q: &[f64],
) -> UnitQuaternion<f64> {
    let c = Matrix3::from_fn(|r, k| chart[r][k]);
    let r = c * zyx(angles_of(joint, q));
    rotation_of(&r)
}

/// The rotation nearest `m` as a unit quaternion (nalgebra's iterative extraction), or NaN
/// when `m` is not finite: with a NaN the extraction never meets its tolerance and would
/// iterate without end.
pub(crate) fn rotation_of(m: &Matrix3<f64>) -> UnitQuaternion<f64> {
    if m.iter().all(|x| x.is_finite()) {
        UnitQuaternion::from_matrix(m)
    } else {
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(
            f64::NAN,
            f64::NAN,
            f64::NAN,
            f64::NAN,
        ))
    }
}

/// The joint's rotation as `[x, y, z, w]` (the order of [`crate::Pose::quaternion`]), of the
/// sign nearest `prev` (continuous from one output to the next; w ≥ 0 without `prev`).
pub fn quaternion_near(u: &UnitQuaternion<f64>, prev: Option<[f64; 4]>) -> [f64; 4] {
    let v = u.as_ref().coords; // (i, j, k, w)
    let mut x = [v[0], v[1], v[2], v[3]];
    let flip = match prev {
        Some(p) => p.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>() < 0.0,
        None => x[3] < 0.0,
    };
    if flip {
        x = x.map(|c| -c);
    }
    x
}

/// One re-centring of joint `joint`: what it changed, to map states and accelerations of the
/// old chart into the new one.
#[derive(Clone, Copy, Debug)]
pub struct Recentring {
    pub joint: usize,
    /// the coordinates of the angles
    angles: [usize; 3],
    /// angles and rates before (old chart)
    q: [f64; 3],
    qd: [f64; 3],
    /// rates after (new chart, angles zero)
    qd_new: [f64; 3],
    /// the new chart
    pub chart: [[f64; 3]; 3],
}

impl Recentring {
    /// Re-centres joint `index` (`joint` its description) at the state (q, qd): the new
    /// chart, and the state's angles and rates in it (written into `q` and `qd`).
    pub fn at(
        index: usize,
        joint: &RotationJoint,
        chart: &[[f64; 3]; 3],
        q: &mut [f64],
        qd: &mut [f64],
    ) -> Recentring {
        let angles = angles_of(joint, q);
        let rates = joint.angles.map(|k| qd[k]);
        let new = joint_rotation(chart, joint, q);
        let qd_new = rates_at_zero(body_rates(angles, rates));
        for (i, &k) in joint.angles.iter().enumerate() {
            q[k] = 0.0;
            qd[k] = qd_new[i];
        }
        Recentring {
            joint: index,
            angles: joint.angles,
            q: angles,
            qd: rates,
            qd_new,
            chart: array(new.to_rotation_matrix().matrix()),
        }
    }

    /// Maps an acceleration of the old chart at the re-centred state (the state's own q̈, or
    /// a scheme's acceleration-like variable) into the new chart: the same angular
    /// acceleration of the joint, ω̇ = J q̈ + J̇ q̇, read at zero angles.
    pub fn map_acceleration(&self, x: &mut [f64]) {
        let acc = self.angles.map(|k| x[k]);
        let j = body_rates(self.q, acc);
        let b = body_bias(self.q, self.qd);
        let wd = [j[0] + b[0], j[1] + b[1], j[2] + b[2]];
        // at zero angles J̇'q̇' = (−ȧ'ḃ', ȧ'ċ', −ḃ'ċ'), J' the permutation (c, b, a)
        let [ad, bd, cd] = self.qd_new;
        let new = [wd[2] + bd * cd, wd[1] - ad * cd, wd[0] + ad * bd];
        for (i, &k) in self.angles.iter().enumerate() {
            x[k] = new[i];
        }
    }
}

impl Recentring {
    /// Maps the derivatives of the joint's angles and rates by a parameter, `s` = ∂q/∂p and
    /// `sd` = ∂q̇/∂p (whole coordinate vectors: the joint's entries are read and written),
    /// from the old chart into the new one, the new chart held fixed: the same perturbation
    /// of the joint's orientation, δθ = J s (so s maps as the rates do), and of its angular
    /// velocity, δω = J ṡ + (∂J/∂q·s) q̇, read at zero angles.
    pub fn map_sensitivity(&self, s: &mut [f64], sd: &mut [f64]) {
        let (s_old, sd_old) = (self.angles.map(|k| s[k]), self.angles.map(|k| sd[k]));
        let s_new = rates_at_zero(body_rates(self.q, s_old));
        let j = body_rates(self.q, sd_old);
        let b = body_bias_along(self.q, s_old, self.qd);
        let b_new = body_bias_along([0.0; 3], s_new, self.qd_new);
        let sd_new = rates_at_zero([
            j[0] + b[0] - b_new[0],
            j[1] + b[1] - b_new[1],
            j[2] + b[2] - b_new[2],
        ]);
        for (i, &k) in self.angles.iter().enumerate() {
            s[k] = s_new[i];
            sd[k] = sd_new[i];
        }
    }
}

/// Re-centres every rotation joint of `model` at (q, qd) (its angles become zero, its
/// chart its orientation: the best-conditioned chart, whose angles are the small rotation
/// in the joint's own axes, δ(a, b, c) ≈ (δθz, δθy, δθx)), except the joints with a
/// coordinate in `keep` (coordinates held at their value); maps q and qd in place.
pub fn recentre<M: Model>(model: &mut M, q: &mut [f64], qd: &mut [f64], keep: &[usize]) {
    let joints = model.info().rotation_joints;
    for (j, joint) in joints.iter().enumerate() {
        if joint.angles.iter().any(|k| keep.contains(k)) {
            continue;
        }
        let r = Recentring::at(j, joint, &model.chart(j), q, qd);
        model.set_chart(j, r.chart);
    }
}

/// Rewrites the angles of every rotation joint in `q`, read in the charts of `from`, in the
/// charts of `to`: the same orientations (a `Tfree`'s translation, in front of its chart, is
/// unchanged), b in [−π/2, π/2].
pub fn reread_angles<M: Model>(from: &M, to: &M, q: &mut [f64]) {
    for (j, joint) in from.info().rotation_joints.iter().enumerate() {
        let r = joint_rotation(&from.chart(j), joint, q).to_rotation_matrix();
        let c = to.chart(j);
        let c = Matrix3::from_fn(|a, b| c[a][b]);
        let local = rotation_of(&(c.transpose() * r.matrix()));
        let angles = zyx_angles_of(quaternion_near(&local, None));
        for (i, &k) in joint.angles.iter().enumerate() {
            q[k] = angles[i];
        }
    }
}

/// Reads a rotation joint's angles and rates at (q, qd), measured in `chart`, in the identity
/// chart, the one a model starts with and initial states are given in: the same orientation
/// (angles a and c in (−π, π], b in [−π/2, π/2]) and the same angular velocity. The rates are
/// singular where the identity chart is, at b = ±π/2. A joint already in the identity chart
/// is left as it is (its angles continuous, not wrapped).
pub fn in_identity_chart(
    joint: &RotationJoint,
    chart: &[[f64; 3]; 3],
    q: &mut [f64],
    qd: &mut [f64],
) {
    if *chart == crate::model::IDENTITY3 {
        return;
    }
    let w = body_rates(angles_of(joint, q), joint.angles.map(|k| qd[k]));
    let angles = zyx_angles_of(quaternion_near(&joint_rotation(chart, joint, q), None));
    let (sb, cb) = angles[1].sin_cos();
    let (sc, cc) = angles[2].sin_cos();
    // body_rates inverted: ω_y s_c + ω_z c_c = ȧ c_b, ω_y c_c − ω_z s_c = ḃ, ω_x = ċ − ȧ s_b
    let ad = (w[1] * sc + w[2] * cc) / cb;
    let rates = [ad, w[1] * cc - w[2] * sc, w[0] + ad * sb];
    for (i, &k) in joint.angles.iter().enumerate() {
        q[k] = angles[i];
        qd[k] = rates[i];
    }
}

/// Sets the charts of `model` to those output `i` of `tr` was read in, so that the model's
/// functions (kinematics, energies, M and h) evaluate that output's q and qd as the
/// simulation did.
pub fn use_charts_of<M: Model>(model: &mut M, tr: &crate::Trajectory, i: usize) {
    for j in 0..tr.joint_names.len() {
        model.set_chart(j, tr.chart(i, j));
    }
}

/// The charts of every rotation joint of `model`.
pub fn charts_of<M: Model>(model: &M) -> Vec<[[f64; 3]; 3]> {
    let mut charts = Vec::new();
    read_charts(model, &mut charts);
    charts
}

/// The charts of every rotation joint of `model` into `charts` (no allocation once it has
/// their number): what a controller or an effort is handed at each call.
pub fn read_charts<M: Model>(model: &M, charts: &mut Vec<[[f64; 3]; 3]>) {
    read_charts_erased(model, charts)
}

/// [`read_charts`] on the model behind the schemes.
pub(crate) fn read_charts_erased(
    model: &dyn crate::erased::ErasedModel,
    charts: &mut Vec<[[f64; 3]; 3]>,
) {
    charts.resize(model.info().rotation_joints.len(), [[0.0; 3]; 3]);
    for (j, c) in charts.iter_mut().enumerate() {
        *c = model.chart(j);
    }
}

/// Whether some rotation joint of `model` is read, at `q`, in a chart of quality below
/// `threshold` (|cos b| < threshold).
pub fn below<M: Model>(model: &M, q: &[f64], threshold: f64) -> bool {
    model
        .info()
        .rotation_joints
        .iter()
        .any(|j| chart_quality(j, q) < threshold)
}

/// Re-centres every joint of `model` whose chart quality at `q` is below `threshold`:
/// sets the model's charts, maps q, qd (and qdd) in place, and returns what moved in `moved`;
/// then lets the model map coordinates of its own ([`Model::recentred`]) and returns whether
/// it asks for the accelerations to be evaluated again.
pub fn recentre_below<M: Model>(
    model: &mut M,
    threshold: f64,
    q: &mut [f64],
    qd: &mut [f64],
    qdd: Option<&mut [f64]>,
    moved: &mut Vec<Recentring>,
) -> bool {
    recentre_below_erased(model, threshold, [q, qd], qdd, moved)
}

/// [`recentre_below`] on the model behind the schemes.
pub(crate) fn recentre_below_erased(
    model: &mut dyn crate::erased::ErasedModel,
    threshold: f64,
    [q, qd]: [&mut [f64]; 2],
    qdd: Option<&mut [f64]>,
    moved: &mut Vec<Recentring>,
) -> bool {
    moved.clear();
    let joints = model.info().rotation_joints;
    for (j, joint) in joints.iter().enumerate() {
        if chart_quality(joint, q) < threshold {
            let r = Recentring::at(j, joint, &model.chart(j), q, qd);
            model.set_chart(j, r.chart);
            moved.push(r);
        }
    }
    if let Some(a) = qdd {
        for r in moved.iter() {
            r.map_acceleration(a);
        }
    }
    !moved.is_empty() && model.recentred(moved, q, qd)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joint() -> RotationJoint {
        RotationJoint {
            frame: 0,
            angles: [0, 1, 2],
            translation: None,
        }
    }

    /// A NaN or infinite angle gives a NaN rotation at once (nalgebra's extraction of the
    /// rotation, unbounded, never met its tolerance on it and did not return).
    #[test]
    fn angles_that_are_not_finite_give_nan_not_a_hang() {
        let eye = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for bad in [f64::NAN, f64::INFINITY] {
            let u = joint_rotation(&eye, &joint(), &[bad, 0.0, 0.0]);
            assert!(u.as_ref().coords.iter().all(|x| x.is_nan()));
        }
        let u = joint_rotation(&eye, &joint(), &[0.3, 0.0, 0.0]);
        assert!((u.angle() - 0.3).abs() < 1e-15);
    }

    fn rot(q: &[f64], chart: &[[f64; 3]; 3]) -> Matrix3<f64> {
        joint_rotation(chart, &joint(), q)
            .to_rotation_matrix()
            .into_inner()
    }

    /// ω (joint axes) by central differences of R(t) = C·E(q + t q̇): skew(Rᵀ Ṙ).
    fn omega_fd(q: &[f64], qd: &[f64], chart: &[[f64; 3]; 3]) -> [f64; 3] {
        let h = 1e-6;
        let at = |s: f64| {
            let x: Vec<f64> = q.iter().zip(qd).map(|(a, b)| a + s * b).collect();
            rot(&x, chart)
        };
        let rd = (at(h) - at(-h)) / (2.0 * h);
        let w = at(0.0).transpose() * rd;
        [w[(2, 1)], w[(0, 2)], w[(1, 0)]]
    }

    #[test]
    fn zyx_is_rz_ry_rx() {
        let (a, b, c) = (0.3, -0.7, 1.1);
        let rz = Rotation3::from_axis_angle(&nalgebra::Vector3::z_axis(), a);
        let ry = Rotation3::from_axis_angle(&nalgebra::Vector3::y_axis(), b);
        let rx = Rotation3::from_axis_angle(&nalgebra::Vector3::x_axis(), c);
        let e = (rz * ry * rx).into_inner();
        assert!((zyx([a, b, c]) - e).norm() < 1e-15);
    }

    #[test]
    fn zyx_angles_of_a_rotation_read_in_any_chart() {
        let angles = [2.9, -1.2, 0.4];
        // the same rotation read in a chart tilted by 1 rad: C · E(q') = E(angles)
        let chart = zyx([0.5, 1.0, -0.3]);
        let q = {
            let r = Rotation3::from_matrix_unchecked(chart.transpose() * zyx(angles));
            let (c, b, a) = r.euler_angles();
            [a, b, c]
        };
        let u = joint_rotation(&array(&chart), &joint(), &q);
        let back = zyx_angles_of(quaternion_near(&u, None));
        for k in 0..3 {
            assert!((back[k] - angles[k]).abs() < 1e-12, "{back:?}");
        }
    }

    #[test]
    fn body_rates_are_the_angular_velocity_in_joint_axes() {
        let chart = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let (q, qd) = ([0.4, 1.2, -2.0], [0.7, -1.3, 2.2]);
        let w = body_rates(q, qd);
        let fd = omega_fd(&q, &qd, &chart);
        for i in 0..3 {
            assert!((w[i] - fd[i]).abs() < 1e-8, "{w:?} {fd:?}");
        }
    }

    #[test]
    fn recentring_keeps_the_rotation_its_rate_and_its_acceleration() {
        let chart = array(&zyx([0.2, 0.5, -0.3]));
        let (q0, qd0, qdd0) = ([0.4, 1.35, -2.0], [0.7, -1.3, 2.2], [3.0, -0.4, 1.7]);
        let (mut q, mut qd, mut qdd) = (q0, qd0, qdd0);
        let r = Recentring::at(0, &joint(), &chart, &mut q, &mut qd);
        r.map_acceleration(&mut qdd);
        assert_eq!(q, [0.0; 3]);
        // the same rotation
        assert!((rot(&q0, &chart) - rot(&q, &r.chart)).norm() < 1e-15);
        // the same angular velocity
        let (w0, w1) = (body_rates(q0, qd0), body_rates(q, qd));
        for i in 0..3 {
            assert!((w0[i] - w1[i]).abs() < 1e-15);
        }
        // the same angular acceleration: ω̇ by differences along each chart's motion
        let wdot = |q: [f64; 3], qd: [f64; 3], qdd: [f64; 3], c: &[[f64; 3]; 3]| {
            let h = 1e-5;
            let w_at = |s: f64| {
                let x: Vec<f64> = (0..3)
                    .map(|i| q[i] + s * qd[i] + 0.5 * s * s * qdd[i])
                    .collect();
                let v: Vec<f64> = (0..3).map(|i| qd[i] + s * qdd[i]).collect();
                // world axes: R ω_joint
                let w = body_rates([x[0], x[1], x[2]], [v[0], v[1], v[2]]);
                rot(&x, c) * nalgebra::Vector3::from(w)
            };
            (w_at(h) - w_at(-h)) / (2.0 * h)
        };
        let a0 = wdot(q0, qd0, qdd0, &chart);
        let a1 = wdot(q, qd, qdd, &r.chart);
        assert!((a0 - a1).norm() < 1e-8, "{a0} {a1}");
    }

    #[test]
    fn quaternions_keep_their_sign_from_one_output_to_the_next() {
        let u = UnitQuaternion::from_euler_angles(0.1, 0.2, 3.1);
        let x = quaternion_near(&u, None);
        assert!(x[3] >= 0.0);
        let y = quaternion_near(&u, Some(x.map(|c| -c)));
        assert_eq!(y, x.map(|c| -c));
    }
}
