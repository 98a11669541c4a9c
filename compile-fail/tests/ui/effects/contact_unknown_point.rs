mbs::multibody! {
    model Drop {
        dof z = 0.5;
        body box1 { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        point corner on box1 at (0.1, 0.1, -0.1);
        TOG[box1] = Tdisp(0, 0, z);
        contact(coner, k = 1e4);
    }
}

fn main() {}
