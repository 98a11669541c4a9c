// `mass NAME on BODY at (x, y, z) = m;` written wrong.
mbs::multibody! {
    model Lumped {
        dof q[0] = 0.1;
        body bar { mass = 1.0; inertia_z = 0.1; }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        mass tip at bar (0, -0.5, 0) = 0.5;
        mass tip on bar (0, -0.5, 0) = 0.5;
        mass tip on bar at 0.5 = 0.5;
        mass tip on bar at (0, -0.5, 0);
    }
}

fn main() {}
