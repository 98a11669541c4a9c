fn main() {}

mbs::multibody! {
    model Loop {
        dof a = 0.1; dof b = 0.2;
        body bar1 { mass = 1.0; }
        body bar2 { mass = 1.0; }
        TOG[bar1] = Trotz(a) * Tdisp(0.5, 0, 0);
        TOG[bar2] = Trotz(b) * Tdisp(0.5, 0, 0);
        constraint pin: meet(bar1, bar2);
    }
}
