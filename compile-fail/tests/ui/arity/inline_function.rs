mbs::multibody! {
    model Pendulum {
        fn bump(x, h) = h * exp(-x * x);
        dof q[0] = 0.5;
        body bar { mass = 1.0; }
        TOG[bar] = Tdisp(q[0], bump(q[0]), 0);
    }
}

fn main() {}
