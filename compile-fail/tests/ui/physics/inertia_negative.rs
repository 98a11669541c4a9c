mbs::multibody! {
    model Pendulum {
        param m = 1.0; param l = 1.0;
        dof q[0] = 0.5;
        body bar { mass = m; inertia = (m * l * l / 12, 0, -m * l * l / 12); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
    }
}

fn main() {}
