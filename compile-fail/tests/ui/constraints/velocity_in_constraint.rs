fn main() {}

mbs::multibody! {
    model Driven {
        dof a = 0.1;
        body bar { mass = 1.0; inertia = (0, 0.1, 0.1); }
        TOG[bar] = Trotz(a) * Tdisp(0.5, 0, 0);
        constraint rolling = qd[0] - 2.0;
        constraint fixed = 2.0 * 0.5;
    }
}
