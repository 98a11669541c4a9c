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
        option tangents;
        for i in 0..16 {
            dof q[i] = 0.3;
            body bar[i] { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        }
        TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
        for i in 1..16 {
            TOG[bar[i]] = TOG[bar[i - 1]] * Tdisp(0, -l / 2, 0) * Trotz(q[i]) * Tdisp(0, -l / 2, 0);
        }
        gravity(0, -g, 0);
        for i in 0..16 {
            generalized_force(q[i], -k * (q[i] - q_rest));
        }
    }
}
