//! chain30_stiff: a chain of 30 light bars joined by stiff torsional springs, without damping, the
//! hard case of BDF on undamped stiff oscillation (`tests/bdf_stiff_oscillation.rs`): its
//! undamped modes run from the swing's 4 rad/s to 1.6e5 rad/s.

mbs::multibody! {
    /// Planar chain of 30 uniform bars (l = 3 cm, m = 10 g), hinged end to end about +z with
    /// relative angles, hanging straight down. The first joint is free and starts swinging at
    /// w0 = 3 rad/s (up to ≈ 0.75 rad); joints 1–29 hold torsional springs of k = 5000 N·m/rad,
    /// no damping, at rest at 0 (generalised forces: their energy ½k Σ q[i]² is outside the
    /// model's potential). The start is on the slow motion to first order: the straight chain
    /// at the bottom has no bending moment, and each spring starts at the rate of its
    /// quasi-static deflection, qd[i] = C_i·w0·m g l/k, with C_i = −(dM_i/dθ)/(m g l) the rate of
    /// the bending moment M_i at joint i of the rigid chain swung by θ. The stiff modes then
    /// hold only what the swing's slowly changing loads give them: an integrator stable on
    /// them steps over them (Radau5 at rtol 1e-6: 32 steps for 2 s).
    pub model Chain30Stiff {
        param l = 0.03; param m = 0.01; param g = 9.81;
        param k = 5000.0; param w0 = 3.0; param q_rest = 0.0;
        dof q[0] = 0.0, qd = w0;
        dof q[1] = 0.0, qd = 7.008333 * w0 * m * g * l / k;
        dof q[2] = 0.0, qd = 13.066667 * w0 * m * g * l / k;
        dof q[3] = 0.0, qd = 18.225000 * w0 * m * g * l / k;
        dof q[4] = 0.0, qd = 22.533333 * w0 * m * g * l / k;
        dof q[5] = 0.0, qd = 26.041667 * w0 * m * g * l / k;
        dof q[6] = 0.0, qd = 28.800000 * w0 * m * g * l / k;
        dof q[7] = 0.0, qd = 30.858333 * w0 * m * g * l / k;
        dof q[8] = 0.0, qd = 32.266667 * w0 * m * g * l / k;
        dof q[9] = 0.0, qd = 33.075000 * w0 * m * g * l / k;
        dof q[10] = 0.0, qd = 33.333333 * w0 * m * g * l / k;
        dof q[11] = 0.0, qd = 33.091667 * w0 * m * g * l / k;
        dof q[12] = 0.0, qd = 32.400000 * w0 * m * g * l / k;
        dof q[13] = 0.0, qd = 31.308333 * w0 * m * g * l / k;
        dof q[14] = 0.0, qd = 29.866667 * w0 * m * g * l / k;
        dof q[15] = 0.0, qd = 28.125000 * w0 * m * g * l / k;
        dof q[16] = 0.0, qd = 26.133333 * w0 * m * g * l / k;
        dof q[17] = 0.0, qd = 23.941667 * w0 * m * g * l / k;
        dof q[18] = 0.0, qd = 21.600000 * w0 * m * g * l / k;
        dof q[19] = 0.0, qd = 19.158333 * w0 * m * g * l / k;
        dof q[20] = 0.0, qd = 16.666667 * w0 * m * g * l / k;
        dof q[21] = 0.0, qd = 14.175000 * w0 * m * g * l / k;
        dof q[22] = 0.0, qd = 11.733333 * w0 * m * g * l / k;
        dof q[23] = 0.0, qd = 9.391667 * w0 * m * g * l / k;
        dof q[24] = 0.0, qd = 7.200000 * w0 * m * g * l / k;
        dof q[25] = 0.0, qd = 5.208333 * w0 * m * g * l / k;
        dof q[26] = 0.0, qd = 3.466667 * w0 * m * g * l / k;
        dof q[27] = 0.0, qd = 2.025000 * w0 * m * g * l / k;
        dof q[28] = 0.0, qd = 0.933333 * w0 * m * g * l / k;
        dof q[29] = 0.0, qd = 0.241667 * w0 * m * g * l / k;
        option tangents;
        for i in 0..30 {
            body bar[i] { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        }
        TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
        for i in 1..30 {
            TOG[bar[i]] = TOG[bar[i - 1]] * Tdisp(0, -l / 2, 0) * Trotz(q[i]) * Tdisp(0, -l / 2, 0);
        }
        gravity(0, -g, 0);
        for i in 1..30 {
            generalized_force(q[i], -k * (q[i] - q_rest));
        }
    }
}
