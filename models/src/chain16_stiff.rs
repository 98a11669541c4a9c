//! chain16 with stiff joints: MODELS.md's chainN at N = 16 with a torsional spring of
//! 1e6 N·m/rad in every joint, the hard cases' stiff chain.

mbs::multibody! {
    /// chain16 (MODELS.md chainN, N = 16: uniform bars l = 0.5 m, 1 kg, relative angles,
    /// 0.3 rad each at the start) with a torsional spring of k = 1e6 N·m/rad in every joint,
    /// at rest at the start angle (generalised forces: their energy ½k(q − q_rest)² is added
    /// by the test).
    pub model Chain16Stiff {
        param l = 0.5; param m = 1.0; param g = 9.81;
        param k = 1e6; param q_rest = 0.3;
        dof q[0] = 0.3;
        dof q[1] = 0.3;
        dof q[2] = 0.3;
        dof q[3] = 0.3;
        dof q[4] = 0.3;
        dof q[5] = 0.3;
        dof q[6] = 0.3;
        dof q[7] = 0.3;
        dof q[8] = 0.3;
        dof q[9] = 0.3;
        dof q[10] = 0.3;
        dof q[11] = 0.3;
        dof q[12] = 0.3;
        dof q[13] = 0.3;
        dof q[14] = 0.3;
        dof q[15] = 0.3;
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
        gravity(0, -g, 0);
        generalized_force(q[0], -k * (q[0] - q_rest));
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
    }
}
