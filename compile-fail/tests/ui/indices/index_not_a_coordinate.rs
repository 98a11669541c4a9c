mbs::multibody! {
    model Pendulum {
        param k = 0.0;
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[k]) * Tdisp(0, -0.5, 0);
    }
}

fn main() {}
