mbs::multibody! {
    model Pendulum {
        extern fn track = [f64::sin, f64::cos];
        dof q[0] = 0.5;
        body bar { mass = 1.0; }
        TOG[bar] = Tdisp(q[0], track(q[0], 2.0), 0);
    }
}

fn main() {}
