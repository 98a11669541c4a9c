mbs::multibody! {
    model Pendulum {
        dof q[0] = 0.5; dof q[2] = 0.0;
        body bar1 { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        body bar2 { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar1] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -0.5, 0) * Trotz(q[1]) * Tdisp(0, -0.5, 0);
    }
}

fn main() {}
