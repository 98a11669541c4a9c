use mbs::Model;

mbs::multibody! {
    model Swing {
        dof a = 0.3;
        body bar { mass = 1.0; inertia = (0.1, 0.01, 0.1); }
        TOG[bar] = Trotz(a) * Tdisp(0, -0.5, 0);
        shape bar box(0.05, 1, 0.05);
        shape bar: 0.05;
        gravity(0, -9.81, 0);
    }
}

fn main() {
    // the model's types still exist: no error here
    let _ = Swing::default().info();
}
