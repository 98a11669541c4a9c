mbs::multibody! {
    model Pendulum {
        dof x = 0.1;
        body cart { mass = 1.0; }
        TOG[cart] = Tdisp(x, 0, 0);
        damper(cart, ground, c = -0.5);
    }
}

fn main() {}
