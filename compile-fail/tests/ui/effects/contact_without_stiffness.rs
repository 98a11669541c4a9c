mbs::multibody! {
    model Drop {
        dof z = 0.5;
        body ball { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        TOG[ball] = Tdisp(0, 0, z);
        contact(ball, sphere = 0.1, c = 20.0);
    }
}

fn main() {}
