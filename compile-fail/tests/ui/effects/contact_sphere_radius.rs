mbs::multibody! {
    model Drop {
        param r = 0.0;
        dof z = 0.5;
        body ball { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        TOG[ball] = Tdisp(0, 0, z);
        contact(ball, k = 1e4, sphere = -0.1);
        contact(ball, k = 1e4, sphere = r);
        contact(ball, k = 1e4, sphere = 0.1 + z);
    }
}

fn main() {}
