// A body named `u` is reported once, not again where it is used.
mbs::multibody! {
    model Pendulum {
        dof q[0] = 0.5;
        body u { mass = 1.0; inertia_z = 0.1; }
        TOG[u] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        spring(ground, u, k = 10.0, l0 = 0.2);
    }
}

fn main() {}
