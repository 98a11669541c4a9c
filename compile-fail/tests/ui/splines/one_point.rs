mbs::multibody! {
    model Knee {
        dof knee = 0.5;
        body shank { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[shank] = Tdisp(spline(knee, [(0.0, 0.0)]), 0, 0) * Trotz(knee) * Tdisp(0, -0.5, 0);
    }
}

fn main() {}
