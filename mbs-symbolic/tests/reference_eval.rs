#![allow(clippy::needless_range_loop)]
//! Reference models evaluated on the DAG (no emission involved).

use mbs_symbolic::expr::SliceEnv;
use mbs_symbolic::{SymbolicModel, systems_from_str};

fn test_state(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n).map(|i| 0.5 * (1.3 * i as f64 + 0.4).sin()).collect();
    let qd = (0..n).map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos()).collect();
    (q, qd)
}

#[test]
fn dpend_matches_reference_at_test_state() {
    let src = r#"
        model DoublePendulum {
            param l = 1.0; param m = 1.0; param g = 9.81;
            dof q[0] = PI / 2; dof q[1] = 0.0;
            body bar1 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
            body bar2 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
            TOG[bar1] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
            TOG[bar2] = TOG[bar1] * Tdisp(0, -l/2, 0) * Trotz(q[1]) * Tdisp(0, -l/2, 0);
            gravity(0, -g, 0);
        }
    "#;
    let sys = systems_from_str(src).unwrap().remove(0);
    let params = sys.param_defaults();
    let model = SymbolicModel::build(sys);
    let (q, qd) = test_state(2);
    let env = SliceEnv {
        q: &q,
        qd: &qd,
        params: &params,
        ..SliceEnv::default()
    };
    let m_ref = [
        [2.546239652854929, 0.7731198264274626],
        [0.7731198264274626, 0.333333333333333],
    ];
    let f_ref = [-5.843720128970542, -3.236224706838456];
    let eq = &model.scenes[0];
    let vp = eq.vp.as_ref().expect("a small model builds virtual power");
    for mb in [vp, &eq.rec] {
        let a = &model.sys.arena;
        for i in 0..2 {
            for j in 0..2 {
                let v = a.eval(&[mb.m[i][j]], &env)[0];
                assert!((v - m_ref[i][j]).abs() < 1e-12, "M[{i}][{j}] = {v}");
            }
            let h = a.eval(&[mb.h[i]], &env)[0];
            assert!((h - f_ref[i]).abs() < 1e-12, "h[{i}] = {h} vs {}", f_ref[i]);
        }
    }
}
