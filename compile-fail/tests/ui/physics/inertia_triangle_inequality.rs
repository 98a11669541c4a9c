mbs::multibody! {
    model Pendulum {
        dof q[0] = 0.5;
        body plate { mass = 1.0; inertia = (0.1, 0.1, 0.3); }
        TOG[plate] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
    }
}

fn main() {}
