mbs::multibody! {
    model Legs {
        part Leg(k, hy, m) {
            dof a[k] = 0.0;
            body thigh[k] { mass = m; inertia = (0.01, 0.01, 0.01); }
            TOG[thigh[k]] = Tdisp(0, hy, 0) * Troty(a[k]) * Tdisp(0, 0, -0.2);
        }
        Leg(0, 0.3, 1.0);
        Leg(1, -0.3, 1.0);
        Leg(2, 0.0, -1.0);
    }
}

fn main() {}
