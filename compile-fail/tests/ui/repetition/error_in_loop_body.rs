mbs::multibody! {
    model Chain {
        param l = 0.5;
        for i in 0..4 {
            dof q[i] = 0.1;
            // the third bar gets no mass
            body bar[i] { mass = 1.0 * (i - 2) * (i - 2); inertia = (0.02, 0, 0.02); }
        }
        TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
        for i in 1..4 {
            TOG[bar[i]] = TOG[bar[i - 1]] * Tdisp(0, -l, 0) * Trotz(q[i]);
        }
    }
}

fn main() {}
