mbs::multibody! {
    model Pendulum {
        fn sin(x) = x - x * x * x / 6;
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[0]) * Tdisp(sin(q[0]), -0.5, 0);
    }
}

fn main() {}
