mbs::multibody! {
    model Chain {
        for i in 0..3 {
            dof q[i] = 0.1;
            body bar[i] { mass = 1.0; inertia = (0.02, 0, 0.02); }
        }
        TOG[bar[0]] = Trotz(q[0]);
        TOG[bar[1]] = TOG[barr[0]] * Tdisp(0, -0.5, 0) * Trotz(q[1]);
        TOG[bar[2]] = TOG[bar[1]] * Tdisp(0, -0.5, 0) * Trotz(q[2]);
    }
}

fn main() {}
