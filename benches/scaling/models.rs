//! The chains and arms of the scaling benchmark that `mbs-models` lacks: planar chains of 2,
//! 4, 16 and 32 uniform bars (as `chain8` and `chain24`: l = 0.5 m, 1 kg, hinged about +z,
//! q(0) = 0.3 rad), and spatial arms of 12 and 24 revolute joints (as `arm3d_6`: axes z, y
//! alternating, 0.3 m boxes of 1 kg, q(0) = 0.2 rad).

mbs::multibody! {
    /// Planar chain of 2 uniform bars.
    pub model Chain2 {
        param l = 0.5; param m = 1.0; param g = 9.81;
        for i in 0..2 {
            dof q[i] = 0.3;
            body bar[i] { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        }
        TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        TOG[bar[1]] = TOG[bar[0]] * Tdisp(0, -l/2, 0) * Trotz(q[1]) * Tdisp(0, -l/2, 0);
        gravity(0, -g, 0);
    }
}

mbs::multibody! {
    /// Planar chain of 4 uniform bars.
    pub model Chain4 {
        param l = 0.5; param m = 1.0; param g = 9.81;
        for i in 0..4 {
            dof q[i] = 0.3;
            body bar[i] { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        }
        TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        for i in 1..4 {
            TOG[bar[i]] = TOG[bar[i-1]] * Tdisp(0, -l/2, 0) * Trotz(q[i]) * Tdisp(0, -l/2, 0);
        }
        gravity(0, -g, 0);
    }
}

mbs::multibody! {
    /// Planar chain of 16 uniform bars.
    pub model Chain16 {
        param l = 0.5; param m = 1.0; param g = 9.81;
        for i in 0..16 {
            dof q[i] = 0.3;
            body bar[i] { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        }
        TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        for i in 1..16 {
            TOG[bar[i]] = TOG[bar[i-1]] * Tdisp(0, -l/2, 0) * Trotz(q[i]) * Tdisp(0, -l/2, 0);
        }
        gravity(0, -g, 0);
    }
}

mbs::multibody! {
    /// Planar chain of 32 uniform bars.
    pub model Chain32 {
        param l = 0.5; param m = 1.0; param g = 9.81;
        for i in 0..32 {
            dof q[i] = 0.3;
            body bar[i] { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        }
        TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        for i in 1..32 {
            TOG[bar[i]] = TOG[bar[i-1]] * Tdisp(0, -l/2, 0) * Trotz(q[i]) * Tdisp(0, -l/2, 0);
        }
        gravity(0, -g, 0);
    }
}

mbs::multibody! {
    /// Spatial arm of 12 revolute joints, axes z, y, z, y… each in the previous link's frame.
    pub model Arm3d12 {
        param g = 9.81; param len = 0.3; param w = 0.05; param m = 1.0;
        let ixx = m * (w * w + w * w) / 12;
        let iyy = m * (len * len + w * w) / 12;
        for i in 0..12 {
            dof q[i] = 0.2;
            body link[i] { mass = m; inertia = (ixx, iyy, iyy); }
        }
        TOG[link[0]] = Trotz(q[0]) * Tdisp(len / 2, 0, 0);
        for k in 0..5 {
            TOG[link[2*k+1]] = TOG[link[2*k]] * Tdisp(len / 2, 0, 0) * Troty(q[2*k+1]) * Tdisp(len / 2, 0, 0);
            TOG[link[2*k+2]] = TOG[link[2*k+1]] * Tdisp(len / 2, 0, 0) * Trotz(q[2*k+2]) * Tdisp(len / 2, 0, 0);
        }
        TOG[link[11]] = TOG[link[10]] * Tdisp(len / 2, 0, 0) * Troty(q[11]) * Tdisp(len / 2, 0, 0);
        gravity(0, 0, -g);
    }
}

mbs::multibody! {
    /// Spatial arm of 24 revolute joints, axes z, y, z, y… each in the previous link's frame.
    pub model Arm3d24 {
        param g = 9.81; param len = 0.3; param w = 0.05; param m = 1.0;
        let ixx = m * (w * w + w * w) / 12;
        let iyy = m * (len * len + w * w) / 12;
        for i in 0..24 {
            dof q[i] = 0.2;
            body link[i] { mass = m; inertia = (ixx, iyy, iyy); }
        }
        TOG[link[0]] = Trotz(q[0]) * Tdisp(len / 2, 0, 0);
        for k in 0..11 {
            TOG[link[2*k+1]] = TOG[link[2*k]] * Tdisp(len / 2, 0, 0) * Troty(q[2*k+1]) * Tdisp(len / 2, 0, 0);
            TOG[link[2*k+2]] = TOG[link[2*k+1]] * Tdisp(len / 2, 0, 0) * Trotz(q[2*k+2]) * Tdisp(len / 2, 0, 0);
        }
        TOG[link[23]] = TOG[link[22]] * Tdisp(len / 2, 0, 0) * Troty(q[23]) * Tdisp(len / 2, 0, 0);
        gravity(0, 0, -g);
    }
}
