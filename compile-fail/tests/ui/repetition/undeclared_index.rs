mbs::multibody! {
    model Chain {
        for i in 0..4 {
            dof q[i] = 0.1;
            body bar[i] { mass = 1.0; inertia = (0.02, 0, 0.02); }
        }
        TOG[bar[0]] = Trotz(q[0]);
        // one iteration too many: there is no bar[4]
        for i in 1..5 {
            TOG[bar[i]] = TOG[bar[i - 1]] * Tdisp(0, -0.5, 0) * Trotz(q[i]);
        }
    }
}

fn main() {}
