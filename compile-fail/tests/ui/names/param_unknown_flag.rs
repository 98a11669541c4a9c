mbs::multibody! {
    pub model Spring {
        param k = 100.0 sensitiv;
        dof x = 0.1;
        body mass { mass = 1.0; }
        TOG[mass] = Tdisp(x, 0, 0);
        spring(ground, mass, k = k, l0 = 0.0);
    }
}

fn main() {}
