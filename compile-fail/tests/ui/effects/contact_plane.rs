mbs::multibody! {
    model Drop {
        dof z = 0.5;
        body ball { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        TOG[ball] = Tdisp(0, 0, z);
        contact(ball, k = 1e4, plane = (0, 0, 2));
        contact(ball, k = 1e4, plane = w);
        contact(ball, k = 1e4, plane = (0, 1));
    }
}

fn main() {}
