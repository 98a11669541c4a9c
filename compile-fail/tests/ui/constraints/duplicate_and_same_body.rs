fn main() {}

mbs::multibody! {
    model Loop {
        dof a = 0.1; dof b = 0.2;
        body bar1 { mass = 1.0; }
        body bar2 { mass = 1.0; }
        point p on bar1 at (0.5, 0, 0);
        point r on bar1 at (-0.5, 0, 0);
        TOG[bar1] = Trotz(a) * Tdisp(0.5, 0, 0);
        TOG[bar2] = Trotz(b) * Tdisp(0.5, 0, 0);
        constraint drive = a - 0.1;
        constraint drive = b - 0.2;
        constraint same: coincide(p, r);
    }
}
