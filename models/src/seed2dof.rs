//! seed2dof: two masses on a line, ground —k1— mass 1 —k2— mass 2, no gravity
//! (`tests/reference/MODELS.md`). Used by `examples/seed2dof.rs` and the tests.

mbs::multibody! {
    /// The 2-dof spring–mass system of the seed course; q = displacements from rest.
    pub model Seed2dof {
        param m1 = 1.0; param m2 = 1.0;
        param k1 = 79.15; param k2 = 1961.0;
        dof q[0] = 0.0; dof q[1] = 1.0;
        body mass1 { mass = m1; }
        body mass2 { mass = m2; }
        // at rest 1 m and 2 m from the wall; linear springs along x (axis = x): their length
        // is the signed distance along x, so the system is linear for any displacement
        TOG[mass1] = Tdisp(1 + q[0], 0, 0);
        TOG[mass2] = Tdisp(2 + q[1], 0, 0);
        spring(ground, mass1, k = k1, l0 = 1, axis = x);
        spring(mass1, mass2, k = k2, l0 = 1, axis = x);
    }
}

/// The exact modes of seed2dof with the default parameters (unit masses, so M = I): circular
/// frequencies ω (rad/s, ascending) and unit mode shapes from K = [k1 + k2, −k2; −k2, k2].
pub fn exact_modes() -> ([f64; 2], [[f64; 2]; 2]) {
    let (k1, k2): (f64, f64) = (79.15, 1961.0);
    let (a, b, d) = (k1 + k2, -k2, k2);
    let disc = ((a - d) * (a - d) / 4.0 + b * b).sqrt();
    let mut w = [0.0; 2];
    let mut v = [[0.0; 2]; 2];
    for (k, lam) in [(a + d) / 2.0 - disc, (a + d) / 2.0 + disc]
        .into_iter()
        .enumerate()
    {
        w[k] = lam.sqrt();
        let (v0, v1) = (b, lam - a);
        let n = v0.hypot(v1);
        v[k] = [v0 / n, v1 / n];
    }
    (w, v)
}

/// The exact (q, qd) at time t from the declared start q0 = (0, 1), qd0 = 0:
/// q(t) = Σ_k v_k (v_kᵀ q0) cos(ω_k t).
pub fn exact_state(t: f64) -> Vec<f64> {
    let (w, v) = exact_modes();
    let mut y = vec![0.0; 4];
    for k in 0..2 {
        let c = v[k][1]; // v_kᵀ q0 with q0 = (0, 1)
        for i in 0..2 {
            y[i] += v[k][i] * c * (w[k] * t).cos();
            y[2 + i] -= v[k][i] * c * w[k] * (w[k] * t).sin();
        }
    }
    y
}
