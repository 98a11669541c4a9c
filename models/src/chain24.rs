//! chain24 of MODELS.md: 24 uniform bars (l = 0.5 m, 1 kg), hinged end to end about +z,
//! relative angles, q(0) = 0.3 rad every joint, gravity: bars `bar[0]` … `bar[23]`, written with
//! `for` loops. Used by the benchmarks.

mbs::multibody! {
    /// Planar chain of 24 uniform bars.
    pub model Chain24 {
        param l = 0.5; param m = 1.0; param g = 9.81;
        for i in 0..24 {
            dof q[i] = 0.3;
            body bar[i] { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        }
        TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        for i in 1..24 {
            TOG[bar[i]] = TOG[bar[i-1]] * Tdisp(0, -l/2, 0) * Trotz(q[i]) * Tdisp(0, -l/2, 0);
        }
        gravity(0, -g, 0);
    }
}
