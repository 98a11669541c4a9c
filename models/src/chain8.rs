//! chain8 of MODELS.md: 8 uniform bars (l = 0.5 m, 1 kg), hinged end to end about +z,
//! relative angles, q(0) = 0.3 rad every joint, gravity. Written out link by link (the language
//! has no loops), as [`chain24`](crate::chain24). Used by `examples/work_precision.rs`.

mbs::multibody! {
    /// Planar chain of 8 uniform bars.
    pub model Chain8 {
        param l = 0.5; param m = 1.0; param g = 9.81;
        dof q[0] = 0.3;
        dof q[1] = 0.3;
        dof q[2] = 0.3;
        dof q[3] = 0.3;
        dof q[4] = 0.3;
        dof q[5] = 0.3;
        dof q[6] = 0.3;
        dof q[7] = 0.3;
        body bar0 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar1 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar2 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar3 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar4 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar5 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar6 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar7 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        TOG[bar0] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        TOG[bar1] = TOG[bar0] * Tdisp(0, -l/2, 0) * Trotz(q[1]) * Tdisp(0, -l/2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l/2, 0) * Trotz(q[2]) * Tdisp(0, -l/2, 0);
        TOG[bar3] = TOG[bar2] * Tdisp(0, -l/2, 0) * Trotz(q[3]) * Tdisp(0, -l/2, 0);
        TOG[bar4] = TOG[bar3] * Tdisp(0, -l/2, 0) * Trotz(q[4]) * Tdisp(0, -l/2, 0);
        TOG[bar5] = TOG[bar4] * Tdisp(0, -l/2, 0) * Trotz(q[5]) * Tdisp(0, -l/2, 0);
        TOG[bar6] = TOG[bar5] * Tdisp(0, -l/2, 0) * Trotz(q[6]) * Tdisp(0, -l/2, 0);
        TOG[bar7] = TOG[bar6] * Tdisp(0, -l/2, 0) * Trotz(q[7]) * Tdisp(0, -l/2, 0);
        gravity(0, -g, 0);
    }
}
