mbs::multibody! {
    model Pendulum {
        param t = 1.0;
        dof q[0] = 0.5;
        body ground { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[ground] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
    }
}

fn main() {}
