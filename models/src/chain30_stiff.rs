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
        body bar0 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar1 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar2 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar3 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar4 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar5 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar6 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar7 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar8 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar9 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar10 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar11 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar12 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar13 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar14 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar15 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar16 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar17 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar18 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar19 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar20 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar21 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar22 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar23 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar24 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar25 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar26 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar27 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar28 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar29 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        TOG[bar0] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
        TOG[bar1] = TOG[bar0] * Tdisp(0, -l / 2, 0) * Trotz(q[1]) * Tdisp(0, -l / 2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l / 2, 0) * Trotz(q[2]) * Tdisp(0, -l / 2, 0);
        TOG[bar3] = TOG[bar2] * Tdisp(0, -l / 2, 0) * Trotz(q[3]) * Tdisp(0, -l / 2, 0);
        TOG[bar4] = TOG[bar3] * Tdisp(0, -l / 2, 0) * Trotz(q[4]) * Tdisp(0, -l / 2, 0);
        TOG[bar5] = TOG[bar4] * Tdisp(0, -l / 2, 0) * Trotz(q[5]) * Tdisp(0, -l / 2, 0);
        TOG[bar6] = TOG[bar5] * Tdisp(0, -l / 2, 0) * Trotz(q[6]) * Tdisp(0, -l / 2, 0);
        TOG[bar7] = TOG[bar6] * Tdisp(0, -l / 2, 0) * Trotz(q[7]) * Tdisp(0, -l / 2, 0);
        TOG[bar8] = TOG[bar7] * Tdisp(0, -l / 2, 0) * Trotz(q[8]) * Tdisp(0, -l / 2, 0);
        TOG[bar9] = TOG[bar8] * Tdisp(0, -l / 2, 0) * Trotz(q[9]) * Tdisp(0, -l / 2, 0);
        TOG[bar10] = TOG[bar9] * Tdisp(0, -l / 2, 0) * Trotz(q[10]) * Tdisp(0, -l / 2, 0);
        TOG[bar11] = TOG[bar10] * Tdisp(0, -l / 2, 0) * Trotz(q[11]) * Tdisp(0, -l / 2, 0);
        TOG[bar12] = TOG[bar11] * Tdisp(0, -l / 2, 0) * Trotz(q[12]) * Tdisp(0, -l / 2, 0);
        TOG[bar13] = TOG[bar12] * Tdisp(0, -l / 2, 0) * Trotz(q[13]) * Tdisp(0, -l / 2, 0);
        TOG[bar14] = TOG[bar13] * Tdisp(0, -l / 2, 0) * Trotz(q[14]) * Tdisp(0, -l / 2, 0);
        TOG[bar15] = TOG[bar14] * Tdisp(0, -l / 2, 0) * Trotz(q[15]) * Tdisp(0, -l / 2, 0);
        TOG[bar16] = TOG[bar15] * Tdisp(0, -l / 2, 0) * Trotz(q[16]) * Tdisp(0, -l / 2, 0);
        TOG[bar17] = TOG[bar16] * Tdisp(0, -l / 2, 0) * Trotz(q[17]) * Tdisp(0, -l / 2, 0);
        TOG[bar18] = TOG[bar17] * Tdisp(0, -l / 2, 0) * Trotz(q[18]) * Tdisp(0, -l / 2, 0);
        TOG[bar19] = TOG[bar18] * Tdisp(0, -l / 2, 0) * Trotz(q[19]) * Tdisp(0, -l / 2, 0);
        TOG[bar20] = TOG[bar19] * Tdisp(0, -l / 2, 0) * Trotz(q[20]) * Tdisp(0, -l / 2, 0);
        TOG[bar21] = TOG[bar20] * Tdisp(0, -l / 2, 0) * Trotz(q[21]) * Tdisp(0, -l / 2, 0);
        TOG[bar22] = TOG[bar21] * Tdisp(0, -l / 2, 0) * Trotz(q[22]) * Tdisp(0, -l / 2, 0);
        TOG[bar23] = TOG[bar22] * Tdisp(0, -l / 2, 0) * Trotz(q[23]) * Tdisp(0, -l / 2, 0);
        TOG[bar24] = TOG[bar23] * Tdisp(0, -l / 2, 0) * Trotz(q[24]) * Tdisp(0, -l / 2, 0);
        TOG[bar25] = TOG[bar24] * Tdisp(0, -l / 2, 0) * Trotz(q[25]) * Tdisp(0, -l / 2, 0);
        TOG[bar26] = TOG[bar25] * Tdisp(0, -l / 2, 0) * Trotz(q[26]) * Tdisp(0, -l / 2, 0);
        TOG[bar27] = TOG[bar26] * Tdisp(0, -l / 2, 0) * Trotz(q[27]) * Tdisp(0, -l / 2, 0);
        TOG[bar28] = TOG[bar27] * Tdisp(0, -l / 2, 0) * Trotz(q[28]) * Tdisp(0, -l / 2, 0);
        TOG[bar29] = TOG[bar28] * Tdisp(0, -l / 2, 0) * Trotz(q[29]) * Tdisp(0, -l / 2, 0);
        gravity(0, -g, 0);
        generalized_force(q[1], -k * (q[1] - q_rest));
        generalized_force(q[2], -k * (q[2] - q_rest));
        generalized_force(q[3], -k * (q[3] - q_rest));
        generalized_force(q[4], -k * (q[4] - q_rest));
        generalized_force(q[5], -k * (q[5] - q_rest));
        generalized_force(q[6], -k * (q[6] - q_rest));
        generalized_force(q[7], -k * (q[7] - q_rest));
        generalized_force(q[8], -k * (q[8] - q_rest));
        generalized_force(q[9], -k * (q[9] - q_rest));
        generalized_force(q[10], -k * (q[10] - q_rest));
        generalized_force(q[11], -k * (q[11] - q_rest));
        generalized_force(q[12], -k * (q[12] - q_rest));
        generalized_force(q[13], -k * (q[13] - q_rest));
        generalized_force(q[14], -k * (q[14] - q_rest));
        generalized_force(q[15], -k * (q[15] - q_rest));
        generalized_force(q[16], -k * (q[16] - q_rest));
        generalized_force(q[17], -k * (q[17] - q_rest));
        generalized_force(q[18], -k * (q[18] - q_rest));
        generalized_force(q[19], -k * (q[19] - q_rest));
        generalized_force(q[20], -k * (q[20] - q_rest));
        generalized_force(q[21], -k * (q[21] - q_rest));
        generalized_force(q[22], -k * (q[22] - q_rest));
        generalized_force(q[23], -k * (q[23] - q_rest));
        generalized_force(q[24], -k * (q[24] - q_rest));
        generalized_force(q[25], -k * (q[25] - q_rest));
        generalized_force(q[26], -k * (q[26] - q_rest));
        generalized_force(q[27], -k * (q[27] - q_rest));
        generalized_force(q[28], -k * (q[28] - q_rest));
        generalized_force(q[29], -k * (q[29] - q_rest));
    }
}
