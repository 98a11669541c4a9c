fn main() {}

mbs::multibody! {
    model Swing {
        param r = 0.0; param l = 1.0;
        dof a = 0.3;
        body bar { mass = 1.0; inertia = (0.1, 0.01, 0.1); }
        TOG[bar] = Trotz(a) * Tdisp(0, -l / 2, 0);
        shape bar: box(0.05, -l, 0.05);
        shape bar: sphere(0);
        shape bar: cylinder(r, l, axis = y);
        shape bar: box(0.05, l * a, 0.05);
        shape bar: sphere(0.05, at = (0, -l / 2 - t, 0));
        gravity(0, -9.81, 0);
    }
}
