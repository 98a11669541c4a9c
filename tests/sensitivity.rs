//! Parameter sensitivities: the generated ∂τ/∂p of parameters marked `sensitive`, and
//! dq_eq/dp of statics, against central differences.

use mbs::analysis::{StaticsOptions, static_equilibrium, static_sensitivity};
use mbs::{Model, ModelError, Parameters};
use mbs_models::sprung_arm::SprungArm;

mbs::multibody! {
    /// The same arm without sensitive parameters.
    pub model PlainArm {
        param l = 0.8; param m = 1.5;
        dof a = 0.4;
        body bar1 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        TOG[bar1] = Trotz(a) * Tdisp(l / 2, 0, 0);
        gravity(0, -9.81, 0);
        rotational_spring(ground, bar1, axis = z, k = 40, angle0 = 0.6);
    }
}

fn with(name: &str, value: f64) -> SprungArm {
    let mut model = SprungArm::default();
    let mut p = model.params().clone();
    p.set(name, value).unwrap();
    model.set_params(p).unwrap();
    model
}

#[test]
fn generated_parameter_tangents_match_central_differences() {
    assert_eq!(SprungArm::SENSITIVE, ["l", "m", "k1"]);
    let (t, q, qd, qdd) = (0.0, [0.7, -0.4], [1.3, -0.8], [2.0, 5.0]);
    let model = SprungArm::default();
    let mut dtau = [0.0; 6];
    model
        .parameter_tangents(t, &q, &qd, &qdd, &[], &mut dtau)
        .unwrap();
    for (j, name) in SprungArm::SENSITIVE.iter().enumerate() {
        let p0 = model.params().values()[j];
        let e = 1e-5 * p0;
        let (mut tp, mut tm) = ([0.0; 2], [0.0; 2]);
        with(name, p0 + e).inverse_dynamics(t, &q, &qd, &qdd, &[], &mut tp);
        with(name, p0 - e).inverse_dynamics(t, &q, &qd, &qdd, &[], &mut tm);
        for i in 0..2 {
            let diff = (tp[i] - tm[i]) / (2.0 * e);
            let exact = dtau[i + 2 * j];
            assert!(
                (exact - diff).abs() <= 1e-7 * exact.abs().max(1.0),
                "∂τ{i}/∂{name}: generated {exact}, differences {diff}"
            );
        }
        assert!(
            dtau[2 * j..2 * j + 2].iter().any(|x| x.abs() > 1e-3),
            "{name}"
        );
    }
    // without sensitive parameters: a typed error that says what to write
    let e = PlainArm::default()
        .parameter_tangents(t, &q[..1], &qd[..1], &qdd[..1], &[], &mut [0.0; 1])
        .unwrap_err();
    assert!(matches!(e, ModelError::NoSensitiveParameters { .. }));
    assert!(e.to_string().contains("sensitive;"), "{e}");
}

#[test]
fn equilibria_move_with_the_parameters_as_differences_say() {
    let options = StaticsOptions {
        tolerance: 1e-13,
        ..StaticsOptions::default()
    };
    let model = SprungArm::default();
    let eq = static_equilibrium(&model, &options).unwrap();
    let s = static_sensitivity(&model, &eq, &options).unwrap();
    assert_eq!(s.params, ["l", "m", "k1"]);
    for (j, name) in s.params.iter().enumerate() {
        let p0 = model.params().values()[j];
        let e = 1e-4 * p0;
        let start = StaticsOptions {
            q0: Some(eq.q.clone()),
            ..options.clone()
        };
        let qp = static_equilibrium(&with(name, p0 + e), &start).unwrap().q;
        let qm = static_equilibrium(&with(name, p0 - e), &start).unwrap().q;
        for i in 0..2 {
            let diff = (qp[i] - qm[i]) / (2.0 * e);
            let exact = s.get(i, name).unwrap();
            println!("∂q{i}/∂{name}: {exact:.10} (differences {diff:.10})");
            assert!(
                (exact - diff).abs() <= 1e-6 * exact.abs().max(1e-3),
                "∂q{i}/∂{name}: {exact} vs {diff}"
            );
        }
    }
    // a locked coordinate does not move
    let locked = StaticsOptions {
        locked: vec![1],
        ..options.clone()
    };
    let eq = static_equilibrium(&model, &locked).unwrap();
    let s = static_sensitivity(&model, &eq, &locked).unwrap();
    assert!((0..3).all(|j| s.dq_dp[1 + 2 * j] == 0.0));
    assert!(s.get(0, "k1").unwrap() != 0.0);
}

/// q(t_end), qd(t_end) of a plain run at tight tolerances.
fn end_state(model: SprungArm, t_end: f64) -> (Vec<f64>, Vec<f64>) {
    let options = mbs::Options {
        t_end,
        step: mbs::StepControl::Adaptive {
            rtol: 1e-12,
            atol: 1e-14,
            h0: None,
        },
        output: mbs::Output::Last,
        ..mbs::Options::default()
    };
    let (tr, _) = mbs::simulate(model, mbs::Scheme::Dopri5, options).unwrap();
    let last = tr.len() - 1;
    (tr.q(last).to_vec(), tr.qd(last).to_vec())
}

#[test]
fn sensitivities_integrated_with_the_motion_match_central_differences() {
    use mbs::{Options, Output, Scheme, Sensitivities, StepControl, simulate};
    let t_end = 2.0;
    // the reference: central differences of plain runs
    let base = SprungArm::default();
    let mut reference = Vec::new();
    for (j, name) in SprungArm::SENSITIVE.iter().enumerate() {
        let p0 = base.params().values()[j];
        let e = 1e-5 * p0;
        let (qp, vp) = end_state(with(name, p0 + e), t_end);
        let (qm, vm) = end_state(with(name, p0 - e), t_end);
        let d = |a: &[f64], b: &[f64]| -> Vec<f64> {
            a.iter().zip(b).map(|(x, y)| (x - y) / (2.0 * e)).collect()
        };
        reference.push((d(&qp, &qm), d(&vp, &vm)));
    }
    let options = Options {
        t_end,
        step: StepControl::Adaptive {
            rtol: 1e-10,
            atol: 1e-12,
            h0: None,
        },
        output: Output::Last,
        ..Options::default()
    };
    for scheme in [
        Scheme::Dopri5,
        Scheme::Radau5,
        Scheme::Bdf(Default::default()),
    ] {
        let model = Sensitivities::new(SprungArm::default()).unwrap();
        assert_eq!(model.info().dofs[3], "∂b/∂l");
        let (tr, stats) = simulate(model, scheme, options.clone()).unwrap();
        let (_, plain) = simulate(SprungArm::default(), scheme, options.clone()).unwrap();
        let last = tr.len() - 1;
        let mut worst: f64 = 0.0;
        for (j, (dq, dv)) in reference.iter().enumerate() {
            let sq = Sensitivities::<SprungArm>::dq_dp(&tr, last, j);
            let sv = Sensitivities::<SprungArm>::dqd_dp(&tr, last, j);
            let scale = dq.iter().chain(dv).fold(0.0f64, |m, x| m.max(x.abs()));
            for (exact, diff) in sq.iter().zip(dq).chain(sv.iter().zip(dv)) {
                worst = worst.max((exact - diff).abs() / scale);
            }
        }
        println!(
            "{}: worst |s − differences| / max|s| = {worst:.1e}; {} steps with sensitivities, {} without",
            scheme.name(),
            stats.steps,
            plain.steps
        );
        assert!(worst < 1e-6, "{}: {worst:e}", scheme.name());
    }
}

#[test]
fn sensitivities_refuse_models_they_cannot_differentiate() {
    let Err(e) = mbs::Sensitivities::new(PlainArm::default()) else {
        panic!("accepted")
    };
    assert!(matches!(e, ModelError::NoSensitiveParameters { .. }), "{e}");
}
