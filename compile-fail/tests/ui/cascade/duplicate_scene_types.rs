use mbs::Model;

mbs::multibody! {
    model Pendulum {
        dof q[0] = 0.5;
        body bar { mass = 1.0; inertia = (0.1, 0.0, 0.1); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        effect weight { gravity(0, -9.81, 0); }
        scene Swing = [weight];
        scene Swing = [];
    }
}

fn main() {
    let model = PendulumSwing::default();
    let mut m = [0.0; PendulumSwing::NQ * PendulumSwing::NQ];
    model.mass_matrix(0.0, &[0.2], &mut m);
}
