use mbs::{Model, Parameters};

mbs::multibody! {
    model Pendulum {
        param l = 1.0; param m = 1.0;
        dof q[0] = 0.5;
        body bar { mass = m; inertia = (m * l * l / 12, 0.0, m * l * l / 12); }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -lenght / 2, 0);
        gravity(0, -9.81, 0);
    }
}

fn main() {
    let params = PendulumParams { l: 2.0, ..PendulumParams::default() };
    params.validate().unwrap();
    let model = Pendulum::new(params).unwrap();
    let mut q = [0.0; Pendulum::NQ];
    let mut qd = [0.0; Pendulum::NQ];
    model.initial_state(&mut q, &mut qd);
    let (mut m, mut h) = ([0.0; 1], [0.0; 1]);
    model.dynamics(0.0, &q, &qd, &[], &mut m, &mut h);
    println!("{} {:?} {}", model.info().name, m, model.energy(0.0, &q, &qd).total());
}
