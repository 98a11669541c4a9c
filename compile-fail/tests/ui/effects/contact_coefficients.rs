mbs::multibody! {
    model Drop {
        dof z = 0.5;
        body ball { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        TOG[ball] = Tdisp(0, 0, z);
        contact(ball, k = 0, c = -1.0, mu = -0.2, eps = 0);
        contact(ball, k = 1e4, mu = 0.1 * qd[0]);
    }
}

fn main() {}
