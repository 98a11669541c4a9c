mbs::multibody! {
    model Drop {
        dof z = 0.5;
        body ball { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        point mark on ground at (0, 0, 0.1);
        TOG[ball] = Tdisp(0, 0, z);
        contact(ground, k = 1e4);
        contact(mark, k = 1e4);
        contact(ball, mark, k = 1e4);
    }
}

fn main() {}
