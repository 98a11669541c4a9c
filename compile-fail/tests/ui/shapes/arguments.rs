fn main() {}

mbs::multibody! {
    model Swing {
        dof a = 0.3;
        body bar { mass = 1.0; inertia = (0.1, 0.01, 0.1); }
        TOG[bar] = Trotz(a) * Tdisp(0, -0.5, 0);
        shape bar: box(0.05, 1);
        shape bar: cube(0.05, 1, 0.05);
        shape bar: sphere(0.05, colour = "#ff0000");
        shape bar: sphere(0.05, color = red);
        shape bar: sphere(0.05, color = "#12345g");
        shape bar: cylinder(0.02, 1, axis = w);
        shape bar: box(0.05, 1, 0.05, at = 0.5);
        shape bar: box(0.05, 1, 0.05, at = (0, 0, 0), at = (0, 1, 0));
        shape bar: line(from = (0, 0, 0));
        shape bar: line(from = (0, 0.5, 0), to = (0, 0.5, 0));
        shape bar: line((0, 0, 0), (0, 1, 0));
        gravity(0, -9.81, 0);
    }
}
