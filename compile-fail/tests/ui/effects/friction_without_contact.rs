mbs::multibody! {
    model Slide {
        dof x = 0.0;
        body block { mass = 1.0; }
        TOG[block] = Tdisp(x, 0, 0);
        friction(block, mu = 0.3);
        contact(block, k = 1e4, eps = 1e-3);
    }
}

fn main() {}
