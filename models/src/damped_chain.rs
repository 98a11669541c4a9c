//! A chain of six bars hanging in a plane with a viscous damper in every joint: fast modes
//! that decay (up to about 3.1e3 1/s) beside the slow swing, the motion Runge–Kutta–Chebyshev
//! (`Scheme::Rkc`) is for.

mbs::multibody! {
    /// Six uniform bars (l = 0.5 m, 1 kg) in a vertical plane, relative angles 0.2 rad each
    /// at the start, a damper of c = 20 N·m·s/rad in every joint (the first to the ground).
    pub model DampedChain {
        param l = 0.5; param m = 1.0; param g = 9.81; param c = 20.0;
        for i in 0..6 {
            dof q[i] = 0.2;
            body bar[i] { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        }
        TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
        for i in 1..6 {
            TOG[bar[i]] = TOG[bar[i - 1]] * Tdisp(0, -l / 2, 0) * Trotz(q[i]) * Tdisp(0, -l / 2, 0);
        }
        gravity(0, -g, 0);
        for i in 0..6 {
            generalized_force(q[i], -c * qd[i]);
        }
    }
}
