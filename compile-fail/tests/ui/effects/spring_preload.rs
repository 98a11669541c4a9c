mbs::multibody! {
    model Hang {
        dof z = -1.0;
        body mass1 { mass = 1.0; }
        TOG[mass1] = Tdisp(0, 0, z);
        spring(ground, mass1, k = 100.0, l0 = 0.5, preload = 10.0 * z);
        damper(ground, mass1, c = 1.0, preload = 5.0);
        generalized_force(z, -1e3 * pos(z, 0.1));
    }
}

fn main() {}
