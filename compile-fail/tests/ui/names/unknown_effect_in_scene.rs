mbs::multibody! {
    model Pendulum {
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        effect weight { gravity(0, -9.81, 0); }
        effect friction { generalized_force(q[0], -0.1 * qd[0]); }
        scene Swing = [wieght];
        scene Full = [weight, friction, air_drag];
    }
}

fn main() {}
