mbs::multibody! {
    model Legs {
        part Leg(k, hy) {
            dof a[k] = 0.0;
            body thigh[k] { mass = 1.0; inertia = (0.01, 0.01, 0.01); }
            TOG[thigh[k]] = Tdisp(0, hy, 0) * Troty(a[k]) * Tdisp(0, 0, -0.2);
        }
        Leg(0, 0.3);
        Leg(1);
    }
}

fn main() {}
