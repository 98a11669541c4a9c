mbs::multibody! {
    model Pendulum {
        extern fn g = [f64::sin];
        dof q[0] = 0.5;
        body slider { mass = 1.0; }
        TOG[slider] = Tdisp(g(q[0]), 0, 0);
    }
}

fn main() {}
