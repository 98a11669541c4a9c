mbs::multibody! {
    model Pendulum {
        param l = 1.0;
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (l^2 / 12, 0.0, l^2 / 12); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
    }
}

fn main() {}
