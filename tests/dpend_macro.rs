use mbs::Model;

mbs::multibody! {
    /// Planar double pendulum of two uniform bars.
    pub model DoublePendulum {
        param l = 1.0; param m = 1.0; param g = 9.81;
        dof q[0] = PI / 2; dof q[1] = 0.0;
        body bar1 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar2 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        TOG[bar1] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l/2, 0) * Trotz(q[1]) * Tdisp(0, -l/2, 0);
        gravity(0, -g, 0);
    }
}

#[test]
fn dpend_compiles_and_matches() {
    let model = DoublePendulum::default();
    let q = [0.19470917115432526, 0.4958324052262343];
    let qd = [0.6860466044888691, 0.3175172849979041];
    let mut m = [0.0; 4];
    let mut h = [0.0; 2];
    model.dynamics(0.0, &q, &qd, &[], &mut m, &mut h);
    assert!((m[0] - 2.546239652854929).abs() < 1e-12);
    assert!((h[0] + 5.843720128970542).abs() < 1e-12, "{h:?}");
}
