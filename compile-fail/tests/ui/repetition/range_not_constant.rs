mbs::multibody! {
    model Chain {
        param n = 3.0;
        for i in 0..n {
            dof q[i] = 0.1;
        }
    }
}

fn main() {}
