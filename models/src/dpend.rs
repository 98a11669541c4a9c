//! dpend: planar double pendulum of two uniform bars (`tests/reference/MODELS.md`).
//! Used by `examples/dpend.rs`, the tests and the benchmarks.

mbs::multibody! {
    /// Planar double pendulum: two uniform bars hinged at the origin and end to end about +z.
    /// q[0] is bar 1's angle from the downward vertical, q[1] bar 2's angle relative to bar 1.
    pub model DoublePendulum {
        param l = 1.0; param m = 1.0; param g = 9.81;
        // Uniform bar along its y axis: m l²/12 about x and z, 0 about its own axis.
        let i_bar = m * l * l / 12;
        dof q[0] = PI / 2; dof q[1] = 0.0;
        body bar1 { mass = m; inertia = (i_bar, 0, i_bar); }
        body bar2 { mass = m; inertia = (i_bar, 0, i_bar); }
        TOG[bar1] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l / 2, 0) * Trotz(q[1]) * Tdisp(0, -l / 2, 0);
        point tip on bar2 at (0, -l / 2, 0);
        gravity(0, -g, 0);
    }
}
