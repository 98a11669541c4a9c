mbs::multibody! {
    model Pendulum {
        let a = b / 2;
        let b = a + 1;
        dof x = 0.1;
        body cart { mass = 1.0; }
        TOG[cart] = Tdisp(x + a, 0, 0);
    }
}

fn main() {}
