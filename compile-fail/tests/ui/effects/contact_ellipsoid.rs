mbs::multibody! {
    model Drop {
        param e = 1.5;
        dof z = 0.5;
        body ball { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        TOG[ball] = Tdisp(0, 0, z);
        contact(ball, k = 1e4, sphere = 0.1, ellipsoid = (0.1, 0.2, 0.3));
        contact(ball, k = 1e4, ellipsoid = (0.1, 0.0, 0.3));
        contact(ball, k = 1e4, ellipsoid = (0.1, 0.2));
        contact(ball, k = 1e4, ellipsoid = (0.1, 0.2, 0.3), exponent = 0.5);
        contact(ball, k = 1e4, ellipsoid = (0.1, 0.2, 0.3), exponent = e);
        contact(ball, k = 1e4, exponent = 1.5, dissipation = -1.0);
    }
}

fn main() {}
