mbs::multibody! {
    model Hip {
        param k = 10.0;
        dof a = 0.0; dof b = 0.0; dof c = 0.0; dof knee = 0.0;
        body thigh { mass = 1.0; inertia = (0.1, 0.1, 0.02); }
        body shank { mass = 1.0; inertia = (0.1, 0.1, 0.02); }
        TOG[thigh] = Tball(a, b, c) * Tdisp(0, 0, -0.2);
        // the angles of a ball joint have no fixed meaning: not in a force, a rate, a pose
        TOG[shank] = TOG[thigh] * Tdisp(0, 0, -0.2) * Troty(knee + b) * Tdisp(0, 0, -0.2);
        generalized_force(b, -k * b);
        generalized_force(knee, -k * qd[a]);
    }
}

fn main() {}
