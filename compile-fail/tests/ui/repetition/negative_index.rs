mbs::multibody! {
    model Chain {
        for i in 0..3 {
            dof q[i] = 0.1;
            body bar[i] { mass = 1.0; inertia = (0.02, 0, 0.02); }
            TOG[bar[i]] = TOG[bar[i - 1]] * Tdisp(0, -0.5, 0) * Trotz(q[i]);
        }
    }
}

fn main() {}
