// Poses that start from each other form a cycle, named as such.
mbs::multibody! {
    model Loop {
        dof q[0] = 0.1;
        body a { mass = 1.0; inertia = (0.01, 0.0, 0.01); }
        body b { mass = 1.0; inertia = (0.01, 0.0, 0.01); }
        body c { mass = 1.0; inertia = (0.01, 0.0, 0.01); }
        TOG[a] = TOG[c] * Trotz(q[0]) * Tdisp(0, -0.5, 0);
        TOG[b] = TOG[a] * Tdisp(0, -0.5, 0);
        TOG[c] = TOG[b] * Tdisp(0, -0.5, 0);
    }
}

fn main() {}
