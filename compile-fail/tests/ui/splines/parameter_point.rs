mbs::multibody! {
    model Knee {
        param y1 = 0.1;
        fn g(a) = spline(a, [(0.0, 0.0), (0.5, y1), (1.0, 0.2)]);
        dof knee = 0.5;
        body shank { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[shank] = Tdisp(g(knee), 0, 0) * Trotz(knee) * Tdisp(0, -0.5, 0);
    }
}

fn main() {}
