//! arm3d_6: spatial serial arm of six revolute joints (`tests/reference/MODELS.md`).
//! Used by `examples/arm3d_6.rs`, the tests and the benchmarks.

mbs::multibody! {
    /// Six revolute joints, axes z, y, z, y, z, y (each in the previous link's frame), links
    /// 0.3 m long along their x axis, 1 kg uniform boxes 0.3 × 0.05 × 0.05 m, gravity along −z.
    pub model Arm3d6 {
        param g = 9.81;
        param len = 0.3;
        param w = 0.05;
        param m = 1.0;
        // Uniform box len × w × w about its centroid, in the link frame.
        let ixx = m * (w * w + w * w) / 12;
        let iyy = m * (len * len + w * w) / 12;
        dof q[0] = 0.2; dof q[1] = 0.2; dof q[2] = 0.2;
        dof q[3] = 0.2; dof q[4] = 0.2; dof q[5] = 0.2;
        body link0 { mass = m; inertia = (ixx, iyy, iyy); }
        body link1 { mass = m; inertia = (ixx, iyy, iyy); }
        body link2 { mass = m; inertia = (ixx, iyy, iyy); }
        body link3 { mass = m; inertia = (ixx, iyy, iyy); }
        body link4 { mass = m; inertia = (ixx, iyy, iyy); }
        body link5 { mass = m; inertia = (ixx, iyy, iyy); }
        // TOG is at the centroid, (len/2, 0, 0) in the link frame; the next joint is at
        // (len, 0, 0), i.e. another len/2 further along x.
        TOG[link0] = Trotz(q[0]) * Tdisp(len / 2, 0, 0);
        TOG[link1] = TOG[link0] * Tdisp(len / 2, 0, 0) * Troty(q[1]) * Tdisp(len / 2, 0, 0);
        TOG[link2] = TOG[link1] * Tdisp(len / 2, 0, 0) * Trotz(q[2]) * Tdisp(len / 2, 0, 0);
        TOG[link3] = TOG[link2] * Tdisp(len / 2, 0, 0) * Troty(q[3]) * Tdisp(len / 2, 0, 0);
        TOG[link4] = TOG[link3] * Tdisp(len / 2, 0, 0) * Trotz(q[4]) * Tdisp(len / 2, 0, 0);
        TOG[link5] = TOG[link4] * Tdisp(len / 2, 0, 0) * Troty(q[5]) * Tdisp(len / 2, 0, 0);
        point tip on link5 at (len / 2, 0, 0);
        gravity(0, 0, -g);
    }
}
