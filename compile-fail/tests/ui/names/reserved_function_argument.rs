mbs::multibody! {
    model Pendulum {
        fn wave(t) = sin(2 * t);
        dof x = 0.1;
        body cart { mass = 1.0; }
        TOG[cart] = Tdisp(x + wave(x), 0, 0);
    }
}

fn main() {}
