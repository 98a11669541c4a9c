mbs::multibody! {
    model Top {
        dof x = 0.0; dof y = 0.0; dof z = 0.0;
        dof a = 0.0; dof b = 0.0; dof c = 0.0;
        body top { mass = 1.0; inertia = (0.1, 0.1, 0.2); }
        // an angle must be a coordinate, not an expression
        TOG[top] = Tball(2 * a, b, c) * Tdisp(0, 0, 0.1);
    }
}

mbs::multibody! {
    model Twice {
        dof a = 0.0; dof b = 0.0; dof c = 0.0;
        body top { mass = 1.0; inertia = (0.1, 0.1, 0.2); }
        // three different coordinates
        TOG[top] = Tball(a, b, a);
    }
}

mbs::multibody! {
    model Drone {
        dof x = 0.0; dof y = 0.0; dof z = 0.0;
        dof a = 0.0; dof b = 0.0; dof c = 0.0;
        body frame { mass = 1.0; inertia = (0.1, 0.1, 0.2); }
        // six arguments
        TOG[frame] = Tfree(x, y, a, b, c);
    }
}

mbs::multibody! {
    model Shared {
        dof a = 0.0; dof b = 0.0; dof c = 0.0; dof d = 0.0;
        body upper { mass = 1.0; inertia = (0.1, 0.1, 0.2); }
        body lower { mass = 1.0; inertia = (0.1, 0.1, 0.2); }
        TOG[upper] = Tball(a, b, c) * Tdisp(0, 0, -0.5);
        // a coordinate belongs to one joint
        TOG[lower] = TOG[upper] * Tdisp(0, 0, -0.5) * Tball(d, b, c);
    }
}

fn main() {}
