mbs::multibody! {
    model Pendulum {
        param k = -50.0;
        dof x = 0.1;
        body cart { mass = 1.0; }
        TOG[cart] = Tdisp(x, 0, 0);
        spring(cart, ground, k = k, l0 = 0.0);
    }
}

fn main() {}
