fn main() {}

mbs::multibody! {
    model Swing {
        dof a = 0.3;
        body bar { mass = 1.0; inertia = (0.1, 0.01, 0.1); }
        point tip on bar at (0, -0.5, 0);
        TOG[bar] = Trotz(a) * Tdisp(0, -0.5, 0);
        shape baar: box(0.05, 1, 0.05);
        shape tip: sphere(0.05);
        gravity(0, -9.81, 0);
    }
}
