mbs::multibody! {
    model Chain {
        param k = 1.0;
        dof q[0] = 0.1;
        body bar[k] { mass = 1.0; inertia = (0.02, 0, 0.02); }
        TOG[bar[k]] = Trotz(q[0]);
    }
}

fn main() {}
