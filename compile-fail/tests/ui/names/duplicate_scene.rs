mbs::multibody! {
    model Pendulum {
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        effect weight { gravity(0, -9.81, 0); }
        scene Swing = [weight];
        scene Swing = [];
    }
}

fn main() {}
