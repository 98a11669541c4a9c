mbs::multibody! {
    model Pendulum {
        extern fn drag = [f64::tanh];
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        generalized_force(q[0], -drag(qd[0]));
        option tangents;
    }
}

fn main() {}
