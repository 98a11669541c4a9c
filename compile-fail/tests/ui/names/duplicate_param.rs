mbs::multibody! {
    model Pendulum {
        param l = 1.0; param l = 2.0;
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
    }
}

fn main() {}
