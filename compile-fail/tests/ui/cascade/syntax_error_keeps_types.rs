use mbs::Model;

mbs::multibody! {
    model Pendulum {
        param l = 1.0;
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        joint hinge;
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
    }
}

fn main() {
    let model = Pendulum::new(PendulumParams { l: 0.5 }).unwrap();
    let mut m = [0.0; 1];
    model.mass_matrix(0.0, &[0.2], &mut m);
}
