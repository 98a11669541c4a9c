mbs::multibody! {
    model Pendulum {
        param c = 0.1;
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        generalized_force(c, -c * qd[0]);
    }
}

fn main() {}
