mbs::multibody! {
    model Pendulum {
        dof x = 0.1;
        body cart { mass = 1.0; }
        TOG[cart] = Tdisp(x, 0, 0);
        spring(cart, ground, k = 10.0, rest = 0.5);
    }
}

fn main() {}
