//! Ellipsoids in contact with a plane (`contact(p, ellipsoid = (a, b, c), …)`), with the
//! Hunt–Crossley law (`exponent`, `dissipation`):
//!
//! - equal semi-axes give the sphere contact's M and h;
//! - a tilted ellipsoid's generalised forces equal a computation by hand (support point,
//!   penetration, its rate, the force's moment);
//! - exact tangents equal central differences in contact;
//! - the energy identity dE/dt = power holds along a run where an egg drops, bounces and rolls.

mod common;

#[path = "common/quoted.rs"]
mod quoted;

use common::{accelerations, energy_rate, fd_tangents};
use mbs::{Model, Options, Output, Scheme, simulate};

mbs::multibody! {
    /// A ball as an ellipsoid of equal semi-axes, spinning and sliding on a tilted plane.
    pub model BallEllipsoid {
        dof x = 0.0; dof y = 0.0; dof z = 0.2; dof a = 0.0; dof b = 0.1; dof r = 0.0;
        body ball { mass = 1.0; inertia = (0.004, 0.004, 0.004); }
        TOG[ball] = Tdisp(x, y, z) * Trotz(a) * Troty(b) * Trotx(r);
        gravity(0, 0, -9.81);
        contact(ball, ellipsoid = (0.1, 0.1, 0.1), plane = (0.6, 0, 0.8), offset = 0.02, k = 1e4, c = 30, mu = 0.4, eps = 1e-2);
    }
}

mbs::multibody! {
    /// The same ball as a sphere.
    pub model BallSphere {
        dof x = 0.0; dof y = 0.0; dof z = 0.2; dof a = 0.0; dof b = 0.1; dof r = 0.0;
        body ball { mass = 1.0; inertia = (0.004, 0.004, 0.004); }
        TOG[ball] = Tdisp(x, y, z) * Trotz(a) * Troty(b) * Trotx(r);
        gravity(0, 0, -9.81);
        contact(ball, sphere = 0.1, plane = (0.6, 0, 0.8), offset = 0.02, k = 1e4, c = 30, mu = 0.4, eps = 1e-2);
    }
}

mbs::multibody! {
    /// An ellipsoid that slides in y, z and turns about x, pressed into the ground z = 0
    /// (Hertz exponent, Hunt–Crossley dissipation, no friction, no gravity).
    pub model TiltedEgg {
        param ea = 0.05; param eb = 0.04; param ec = 0.02; param k = 2e6; param d = 0.8;
        dof y = 0.0; dof z = 0.01; dof th = 0.0;
        body egg { mass = 0.3; inertia = (1e-4, 2e-4, 3e-4); }
        TOG[egg] = Tdisp(0, y, z) * Trotx(th);
        contact(egg, ellipsoid = (ea, eb, ec), k = k, exponent = 1.5, dissipation = d);
    }
}

mbs::multibody! {
    /// A free egg: a Hertzian ellipsoid with friction on the ground, and a linear one at a
    /// point off its centre against a tilted wall.
    pub model Egg {
        dof x = 0.0, qd = 0.6; dof y = 0.0, qd = -0.2; dof z = 0.08, qd = -0.5;
        dof a = 0.2, qd = 1.0; dof b = 0.5, qd = -2.0; dof r = 0.3, qd = 3.0;
        body egg { mass = 0.2; inertia = (2e-4, 2e-4, 1e-4); }
        point nose on egg at (0, 0, 0.03);
        TOG[egg] = Tdisp(x, y, z) * Trotz(a) * Troty(b) * Trotx(r);
        gravity(0, 0, -9.81);
        contact(egg, ellipsoid = (0.03, 0.03, 0.045), k = 5e6, exponent = 1.5, dissipation = 0.5, mu = 0.3, eps = 1e-2);
        contact(nose, ellipsoid = (0.01, 0.02, 0.015), plane = (-0.8, 0, 0.6), offset = -0.05, k = 2e4, c = 20, mu = 0.2, eps = 1e-2);
        option tangents;
    }
}

fn dynamics<M: Model>(m: &M, q: &[f64], qd: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = M::NQ;
    let (mut mm, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    m.dynamics(0.0, q, qd, &[], &mut mm, &mut h);
    (mm, h)
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

#[test]
fn equal_semi_axes_are_the_sphere() {
    // how far M and h may differ, relative to the largest |h| (or 1)
    const WITHIN: f64 = 1e-12;
    let (e, s) = (BallEllipsoid::default(), BallSphere::default());
    // pressing into the tilted plane, spinning and sliding; then out of contact
    for (q, qd) in [
        (
            [0.05, 0.02, 0.06, 0.3, -0.4, 0.7],
            [0.5, -0.3, -0.2, 2.0, -1.0, 3.0],
        ),
        (
            [-0.1, 0.3, 0.1, 1.3, 0.2, -0.5],
            [0.01, 0.02, -0.1, 0.1, 0.05, -0.2],
        ),
        (
            [0.0, 0.0, 0.5, 0.0, 0.0, 0.0],
            [0.1, 0.0, 0.0, 0.0, 1.0, 0.0],
        ),
    ] {
        let (me, he) = dynamics(&e, &q, &qd);
        let (ms, hs) = dynamics(&s, &q, &qd);
        let scale = max_abs(&hs).max(1.0);
        for (x, y) in me.iter().chain(&he).zip(ms.iter().chain(&hs)) {
            assert!((x - y).abs() <= WITHIN * scale, "at {q:?}: {x} vs {y}");
        }
    }
    quoted::says(
        "README.md",
        &[format!(
            "ellipsoids equal spheres at equal semi-axes to {WITHIN:.0e} and a tilted one a \
             computation by hand (`tests/ellipsoid_contact.rs`)"
        )],
    );
}

#[test]
fn a_tilted_ellipsoid_pushes_as_computed_by_hand() {
    let egg = TiltedEgg::default();
    let p = egg.params().clone();
    let (b2, c2) = (p.eb * p.eb, p.ec * p.ec);
    for (q, qd) in [
        ([0.01, 0.02, 0.4f64], [0.3, -0.05, 1.5f64]),
        ([0.0, 0.025, -1.1], [0.0, 0.02, -0.7]),
        ([0.0, 0.03, 0.9], [0.0, 0.0, 0.0]),
    ] {
        let [_, z, th] = q;
        let [_, zd, thd] = qd;
        let (s, c) = th.sin_cos();
        // the egg's axes are Rx(θ): the ground's normal in them is m = (0, sin θ, cos θ);
        // the support point is −D² m / sqrt(mᵀ D² m) from the centre
        let root = (b2 * s * s + c2 * c * c).sqrt();
        let delta = -z + root;
        let delta_rate = -zd + (b2 - c2) * s * c / root * thd;
        assert!(delta > 0.0, "in contact at {q:?}");
        let f = p.k * delta.powf(1.5) * (1.0 + p.d * delta_rate);
        // the support point in world axes: Rx(θ) (0, −b² sin θ, −c² cos θ) / root
        let yw = (c * (-b2 * s) - s * (-c2 * c)) / root;
        let expected = [0.0, f, yw * f];
        let (_, h) = dynamics(&egg, &q, &qd);
        // the only other term, −ω × Iω, is zero for a rotation about a principal axis
        for i in 0..3 {
            assert!(
                (h[i] - expected[i]).abs() <= 1e-12 * f.abs(),
                "h[{i}] at {q:?}: {} vs {}",
                h[i],
                expected[i]
            );
        }
    }
    // above the ground: no force
    let (_, h) = dynamics(&egg, &[0.0, 0.05, 0.3], &[0.0, -1.0, 0.0]);
    assert_eq!(h, vec![0.0; 3]);
    // semi-axes and dissipation from parameters are checked when they are set
    let mut bad = egg.clone();
    for (axis, d) in [(-0.01, 0.8), (0.05, -0.1)] {
        let mut p = egg.params().clone();
        p.ea = axis;
        p.d = d;
        let err = bad.set_params(p).unwrap_err();
        let name = if axis < 0.0 {
            "ellipsoid"
        } else {
            "dissipation"
        };
        assert!(
            matches!(err, mbs::ParamError::InvalidCoefficient { name: n, .. } if n == name),
            "{err}"
        );
    }
}

/// Penetrations of the egg into the ground and of its nose's ellipsoid into the wall, from
/// the model's kinematics and the support-point formula.
fn penetrations(egg: &Egg, q: &[f64]) -> [f64; 2] {
    let mut kin = mbs::Kinematics::new::<Egg>();
    egg.kinematics(0.0, q, &[0.0; 6], &mut kin);
    let pose = &kin.frames[0].pose;
    let depth = |centre: [f64; 3], axes: [f64; 3], n: [f64; 3], h0: f64| {
        // m = Rᵀ n, s = sqrt(Σ (aᵢ mᵢ)²)
        let r = pose.rotation;
        let m: Vec<f64> = (0..3)
            .map(|j| (0..3).map(|i| r[i][j] * n[i]).sum())
            .collect();
        let s = (0..3).map(|i| (axes[i] * m[i]).powi(2)).sum::<f64>().sqrt();
        h0 - (0..3).map(|i| n[i] * centre[i]).sum::<f64>() + s
    };
    [
        depth(pose.position, [0.03, 0.03, 0.045], [0.0, 0.0, 1.0], 0.0),
        depth(
            kin.points[0].position,
            [0.01, 0.02, 0.015],
            [-0.8, 0.0, 0.6],
            -0.05,
        ),
    ]
}

#[test]
fn exact_tangents_of_ellipsoid_contacts_match_central_differences() {
    let egg = Egg::default();
    let q = [0.09, -0.02, 0.035, 0.4, 0.6, -0.3];
    let qd = [0.6, -0.3, -0.2, 1.5, -2.0, 1.0];
    let qdd = [0.3, -1.0, 2.0, 0.5, -0.2, 0.1];
    let d = penetrations(&egg, &q);
    assert!(d[0] > 0.0 && d[1] > 0.0, "both in contact: {d:?}");
    let n = Egg::NQ;
    let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
    egg.tangents(0.0, &q, &qd, &qdd, &[], &mut k, &mut c)
        .unwrap();
    let (kf, cf) = fd_tangents(&egg, &q, &qd, &qdd, 1e-7);
    let rel = |x: &[f64], y: &[f64]| {
        let d: Vec<f64> = x.iter().zip(y).map(|(a, b)| a - b).collect();
        max_abs(&d) / max_abs(y)
    };
    let (ek, ec) = (rel(&k, &kf), rel(&c, &cf));
    println!("egg in two contacts: K_t {ek:.2e}, C_t {ec:.2e}");
    assert!(ek < 1e-6 && ec < 1e-6, "K_t {ek:.2e}, C_t {ec:.2e}");
}

#[test]
fn energy_identity_for_a_dropped_egg() {
    let egg = Egg::default();
    let opts = Options {
        output: Output::Every { dt: 1e-3 },
        ..Options::adaptive(0.8, 1e-8)
    };
    let (tr, st) = simulate(Egg::default(), Scheme::Radau5, opts).unwrap();
    let (mut worst, mut in_contact, mut dissipated) = (0.0f64, [0usize; 2], 0.0f64);
    for i in 0..tr.len() {
        let (t, q, qd) = (tr.t[i], tr.q(i), tr.qd(i));
        let qdd = accelerations(&egg, t, q, qd);
        // dE/dt along the motion: the difference's truncation error scales as its step², so
        // 1e-7 keeps it far below the bound
        let de = energy_rate(&egg, t, q, qd, &qdd, 1e-7);
        let p = egg.power(t, q, qd, &[]);
        let scale = p.abs().max(de.abs()).max(1.0);
        worst = worst.max((de - p).abs() / scale);
        assert!(p <= 1e-12 * scale, "power {p} > 0 at t = {t}");
        dissipated = dissipated.min(p);
        let d = penetrations(&egg, q);
        in_contact[0] += (d[0] > 0.0) as usize;
        in_contact[1] += (d[1] > 0.0) as usize;
    }
    println!(
        "egg, radau5 rtol 1e-8, {} steps: {} outputs, on the ground at {}, nose in the wall at {}; \
         max |dE/dt − P| / max(|P|, |dE/dt|, 1 W) = {worst:.2e}; most negative power {dissipated:.2} W",
        st.steps,
        tr.len(),
        in_contact[0],
        in_contact[1]
    );
    assert!(in_contact[0] > 50 && in_contact[1] > 5, "{in_contact:?}");
    assert!(worst < 1e-6, "energy identity: {worst:.2e}");
}
