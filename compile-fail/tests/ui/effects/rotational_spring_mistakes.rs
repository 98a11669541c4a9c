mbs::multibody! {
    model Hinge {
        param k = 2.0;
        dof q[0] = 0.1; dof q[1] = 0.2;
        body bar { mass = 1.0; inertia_z = 0.1; }
        body arm { mass = 1.0; inertia_z = 0.1; }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        TOG[arm] = TOG[bar] * Trotz(q[1]) * Tdisp(0, -0.5, 0);
        rotational_spring(bar, bar, axis = z, k = k);
        rotational_spring(ground, bar, k = k);
        rotational_spring(ground, bar, axis = w, k = k);
        rotational_spring(bar, arm, axis = z, c = 0.1);
        rotational_spring(bar, arm, axis = z, k = -1.0);
        rotational_spring(bar, arm, axis = z, k = k * qd[0]);
        rotational_spring(arm, axis = z, k = k);
        rotational_damper(bar, arm, axis = z);
        rotational_damper(bar, arm, axis = z, c = 0.1, k = k);
    }
}

fn main() {}
