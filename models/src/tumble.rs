//! tumble (`tests/reference/MODELS.md`): a free rigid body spinning about its intermediate
//! axis, on ZYX Euler angles ([`Tumble`], MODELS.md's), on XYZ angles ([`TumbleXyz`]), which
//! every flip drives through their singularity, and on a spherical joint ([`TumbleBall`]),
//! which runs through every orientation.

mbs::multibody! {
    /// tumble (MODELS.md): a free rigid body, 0.12 kg, principal inertias (1.7231e-4, 6.58e-6,
    /// 1.7243e-4) kg m² about body x, y, z (x the intermediate axis), ZYX Euler angles,
    /// spinning at 10 rad/s about body x plus 1e-3 rad/s about body z (at q = 0:
    /// ω_body = (q̇2, q̇1, q̇0)). Singular at q1 = ±π/2 (body x along world z).
    pub model Tumble {
        dof q[0] = 0.0, qd = 1e-3;
        dof q[1] = 0.0;
        dof q[2] = 0.0, qd = 10.0;
        option tangents;
        body b { mass = 0.12; inertia = (1.7231e-4, 6.58e-6, 1.7243e-4); }
        TOG[b] = Trotz(q[0]) * Troty(q[1]) * Trotx(q[2]);
    }
}

mbs::multibody! {
    /// tumble's body and spin on XYZ Euler angles: singular at q1 = ±π/2, where body z lies
    /// along world x. Half-way through its flip the body spins about its z axis, which then
    /// points along the angular momentum (world x) to within 5e-3 rad: every flip meets
    /// the singularity, whatever its timing (at q = 0: ω_body = (q̇0, q̇1, q̇2)).
    pub model TumbleXyz {
        dof q[0] = 0.0, qd = 10.0;
        dof q[1] = 0.0;
        dof q[2] = 0.0, qd = 1e-3;
        option tangents;
        body b { mass = 0.12; inertia = (1.7231e-4, 6.58e-6, 1.7243e-4); }
        TOG[b] = Trotx(q[0]) * Troty(q[1]) * Trotz(q[2]);
    }
}

mbs::multibody! {
    /// tumble's body and spin on a spherical joint (`Tball`): ZYX angles read in a chart the
    /// runtime re-centres before gimbal lock, so the flips never stop the run. The same start
    /// as [`Tumble`] (the chart starts at the identity).
    pub model TumbleBall {
        dof q[0] = 0.0, qd = 1e-3;
        dof q[1] = 0.0;
        dof q[2] = 0.0, qd = 10.0;
        option tangents;
        body b { mass = 0.12; inertia = (1.7231e-4, 6.58e-6, 1.7243e-4); }
        TOG[b] = Tball(q[0], q[1], q[2]);
    }
}

/// The principal inertias of the tumble's body about body x, y, z (kg m²), as in its models.
pub const INERTIA: [f64; 3] = [1.7231e-4, 6.58e-6, 1.7243e-4];

/// The spin phase that makes the accurate flip of [`Tumble`] (ZYX) meet its singularity at
/// t ≈ 8.0 s: −π/2 − φ*, φ* = 3.0587 rad the azimuth (atan2(z, y)) of body x when it crosses
/// the plane x = 0 in the run from MODELS.md's start (DOPRI5, rtol 1e-10, at t = 8.0033 s).
pub const PHI0: f64 = -1.487_927_615_474_704;

/// MODELS.md's start turned by `phi` about world x, on ZYX angles (those of [`Tumble`] and
/// [`TumbleBall`] at the identity chart): (q0, qd0), the same body rates (10, 0, 1e-3) rad/s
/// about body (x, y, z).
pub fn turned_start(phi: f64) -> (Vec<f64>, Vec<f64>) {
    (
        vec![0.0, 0.0, phi],
        vec![1e-3 * phi.cos(), -1e-3 * phi.sin(), 10.0],
    )
}
