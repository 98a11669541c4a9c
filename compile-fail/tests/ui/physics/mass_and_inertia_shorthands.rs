mbs::multibody! {
    model Shorthands {
        param l = 1.0;
        dof q[0] = 0.1;
        body bar { mass = 1.0; inertia_z = -0.1; }
        body arm { mass = 1.0; inertia = (0.1, 0.1, 0.1); inertia_z = 0.1; }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
        TOG[arm] = TOG[bar] * Tdisp(0, -l / 2, 0);
        mass tip on bar at (0, -l / 2, 0) = -0.5;
        mass fixed on ground at (0, 0, 0) = 0.5;
        mass stacked on tip at (0, 0, 0) = 0.5;
        mass flat on arm at (0, 0) = 0.5;
        frame sensor;
        TOG[sensor] = TOG[tip] * Tdisp(0, 0.1, 0);
    }
}

fn main() {}
