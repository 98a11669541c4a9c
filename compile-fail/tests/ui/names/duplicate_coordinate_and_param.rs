mbs::multibody! {
    model Pendulum {
        param x = 1.0;
        dof x = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(x) * Tdisp(0, -0.5, 0);
    }
}

fn main() {}
