mbs::multibody! {
    model Pendulum {
        extern fn g = [profile::g, profile::g_d, profile::g_dd];
        dof q[0] = 0.5;
        body slider { mass = 1.0; }
        TOG[slider] = Tdisp(g(q[0]), 0, 0);
    }
}

fn main() {}
