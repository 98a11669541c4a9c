//! chain24 of MODELS.md: 24 uniform bars (l = 0.5 m, 1 kg), hinged end to end about +z,
//! relative angles, q(0) = 0.3 rad every joint, gravity. Written out link by link (the language
//! has no loops). Used by the benchmarks.

mbs::multibody! {
    /// Planar chain of 24 uniform bars.
    pub model Chain24 {
        param l = 0.5; param m = 1.0; param g = 9.81;
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
        dof q[16] = 0.3;
        dof q[17] = 0.3;
        dof q[18] = 0.3;
        dof q[19] = 0.3;
        dof q[20] = 0.3;
        dof q[21] = 0.3;
        dof q[22] = 0.3;
        dof q[23] = 0.3;
        body bar0 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar1 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar2 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar3 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar4 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar5 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar6 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar7 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar8 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar9 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar10 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar11 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar12 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar13 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar14 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar15 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar16 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar17 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar18 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar19 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar20 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar21 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar22 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar23 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        TOG[bar0] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        TOG[bar1] = TOG[bar0] * Tdisp(0, -l/2, 0) * Trotz(q[1]) * Tdisp(0, -l/2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l/2, 0) * Trotz(q[2]) * Tdisp(0, -l/2, 0);
        TOG[bar3] = TOG[bar2] * Tdisp(0, -l/2, 0) * Trotz(q[3]) * Tdisp(0, -l/2, 0);
        TOG[bar4] = TOG[bar3] * Tdisp(0, -l/2, 0) * Trotz(q[4]) * Tdisp(0, -l/2, 0);
        TOG[bar5] = TOG[bar4] * Tdisp(0, -l/2, 0) * Trotz(q[5]) * Tdisp(0, -l/2, 0);
        TOG[bar6] = TOG[bar5] * Tdisp(0, -l/2, 0) * Trotz(q[6]) * Tdisp(0, -l/2, 0);
        TOG[bar7] = TOG[bar6] * Tdisp(0, -l/2, 0) * Trotz(q[7]) * Tdisp(0, -l/2, 0);
        TOG[bar8] = TOG[bar7] * Tdisp(0, -l/2, 0) * Trotz(q[8]) * Tdisp(0, -l/2, 0);
        TOG[bar9] = TOG[bar8] * Tdisp(0, -l/2, 0) * Trotz(q[9]) * Tdisp(0, -l/2, 0);
        TOG[bar10] = TOG[bar9] * Tdisp(0, -l/2, 0) * Trotz(q[10]) * Tdisp(0, -l/2, 0);
        TOG[bar11] = TOG[bar10] * Tdisp(0, -l/2, 0) * Trotz(q[11]) * Tdisp(0, -l/2, 0);
        TOG[bar12] = TOG[bar11] * Tdisp(0, -l/2, 0) * Trotz(q[12]) * Tdisp(0, -l/2, 0);
        TOG[bar13] = TOG[bar12] * Tdisp(0, -l/2, 0) * Trotz(q[13]) * Tdisp(0, -l/2, 0);
        TOG[bar14] = TOG[bar13] * Tdisp(0, -l/2, 0) * Trotz(q[14]) * Tdisp(0, -l/2, 0);
        TOG[bar15] = TOG[bar14] * Tdisp(0, -l/2, 0) * Trotz(q[15]) * Tdisp(0, -l/2, 0);
        TOG[bar16] = TOG[bar15] * Tdisp(0, -l/2, 0) * Trotz(q[16]) * Tdisp(0, -l/2, 0);
        TOG[bar17] = TOG[bar16] * Tdisp(0, -l/2, 0) * Trotz(q[17]) * Tdisp(0, -l/2, 0);
        TOG[bar18] = TOG[bar17] * Tdisp(0, -l/2, 0) * Trotz(q[18]) * Tdisp(0, -l/2, 0);
        TOG[bar19] = TOG[bar18] * Tdisp(0, -l/2, 0) * Trotz(q[19]) * Tdisp(0, -l/2, 0);
        TOG[bar20] = TOG[bar19] * Tdisp(0, -l/2, 0) * Trotz(q[20]) * Tdisp(0, -l/2, 0);
        TOG[bar21] = TOG[bar20] * Tdisp(0, -l/2, 0) * Trotz(q[21]) * Tdisp(0, -l/2, 0);
        TOG[bar22] = TOG[bar21] * Tdisp(0, -l/2, 0) * Trotz(q[22]) * Tdisp(0, -l/2, 0);
        TOG[bar23] = TOG[bar22] * Tdisp(0, -l/2, 0) * Trotz(q[23]) * Tdisp(0, -l/2, 0);
        gravity(0, -g, 0);
    }
}
