//! Rotation joints (`Tball`, `Tfree`) run through every orientation: the runtime re-centres
//! their charts before gimbal lock.

use mbs::{Model, Options, Scheme, StepControl, simulate};
use mbs_models::tumble::TumbleBall;

/// World angular momentum of the tumble's body: R · I · ω_body.
fn momentum(tr: &mbs::Trajectory, i: usize) -> [f64; 3] {
    let inertia = [1.7231e-4, 6.58e-6, 1.7243e-4];
    let q = tr.q(i);
    let qd = tr.qd(i);
    let w = mbs::charts::body_rates([q[0], q[1], q[2]], [qd[0], qd[1], qd[2]]);
    let r = tr.chart(i, 0);
    let e = mbs::charts::zyx([q[0], q[1], q[2]]);
    let rr: Vec<f64> = (0..9)
        .map(|k| (0..3).map(|m| r[k / 3][m] * e[(m, k % 3)]).sum())
        .collect();
    let l = [0, 1, 2].map(|k| inertia[k] * w[k]);
    [0, 1, 2].map(|i| (0..3).map(|k| rr[3 * i + k] * l[k]).sum())
}

#[test]
fn tumble_on_a_ball_joint_runs_through_its_flips() {
    for scheme in [Scheme::Dopri5, Scheme::Radau5] {
        let o = Options {
            t_end: 20.0,
            step: StepControl::Adaptive {
                rtol: 1e-10,
                atol: 1e-12,
                h0: None,
            },
            output: mbs::Output::Steps,
            ..Options::default()
        };
        let (tr, st) = simulate(TumbleBall::default(), scheme, o).unwrap();
        let e0 = tr.energy[0].total();
        let de = tr
            .energy
            .iter()
            .map(|e| (e.total() / e0 - 1.0).abs())
            .fold(0.0, f64::max);
        let l0 = momentum(&tr, 0);
        let n0 = l0.iter().map(|x| x * x).sum::<f64>().sqrt();
        let dl = (0..tr.len())
            .map(|i| {
                let l = momentum(&tr, i);
                (0..3).map(|k| (l[k] - l0[k]).powi(2)).sum::<f64>().sqrt() / n0
            })
            .fold(0.0, f64::max);
        println!(
            "{}: {} switches, dE {de:.2e}, dL {dl:.2e}\n{st}",
            scheme.name(),
            st.chart_switches
        );
        assert!(st.chart_switches > 0);
        assert!(de < 1e-8 && dl < 1e-8);
        let _ = TumbleBall::default().info();
    }
}
