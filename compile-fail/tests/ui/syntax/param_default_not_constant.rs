mbs::multibody! {
    model Pendulum {
        param l = 1.0;
        param m = 2.0 * l;
        param phase = q[0];
        dof q[0] = 0.5;
        body bar { mass = m; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[0] + phase) * Tdisp(0, -l / 2, 0);
    }
}

fn main() {}
