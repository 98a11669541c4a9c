//! Parameter sensitivities: the generated ∂τ/∂p of parameters marked `sensitive`, and
//! dq_eq/dp of statics, against central differences.

use mbs::analysis::{StaticsOptions, static_equilibrium, static_sensitivity};
use mbs::{Model, ModelError, Parameters};
use mbs_models::fourbar::SensitiveFourBar;
use mbs_models::sprung_arm::SprungArm;

#[macro_use]
#[path = "common/delegating.rs"]
mod delegating;
#[path = "common/oscillators.rs"]
mod oscillators;
#[path = "common/quoted.rs"]
mod quoted;
use oscillators::Oscillators;

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

mbs::multibody! {
    /// A mass on a spring (ω = 10 rad/s) started at x0 with speed v0, both sensitive, and a
    /// force input (zero unless a controller sets it): x(t) =
    /// x0 cos ωt + (v0/ω) sin ωt, so dx/dx0 = cos ωt and dx/dv0 = sin(ωt)/ω.
    pub model StartedSpring {
        param x0 = 0.1 sensitive; param v0 = 0.5 sensitive; param k = 100.0;
        option tangents;
        dof x = x0, qd = v0;
        input push;
        body a { mass = 1.0; inertia = (0.01, 0.01, 0.01); }
        TOG[a] = Tdisp(x, 0, 0);
        generalized_force(x, -k * x + push);
    }
}

mbs::multibody! {
    /// A stiff spring (ω ≈ 1000 rad/s) started 1 cm out: its sensitivities to k are about
    /// 1e-7 m per N/m, far below any atol a user gives in metres.
    pub model StiffSpring {
        param k = 1e6 sensitive; param c = 0.5 sensitive;
        option tangents;
        dof x = 0.01;
        body a { mass = 1.0; inertia = (0.01, 0.01, 0.01); }
        TOG[a] = Tdisp(x, 0, 0);
        generalized_force(x, -k * x - c * x);
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
    // ∂M/∂p and ∂h/∂p apart, against differences of M and h
    let (mut dm, mut dh) = ([0.0; 12], [0.0; 6]);
    model
        .parameter_derivatives(t, &q, &qd, &[], &mut dm, &mut dh)
        .unwrap();
    for (j, name) in SprungArm::SENSITIVE.iter().enumerate() {
        let p0 = model.params().values()[j];
        let e = 1e-5 * p0;
        let (mut mp, mut hp, mut mm, mut hm) = ([0.0; 4], [0.0; 2], [0.0; 4], [0.0; 2]);
        with(name, p0 + e).dynamics(t, &q, &qd, &[], &mut mp, &mut hp);
        with(name, p0 - e).dynamics(t, &q, &qd, &[], &mut mm, &mut hm);
        for i in 0..4 {
            let diff = (mp[i] - mm[i]) / (2.0 * e);
            let exact = dm[i + 4 * j];
            assert!(
                (exact - diff).abs() <= 1e-7 * exact.abs().max(1.0),
                "∂M/∂{name}: {exact} vs {diff}"
            );
        }
        for i in 0..2 {
            let diff = (hp[i] - hm[i]) / (2.0 * e);
            let exact = dh[i + 2 * j];
            assert!(
                (exact - diff).abs() <= 1e-7 * exact.abs().max(1.0),
                "∂h/∂{name}: {exact} vs {diff}"
            );
        }
    }
    assert!(dm.iter().any(|x| x.abs() > 1e-2) && dh.iter().any(|x| x.abs() > 1e-2));
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

/// M, C, K at rest at q.
fn rest_matrices(model: &SprungArm, q: &[f64]) -> [Vec<f64>; 3] {
    let (mut m, mut h, mut k, mut c) = (vec![0.0; 4], vec![0.0; 2], vec![0.0; 4], vec![0.0; 4]);
    model.dynamics(0.0, q, &[0.0; 2], &[], &mut m, &mut h);
    model
        .tangents(0.0, q, &[0.0; 2], &[0.0; 2], &[], &mut k, &mut c)
        .unwrap();
    [m, c, k]
}

#[test]
fn generated_second_derivatives_at_rest_match_central_differences() {
    let model = SprungArm::default();
    let (q, dir) = ([0.7, -0.4], [0.3, -1.1]);
    let (mut dm, mut dc, mut dk) = (vec![0.0; 16], vec![0.0; 16], vec![0.0; 16]);
    model
        .rest_tangent_derivatives(0.0, &q, &dir, &[], &mut dm, &mut dc, &mut dk)
        .unwrap();
    let generated = [&dm, &dc, &dk];
    let check = |what: &str, block: usize, plus: [Vec<f64>; 3], minus: [Vec<f64>; 3], e: f64| {
        for x in 0..3 {
            for i in 0..4 {
                let diff = (plus[x][i] - minus[x][i]) / (2.0 * e);
                let exact = generated[x][4 * block + i];
                assert!(
                    (exact - diff).abs() <= 1e-7 * exact.abs().max(1.0),
                    "{what}: matrix {x} entry {i}: generated {exact}, differences {diff}"
                );
            }
        }
    };
    // block 0: along the direction in q
    let e = 1e-5;
    let qp: Vec<f64> = (0..2).map(|i| q[i] + e * dir[i]).collect();
    let qm: Vec<f64> = (0..2).map(|i| q[i] - e * dir[i]).collect();
    check(
        "along dq",
        0,
        rest_matrices(&model, &qp),
        rest_matrices(&model, &qm),
        e,
    );
    // block 1 + j: by parameter j
    for (j, name) in SprungArm::SENSITIVE.iter().enumerate() {
        let p0 = model.params().values()[j];
        let e = 1e-5 * p0;
        let plus = rest_matrices(&with(name, p0 + e), &q);
        let minus = rest_matrices(&with(name, p0 - e), &q);
        check(name, 1 + j, plus, minus, e);
    }
    assert!(dk.iter().any(|x| x.abs() > 1e-3) && dm.iter().any(|x| x.abs() > 1e-3));
    // without sensitive parameters: the typed error
    let e = PlainArm::default()
        .rest_tangent_derivatives(0.0, &[0.1], &[1.0], &[], &mut [0.0], &mut [0.0], &mut [0.0])
        .unwrap_err();
    assert!(matches!(e, ModelError::NoSensitiveParameters { .. }), "{e}");
}

/// The sprung arm written "by hand": every function the generated one's, but for
/// `parameter_tangents`, which it does not have.
#[derive(Clone)]
struct LacksParameterTangents(SprungArm);

delegating_model!(LacksParameterTangents => SprungArm {
    const SENSITIVE: &'static [&'static str] = SprungArm::SENSITIVE;
    fn dynamics(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], m: &mut [f64], h: &mut [f64]) {
        self.0.dynamics(t, q, qd, u, m, h)
    }
});

/// The modes about the equilibrium of `model` found from `start`.
fn poles_at<M: Model + Clone>(model: &M, start: &[f64], options: &StaticsOptions) -> mbs::Modes {
    use mbs::analysis::{linearize, modes};
    let start = StaticsOptions {
        q0: Some(start.to_vec()),
        ..options.clone()
    };
    let eq = static_equilibrium(model, &start).unwrap();
    let zero = vec![0.0; M::NQ];
    let lin = linearize(model, 0.0, &eq.q, &zero, &[], mbs::IterationMatrix::Exact).unwrap();
    modes(&lin, None).unwrap()
}

#[test]
fn poles_move_with_the_parameters_as_differences_say() {
    use mbs::analysis::pole_sensitivity;
    let options = StaticsOptions {
        tolerance: 1e-13,
        ..StaticsOptions::default()
    };
    let model = SprungArm::default();
    let eq = static_equilibrium(&model, &options).unwrap();
    let s = pole_sensitivity(&model, &eq, &options).unwrap();
    assert_eq!(s.params, ["l", "m", "k1"]);
    assert_eq!(s.modes.modes.len(), 2);
    assert!(
        s.modes.modes.iter().all(|m| m.im > 0.0),
        "two oscillating modes"
    );
    for (j, name) in s.params.iter().enumerate() {
        let p0 = model.params().values()[j];
        let e = 1e-5 * p0;
        let plus = poles_at(&with(name, p0 + e), &eq.q, &options);
        let minus = poles_at(&with(name, p0 - e), &eq.q, &options);
        for (i, mode) in s.modes.modes.iter().enumerate() {
            let (dre, dim) = s.dpole(i, name).unwrap();
            let diff_re = (plus.modes[i].re - minus.modes[i].re) / (2.0 * e);
            let diff_im = (plus.modes[i].im - minus.modes[i].im) / (2.0 * e);
            let diff_f = (plus.modes[i].frequency_hz - minus.modes[i].frequency_hz) / (2.0 * e);
            let diff_z = (plus.modes[i].damping_ratio - minus.modes[i].damping_ratio) / (2.0 * e);
            println!(
                "mode {i} ({:.3} Hz) d/d{name}: λ' = {dre:.8} + {dim:.8}i (differences {diff_re:.8} + {diff_im:.8}i)",
                mode.frequency_hz
            );
            let size = dre.hypot(dim).max(1e-3);
            assert!(
                (dre - diff_re).abs() <= 1e-6 * size && (dim - diff_im).abs() <= 1e-6 * size,
                "mode {i}, {name}: ({dre}, {dim}) vs ({diff_re}, {diff_im})"
            );
            let df = s.dfrequency(i, name).unwrap();
            assert!(
                (df - diff_f).abs() <= 1e-6 * df.abs().max(1e-3),
                "{df} vs {diff_f}"
            );
            let dz = s.ddamping(i, name).unwrap();
            assert!(
                (dz - diff_z).abs() <= 1e-6 * dz.abs().max(1e-4),
                "{dz} vs {diff_z}"
            );
        }
    }
    // every parameter moves the first pole
    assert!(
        s.params
            .iter()
            .all(|p| s.dfrequency(0, p).unwrap().abs() > 1e-3)
    );
    // a locked coordinate is refused
    let locked = StaticsOptions {
        locked: vec![1],
        ..options.clone()
    };
    let eq = static_equilibrium(&model, &locked).unwrap();
    let err = pole_sensitivity(&model, &eq, &locked).unwrap_err();
    assert!(err.to_string().contains("locked"), "{err}");
}

/// q(t_end), qd(t_end) of a plain run at tight tolerances.
fn end_state<M: Model + 'static>(model: M, t_end: f64) -> (Vec<f64>, Vec<f64>) {
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

/// (dq/dp, dqd/dp) at t_end for each sensitive parameter of `M`, by central differences of
/// plain runs.
fn end_state_differences<M: Model + Default + 'static>(t_end: f64) -> Vec<(Vec<f64>, Vec<f64>)> {
    M::SENSITIVE
        .iter()
        .map(|name| {
            let p0 = default_value::<M>(name);
            let e = 1e-5 * p0;
            let (qp, vp) = end_state(with_value::<M>(name, p0 + e), t_end);
            let (qm, vm) = end_state(with_value::<M>(name, p0 - e), t_end);
            let d = |a: &[f64], b: &[f64]| -> Vec<f64> {
                a.iter().zip(b).map(|(x, y)| (x - y) / (2.0 * e)).collect()
            };
            (d(&qp, &qm), d(&vp, &vm))
        })
        .collect()
}

/// Runs with sensitivities to `t_end` at rtol 1e-10, atol 1e-12, their last state only.
fn last_state_at(t_end: f64) -> mbs::Options {
    mbs::Options {
        t_end,
        step: mbs::StepControl::Adaptive {
            rtol: 1e-10,
            atol: 1e-12,
            h0: None,
        },
        output: mbs::Output::Last,
        ..mbs::Options::default()
    }
}

#[test]
fn sensitivities_integrated_with_the_motion_match_central_differences() {
    use mbs::{Scheme, Sensitivities, simulate};
    let t_end = 2.0;
    let reference = end_state_differences::<SprungArm>(t_end);
    let options = last_state_at(t_end);
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

/// Sensitivities start where the declared start moves with the parameters: they started at
/// zero always, and a spring started at a sensitive x0 had dx/dx0 = 0 throughout (cos 10t,
/// 0.284 at t = 0.5 s).
#[test]
fn sensitivities_of_a_start_that_depends_on_the_parameters() {
    use mbs::{Scheme, Sensitivities, simulate};
    let t_end = 0.5;
    let options = last_state_at(t_end);
    let model = Sensitivities::new(StartedSpring::default()).unwrap();
    let (tr, _) = simulate(model, Scheme::Dopri5, options).unwrap();
    let last = tr.len() - 1;
    let w = 10.0f64;
    let want = [
        ((w * t_end).cos(), -w * (w * t_end).sin()),
        ((w * t_end).sin() / w, (w * t_end).cos()),
    ];
    for (j, (dq, dv)) in want.into_iter().enumerate() {
        let sq = Sensitivities::<StartedSpring>::dq_dp(&tr, last, j)[0];
        let sv = Sensitivities::<StartedSpring>::dqd_dp(&tr, last, j)[0];
        println!("parameter {j}: dx/dp {sq:.9} (exact {dq:.9}), dv/dp {sv:.9} (exact {dv:.9})");
        assert!(
            (sq - dq).abs() < 1e-8 && (sv - dv).abs() < 1e-7,
            "{sq} {sv}"
        );
    }
}

/// A sampled controller's u depends on the parameters through the state, which the
/// sensitivities do not differentiate: refused, where dq/dp came out without its feedback
/// (3.5 times too large for u = −20 q on a spring).
#[test]
fn sensitivities_refuse_sampled_controllers() {
    use mbs::{Inputs, Options, Scheme, Sensitivities, Simulation, State};
    let model = Sensitivities::new(StartedSpring::default()).unwrap();
    let inputs = Inputs::new().controller(0.01, |_: f64, _: &State, _: &mut [f64]| {});
    let Err(e) = Simulation::with_inputs(model, Scheme::Dopri5, Options::default(), inputs) else {
        panic!("a controller on sensitivities was accepted")
    };
    println!("{e}");
    assert!(
        matches!(
            e.kind,
            mbs::Failure::InvalidOption {
                name: "controllers",
                ..
            }
        ),
        "{e}"
    );
    // the plain model takes it
    let inputs = Inputs::new().controller(0.01, |_: f64, _: &State, _: &mut [f64]| {});
    let plain = Simulation::with_inputs(
        StartedSpring::default(),
        Scheme::Dopri5,
        Options::default(),
        inputs,
    );
    if let Err(e) = plain {
        panic!("{e}");
    }
}

#[test]
fn sensitivities_refuse_models_they_cannot_differentiate() {
    let Err(e) = mbs::Sensitivities::new(PlainArm::default()) else {
        panic!("accepted")
    };
    assert!(matches!(e, ModelError::NoSensitiveParameters { .. }), "{e}");
    // a model written by hand that says it has tangents and sensitive parameters but lacks
    // ∂τ/∂p (the trait's default answers for it): refused when wrapped, with what its
    // function says, where the wrapper read its sensitivities' forces as zeros before
    let Err(e) = mbs::Sensitivities::new(LacksParameterTangents(SprungArm::default())) else {
        panic!("accepted a model without ∂τ/∂p")
    };
    assert!(matches!(e, ModelError::NoSensitiveParameters { .. }), "{e}");
}

// ---- closed loops ----

/// The default model with parameter `name` set to `value`.
fn with_value<M: Model + Default>(name: &str, value: f64) -> M {
    let mut model = M::default();
    let mut p = model.params().clone();
    p.set(name, value).unwrap();
    model.set_params(p).unwrap();
    model
}

/// The default value of parameter `name`.
fn default_value<M: Model + Default>(name: &str) -> f64 {
    let i = <M::Params as Parameters>::NAMES
        .iter()
        .position(|n| *n == name)
        .unwrap();
    M::default().params().values()[i]
}

/// The value of sensitive parameter `j` of the four-bar.
fn fourbar_param(j: usize) -> f64 {
    default_value::<SensitiveFourBar>(SensitiveFourBar::SENSITIVE[j])
}

/// Φ, Φ̇ = B qd + Φ_t, Φ̈ = B qdd − γ and Bᵀλ of the four-bar, concatenated.
fn loop_terms(
    model: &SensitiveFourBar,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    lam: &[f64],
) -> Vec<f64> {
    let (n, nc, t) = (3, 2, 0.3);
    let (mut phi, mut b, mut phi_t, mut gamma) = (
        vec![0.0; nc],
        vec![0.0; nc * n],
        vec![0.0; nc],
        vec![0.0; nc],
    );
    model.constraints(t, q, &mut phi);
    model.constraint_jacobian(t, q, &mut b);
    model.constraint_rate(t, q, &mut phi_t);
    model.constraint_bias(t, q, qd, &mut gamma);
    let bv = |i: usize, v: &[f64]| (0..n).map(|k| b[i + nc * k] * v[k]).sum::<f64>();
    let mut out = phi.clone();
    out.extend((0..nc).map(|i| bv(i, qd) + phi_t[i]));
    out.extend((0..nc).map(|i| bv(i, qdd) - gamma[i]));
    out.extend((0..n).map(|k| (0..nc).map(|i| b[i + nc * k] * lam[i]).sum::<f64>()));
    out
}

#[test]
fn generated_constraint_derivatives_match_central_differences() {
    use mbs::ConstraintTangents;
    let (n, nc) = (3, 2);
    let (q, qd, qdd, lam) = (
        [1.0, 0.6, 1.8],
        [5.0, -1.2, 0.7],
        [3.0, -20.0, 8.0],
        [1.5, -0.7],
    );
    let model = SensitiveFourBar::default();
    let mut ct = ConstraintTangents::new::<SensitiveFourBar>();
    model
        .constraint_parameter_tangents(0.3, &q, &qd, &qdd, &lam, &mut ct)
        .unwrap();
    let close = |what: &str, exact: f64, diff: f64| {
        assert!(
            (exact - diff).abs() <= 1e-7 * exact.abs().max(1.0),
            "{what}: generated {exact}, differences {diff}"
        );
    };
    // by the parameters: rows Φ, Φ̇, Φ̈ (nc each), then Bᵀλ (n)
    for j in 0..4 {
        let (name, p0) = (SensitiveFourBar::SENSITIVE[j], fourbar_param(j));
        let e = 1e-6 * p0;
        let plus = loop_terms(
            &with_value::<SensitiveFourBar>(name, p0 + e),
            &q,
            &qd,
            &qdd,
            &lam,
        );
        let minus = loop_terms(
            &with_value::<SensitiveFourBar>(name, p0 - e),
            &q,
            &qd,
            &qdd,
            &lam,
        );
        let d = |r: usize| (plus[r] - minus[r]) / (2.0 * e);
        for i in 0..nc {
            close(&format!("∂Φ{i}/∂{name}"), ct.dphi_dp[i + nc * j], d(i));
            close(
                &format!("∂Φ̇{i}/∂{name}"),
                ct.drate_dp[i + nc * j],
                d(nc + i),
            );
            close(
                &format!("∂Φ̈{i}/∂{name}"),
                ct.dacc_dp[i + nc * j],
                d(2 * nc + i),
            );
        }
        for k in 0..n {
            close(
                &format!("∂(Bᵀλ){k}/∂{name}"),
                ct.dforce_dp[k + n * j],
                d(3 * nc + k),
            );
        }
    }
    // by the coordinates and their rates
    let e = 1e-6;
    for k in 0..n {
        let (mut qp, mut qm, mut vp, mut vm) = (q, q, qd, qd);
        qp[k] += e;
        qm[k] -= e;
        vp[k] += e;
        vm[k] -= e;
        let by_q = (
            loop_terms(&model, &qp, &qd, &qdd, &lam),
            loop_terms(&model, &qm, &qd, &qdd, &lam),
        );
        let by_v = (
            loop_terms(&model, &q, &vp, &qdd, &lam),
            loop_terms(&model, &q, &vm, &qdd, &lam),
        );
        for i in 0..nc {
            let dq = |r: usize| (by_q.0[r] - by_q.1[r]) / (2.0 * e);
            let dv = |r: usize| (by_v.0[r] - by_v.1[r]) / (2.0 * e);
            close(&format!("∂Φ̇{i}/∂q{k}"), ct.drate_dq[i + nc * k], dq(nc + i));
            close(
                &format!("∂Φ̈{i}/∂q{k}"),
                ct.dacc_dq[i + nc * k],
                dq(2 * nc + i),
            );
            close(
                &format!("∂Φ̈{i}/∂qd{k}"),
                ct.dacc_dqd[i + nc * k],
                dv(2 * nc + i),
            );
        }
    }
    assert!(ct.dphi_dp.iter().any(|x| x.abs() > 1e-2));
    assert!(ct.dforce_dp.iter().any(|x| x.abs() > 1e-2));
    // B' and K_λ' (pole sensitivities): along a direction in q, then by each parameter
    let dir = [0.3, -1.1, 0.6];
    let (mut db, mut dk) = (vec![0.0; nc * n * 5], vec![0.0; n * n * 5]);
    model
        .constraint_rest_derivatives(0.3, &q, &dir, &lam, &mut db, &mut dk)
        .unwrap();
    let b_and_k = |m: &SensitiveFourBar, q: &[f64]| {
        let (mut b, mut k) = (vec![0.0; nc * n], vec![0.0; n * n]);
        m.constraint_jacobian(0.3, q, &mut b);
        m.constraint_tangent(0.3, q, &lam, &mut k);
        (b, k)
    };
    let compare = |what: &str,
                   block: usize,
                   plus: (Vec<f64>, Vec<f64>),
                   minus: (Vec<f64>, Vec<f64>),
                   e: f64| {
        for i in 0..nc * n {
            close(
                &format!("B' {what} [{i}]"),
                db[nc * n * block + i],
                (plus.0[i] - minus.0[i]) / (2.0 * e),
            );
        }
        for i in 0..n * n {
            close(
                &format!("K_λ' {what} [{i}]"),
                dk[n * n * block + i],
                (plus.1[i] - minus.1[i]) / (2.0 * e),
            );
        }
    };
    let qp: Vec<f64> = (0..n).map(|i| q[i] + e * dir[i]).collect();
    let qm: Vec<f64> = (0..n).map(|i| q[i] - e * dir[i]).collect();
    compare("along dq", 0, b_and_k(&model, &qp), b_and_k(&model, &qm), e);
    for j in 0..4 {
        let (name, p0) = (SensitiveFourBar::SENSITIVE[j], fourbar_param(j));
        let e = 1e-6 * p0;
        compare(
            name,
            1 + j,
            b_and_k(&with_value::<SensitiveFourBar>(name, p0 + e), &q),
            b_and_k(&with_value::<SensitiveFourBar>(name, p0 - e), &q),
            e,
        );
    }
    assert!(db.iter().any(|x| x.abs() > 1e-2) && dk.iter().any(|x| x.abs() > 1e-2));
    // models without constraints or sensitive parameters have none
    let e = SprungArm::default()
        .constraint_parameter_tangents(0.0, &[0.0; 2], &[0.0; 2], &[0.0; 2], &[], &mut ct)
        .unwrap_err();
    assert!(matches!(e, ModelError::NoSensitiveParameters { .. }), "{e}");
}

#[test]
fn closed_loop_equilibria_move_with_the_parameters_as_differences_say() {
    let options = StaticsOptions {
        tolerance: 1e-13,
        ..StaticsOptions::default()
    };
    let model = SensitiveFourBar::default();
    let eq = static_equilibrium(&model, &options).unwrap();
    assert!(eq.constraint_residual < 1e-12, "{eq}");
    let s = static_sensitivity(&model, &eq, &options).unwrap();
    assert_eq!(s.params, ["l1", "l2", "rho", "k1"]);
    // an equilibrium of another model is refused, not indexed out of bounds
    let other = static_equilibrium(&SprungArm::default(), &options).unwrap();
    let err = static_sensitivity(&model, &other, &options).unwrap_err();
    assert!(err.to_string().contains("not one of this model"), "{err}");
    // so is one with charts of rotation joints the model does not have, and inputs it does
    // not take (they were handed to the generated code, which indexes them)
    let mut charted = eq.clone();
    charted
        .charts
        .push([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    let err = static_sensitivity(&model, &charted, &options).unwrap_err();
    assert!(err.to_string().contains("not one of this model"), "{err}");
    let with_u = StaticsOptions {
        u: Some(vec![1.0, 2.0]),
        ..options.clone()
    };
    let err = static_sensitivity(&model, &eq, &with_u).unwrap_err();
    assert!(
        matches!(
            err,
            mbs::AnalysisError::Failure(mbs::Failure::InvalidOption { name: "u", .. })
        ),
        "{err}"
    );
    assert_eq!(s.dlambda_dp.len(), 2 * 4);
    for (j, name) in s.params.iter().enumerate() {
        let p0 = fourbar_param(j);
        let e = 1e-5 * p0;
        let start = StaticsOptions {
            q0: Some(eq.q.clone()),
            ..options.clone()
        };
        let plus =
            static_equilibrium(&with_value::<SensitiveFourBar>(name, p0 + e), &start).unwrap();
        let minus =
            static_equilibrium(&with_value::<SensitiveFourBar>(name, p0 - e), &start).unwrap();
        for i in 0..3 {
            let diff = (plus.q[i] - minus.q[i]) / (2.0 * e);
            let exact = s.get(i, name).unwrap();
            println!("∂q{i}/∂{name}: {exact:.10} (differences {diff:.10})");
            assert!(
                (exact - diff).abs() <= 1e-6 * exact.abs().max(1e-3),
                "∂q{i}/∂{name}: {exact} vs {diff}"
            );
        }
        for i in 0..2 {
            let diff = (plus.lambda[i] - minus.lambda[i]) / (2.0 * e);
            let exact = s.dlambda_dp[i + 2 * j];
            println!("∂λ{i}/∂{name}: {exact:.10} (differences {diff:.10})");
            assert!(
                (exact - diff).abs() <= 1e-6 * exact.abs().max(1e-3),
                "∂λ{i}/∂{name}: {exact} vs {diff}"
            );
        }
    }
}

#[test]
fn closed_loop_poles_move_with_the_parameters_as_differences_say() {
    closed_loop_poles_against_differences(2.0);
}

/// The same with the spring 10⁸ times stiffer (its pole at 305,533 rad/s): the constraints'
/// block of each augmented system is a billion times smaller than the stiffness', and the
/// factorisations took the pivots of B K⁻¹ Bᵀ for singular: the statics refused the loop as
/// a singular reduced stiffness (from k1 = 2e8; the pole's eigenvector system from 2e6).
#[test]
fn closed_loop_poles_with_a_stiff_spring_move_as_differences_say() {
    closed_loop_poles_against_differences(2e8);
}

/// The four-bar's pole and its derivative by each sensitive parameter, its spring k1,
/// against central differences of the poles of equilibria found from the same start.
fn closed_loop_poles_against_differences(k1: f64) {
    use mbs::analysis::pole_sensitivity;
    let options = StaticsOptions {
        tolerance: 1e-13 * (k1 / 2.0).max(1.0),
        ..StaticsOptions::default()
    };
    let with = |model: &SensitiveFourBar, name: &str, value: f64| {
        let mut model = model.clone();
        let mut p = model.params().clone();
        p.set(name, value).unwrap();
        model.set_params(p).unwrap();
        model
    };
    let model = with(&SensitiveFourBar::default(), "k1", k1);
    let eq = static_equilibrium(&model, &options).unwrap();
    let s = pole_sensitivity(&model, &eq, &options).unwrap();
    // one degree of freedom: one lightly damped mode
    assert_eq!(s.modes.modes.len(), 1);
    assert!(s.repeated.is_empty(), "repeated: {:?}", s.repeated);
    let mode = &s.modes.modes[0];
    assert!(mode.im > 0.0, "{mode:?}");
    let values = model.params().values();
    for name in s.params.iter() {
        let i = <<SensitiveFourBar as Model>::Params as Parameters>::NAMES
            .iter()
            .position(|n| n == name)
            .unwrap();
        let p0 = values[i];
        let e = 1e-5 * p0;
        let plus = poles_at(&with(&model, name, p0 + e), &eq.q, &options);
        let minus = poles_at(&with(&model, name, p0 - e), &eq.q, &options);
        let (dre, dim) = s.dpole(0, name).unwrap();
        let diff_re = (plus.modes[0].re - minus.modes[0].re) / (2.0 * e);
        let diff_im = (plus.modes[0].im - minus.modes[0].im) / (2.0 * e);
        println!(
            "k1 = {k1}: mode 0 ({:.4} Hz) d/d{name}: λ' = {dre:.8} + {dim:.8}i (differences {diff_re:.8} + {diff_im:.8}i)",
            mode.frequency_hz
        );
        let size = dre.hypot(dim).max(1e-3);
        assert!(
            (dre - diff_re).abs() <= 1e-6 * size && (dim - diff_im).abs() <= 1e-6 * size,
            "{name}: ({dre}, {dim}) vs ({diff_re}, {diff_im})"
        );
        assert!(dim.abs() > 1e-2 / k1.max(1.0), "{name} moves the pole");
    }
}

#[test]
fn closed_loop_sensitivities_match_central_differences() {
    use mbs::{Options, Scheme, Sensitivities, StepControl, simulate};
    type S = Sensitivities<SensitiveFourBar>;
    let t_end = 1.0;
    let reference = end_state_differences::<SensitiveFourBar>(t_end);
    let options = Options {
        t_end,
        step: StepControl::Adaptive {
            rtol: 1e-10,
            atol: 1e-12,
            h0: None,
        },
        ..Options::default()
    };
    for scheme in [
        Scheme::Dopri5,
        Scheme::Radau5,
        Scheme::Bdf(Default::default()),
    ] {
        let model = S::new(SensitiveFourBar::default()).unwrap();
        let (tr, stats) = simulate(model, scheme, options.clone()).unwrap();
        let (_, plain) = simulate(SensitiveFourBar::default(), scheme, options.clone()).unwrap();
        let last = tr.len() - 1;
        // the start's sensitivities are the assembly's: the crank's (independent) stays 0,
        // the coupler's and rocker's close the loop for a longer crank
        let s0 = S::dq_dp(&tr, 0, 0);
        assert!(
            s0[0] == 0.0 && s0[1].abs() > 0.1 && s0[2].abs() > 0.1,
            "{s0:?}"
        );
        let mut worst: f64 = 0.0;
        for (j, (dq, dv)) in reference.iter().enumerate() {
            let (sq, sv) = (S::dq_dp(&tr, last, j), S::dqd_dp(&tr, last, j));
            let scale = dq.iter().chain(dv).fold(0.0f64, |m, x| m.max(x.abs()));
            for (exact, diff) in sq.iter().zip(dq).chain(sv.iter().zip(dv)) {
                worst = worst.max((exact - diff).abs() / scale);
            }
        }
        let mut wrapper = S::new(SensitiveFourBar::default()).unwrap();
        let drift = (0..tr.len()).fold((0.0f64, 0.0f64), |m, i| {
            let (p, v) = wrapper.residuals(&tr, i).unwrap();
            (m.0.max(p), m.1.max(v))
        });
        println!(
            "{}: worst |s − differences| / max|s| = {worst:.1e}; drift |B s + Φ_p| ≤ {:.1e}, rate ≤ {:.1e}; {} steps with sensitivities, {} without",
            scheme.name(),
            drift.0,
            drift.1,
            stats.steps,
            plain.steps
        );
        assert!(worst < 1e-6, "{}: {worst:e}", scheme.name());
        assert!(drift.0 < 1e-7 && drift.1 < 1e-6, "{drift:?}");
    }
}

// ---- rotation joints ----

mbs::multibody! {
    /// The ball on a rod of `mbs_models::spherical_pendulum` (a `Tball` joint whose ZYX chart
    /// locks at the bottom of the swing) with a sideways start rate that does not depend on
    /// the parameters, and its length, radius and gravity marked `sensitive`.
    pub model SensitiveBall {
        param m = 1.0;
        param l = 1.0 sensitive;
        param r = 0.05 sensitive;
        param g = 9.81 sensitive;
        dof a = 0.0, qd = 0.6;
        dof b = PI / 6;
        dof c = 0.0;
        option tangents;
        body ball { mass = m; inertia = (0.4 * m * r * r, 0.4 * m * r * r, 0.4 * m * r * r); }
        point centre on ball at (0, 0, 0);
        TOG[ball] = Tball(a, b, c) * Tdisp(l, 0, 0);
        gravity(0, 0, -g);
    }
}

/// The ball's position and velocity at output `i` of a trajectory of `model` (read in that
/// output's charts).
fn ball_state<M: Model>(
    model: &mut M,
    tr: &mbs::Trajectory,
    i: usize,
    q: &[f64],
    qd: &[f64],
) -> [f64; 6] {
    mbs::charts::use_charts_of(model, tr, i);
    let mut k = mbs::Kinematics::new::<M>();
    model.kinematics(tr.t[i], q, qd, &mut k);
    let p = &k.points[0];
    [
        p.position[0],
        p.position[1],
        p.position[2],
        p.velocity[0],
        p.velocity[1],
        p.velocity[2],
    ]
}

#[test]
fn sensitivities_cross_chart_switches_as_differences_say() {
    use mbs::{Options, Scheme, Sensitivities, StepControl, simulate};
    type S = Sensitivities<SensitiveBall>;
    let t_end = 3.0;
    let options = |rtol: f64| Options {
        t_end,
        step: StepControl::Adaptive {
            rtol,
            atol: rtol * 1e-2,
            h0: None,
        },
        output: mbs::Output::Last,
        ..Options::default()
    };
    // the ball's position and velocity at the end by central differences of plain runs
    let end = |model: SensitiveBall| {
        let (tr, stats) = simulate(model.clone(), Scheme::Dopri5, options(1e-12)).unwrap();
        let last = tr.len() - 1;
        (
            ball_state(&mut model.clone(), &tr, last, tr.q(last), tr.qd(last)),
            stats.chart_switches,
        )
    };
    let mut reference = Vec::new();
    for name in SensitiveBall::SENSITIVE {
        let p0 = default_value::<SensitiveBall>(name);
        let e = 1e-5 * p0;
        let ((plus, switches), (minus, _)) = (
            end(with_value::<SensitiveBall>(name, p0 + e)),
            end(with_value::<SensitiveBall>(name, p0 - e)),
        );
        assert!(switches >= 2, "the swing re-centres the chart: {switches}");
        reference.push(
            (0..6)
                .map(|i| (plus[i] - minus[i]) / (2.0 * e))
                .collect::<Vec<f64>>(),
        );
    }
    let mut worsts = Vec::new();
    for scheme in [
        Scheme::Dopri5,
        Scheme::Radau5,
        Scheme::Bdf(Default::default()),
        Scheme::GenAlpha(Default::default()),
    ] {
        let (tr, stats) = simulate(
            S::new(SensitiveBall::default()).unwrap(),
            scheme,
            options(1e-10),
        )
        .unwrap();
        assert!(stats.chart_switches >= 2, "{}", stats.chart_switches);
        let last = tr.len() - 1;
        let (x, xd) = (tr.q(last), tr.qd(last));
        let mut model = SensitiveBall::default();
        let mut worst: f64 = 0.0;
        for (j, r) in reference.iter().enumerate() {
            // the ball's state along (s, ṡ), in the run's last charts
            let (sq, sv) = (S::dq_dp(&tr, last, j), S::dqd_dp(&tr, last, j));
            let h = 1e-6;
            let at = |sign: f64, model: &mut SensitiveBall| {
                let q: Vec<f64> = (0..3).map(|i| x[i] + sign * h * sq[i]).collect();
                let qd: Vec<f64> = (0..3).map(|i| xd[i] + sign * h * sv[i]).collect();
                ball_state(model, &tr, last, &q, &qd)
            };
            let (plus, minus) = (at(1.0, &mut model), at(-1.0, &mut model));
            // ... plus the parameter's own effect at fixed (q, qd) (the rod's length)
            let (name, p0) = (
                SensitiveBall::SENSITIVE[j],
                default_value::<SensitiveBall>(SensitiveBall::SENSITIVE[j]),
            );
            let e = 1e-6 * p0;
            let direct = |v: f64| {
                ball_state(
                    &mut with_value::<SensitiveBall>(name, v),
                    &tr,
                    last,
                    &x[..3],
                    &xd[..3],
                )
            };
            let (dplus, dminus) = (direct(p0 + e), direct(p0 - e));
            let scale = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..6 {
                let exact = (plus[i] - minus[i]) / (2.0 * h) + (dplus[i] - dminus[i]) / (2.0 * e);
                worst = worst.max((exact - r[i]).abs() / scale);
            }
        }
        println!(
            "{}: {} chart switches; worst |d(ball position, velocity)/dp − differences| / max = {worst:.1e}",
            scheme.name(),
            stats.chart_switches
        );
        assert!(worst < 1e-5, "{}: {worst:e}", scheme.name());
        worsts.push(format!("{worst:.1e}"));
    }
    let quote = if worsts[1..3].iter().all(|w| *w == worsts[0]) {
        format!(
            "{} for DOPRI5, Radau5 and BDF at rtol 1e-10 and {} for generalized-α",
            worsts[0], worsts[3]
        )
    } else {
        format!(
            "{}, {} and {} for DOPRI5, Radau5 and BDF at rtol 1e-10 and {} for generalized-α",
            worsts[0], worsts[1], worsts[2], worsts[3]
        )
    };
    quoted::says("README.md", &[quote]);
}

/// A repeated pole (a symmetric machine's twin modes) has no derivative: it is listed, gives
/// none, and the simple pole beside it keeps its own (dλ/dkz = i/(2 m ω) at ω = √(kz/m),
/// dλ/dkx = 0).
#[test]
fn a_repeated_pole_is_listed_and_the_others_keep_their_derivatives() {
    use mbs::analysis::pole_sensitivity;
    let model = Oscillators::default();
    let options = StaticsOptions::default();
    let eq = static_equilibrium(&model, &options).unwrap();
    let s = pole_sensitivity(&model, &eq, &options).unwrap();
    for (i, mode) in s.modes.modes.iter().enumerate() {
        println!(
            "mode {i}: λ = {:.6} + {:.6}i, dλ/dkx {:?}, dλ/dkz {:?}",
            mode.re,
            mode.im,
            s.dpole(i, "kx"),
            s.dpole(i, "kz")
        );
    }
    assert_eq!(s.modes.modes.len(), 3);
    let simple: Vec<usize> = (0..3).filter(|i| !s.repeated.contains(i)).collect();
    assert_eq!(simple.len(), 1, "repeated: {:?}", s.repeated);
    let z = simple[0];
    let omega = 300.0f64.sqrt();
    assert!((s.modes.modes[z].im - omega).abs() < 1e-9 * omega);
    let (re, im) = s.dpole(z, "kz").unwrap();
    assert!(
        re.abs() < 1e-12 && (im - 1.0 / (2.0 * omega)).abs() < 1e-12,
        "{re} {im}"
    );
    let (re, im) = s.dpole(z, "kx").unwrap();
    assert!(re.abs() < 1e-12 && im.abs() < 1e-12, "{re} {im}");
    for &i in &s.repeated {
        assert_eq!(s.dpole(i, "kx"), None);
        assert_eq!(s.dfrequency(i, "kz"), None);
    }
}

mbs::multibody! {
    /// Two masses on springs along x and y whose stiffnesses differ by a part in 10⁷, so that
    /// their poles are apart by about 5e-8 of their size (a repeated pole counts from 1e-8),
    /// and a coupling spring between the two coordinates, absent at its default kc = 0.
    model NearTwins {
        param kx = 100.0; param ky = 100.00001; param kc = 0.0 sensitive; param m = 1.0;
        option tangents;
        dof x = 0.0; dof y = 0.0;
        body a { mass = m; inertia = (0.01, 0.01, 0.01); }
        body b { mass = m; inertia = (0.01, 0.01, 0.01); }
        TOG[a] = Tdisp(x, 0, 0);
        TOG[b] = Tdisp(0, y, 0);
        generalized_force(x, -kx * x - kc * (x - y));
        generalized_force(y, -ky * y - kc * (y - x));
    }
}

/// Nearly repeated poles are simple, and their derivatives exact: with the coupling absent,
/// each mode moves one coordinate alone, and the coupling spring stiffens each by dk = dkc,
/// dλ/dkc = i/(2 m ω) at ω = √(k/m). The eigenvectors come from inverse iteration, whose
/// convergence the other pole, 5e-8 of their size away, slows: they are iterated until they
/// settle (three iterations left 1.4e-5 of the other mode in each, and the derivatives that
/// much off). Each mode's separation from the nearest other pole is reported.
#[test]
fn nearly_repeated_poles_have_exact_derivatives_and_their_separation() {
    use mbs::analysis::pole_sensitivity;
    let model = NearTwins::default();
    let options = StaticsOptions::default();
    let eq = static_equilibrium(&model, &options).unwrap();
    let s = pole_sensitivity(&model, &eq, &options).unwrap();
    assert!(s.repeated.is_empty(), "repeated: {:?}", s.repeated);
    assert_eq!(s.modes.modes.len(), 2);
    let mut worst = 0.0f64;
    for (i, mode) in s.modes.modes.iter().enumerate() {
        let omega = mode.im;
        let (re, im) = s.dpole(i, "kc").unwrap();
        let exact = 1.0 / (2.0 * omega);
        let error = re.hypot(im - exact) / exact;
        println!(
            "mode {i}: λ = {:.9}i, dλ/dkc = {re:.3e} + {im:.12}i (exact {exact:.12}i, relative error {error:.1e}), separation {:.2e}",
            mode.im, s.separation[i]
        );
        worst = worst.max(error);
        let expected = (100.00001f64.sqrt() - 10.0) / 10.0;
        assert!(
            (s.separation[i] - expected).abs() < 1e-3 * expected,
            "{} against {expected}",
            s.separation[i]
        );
    }
    assert!(worst < 1e-10, "{worst:e}");
}

/// The equilibrium's sensitivities of a loop held by a spring of 2e6 to 2e14 N·m/rad: the
/// crank the spring holds moves with the link lengths as 1/k1, the others as the loop's
/// geometry says, whatever k1. At 2e14 the factorisation of [K, −Bᵀ; B, 0] took the pivots
/// of B K⁻¹ Bᵀ for singular and the loop was refused as having a neutral direction.
#[test]
fn a_stiff_loop_s_equilibrium_sensitivities_scale_with_its_spring() {
    let at = |k1: f64| {
        let mut model = SensitiveFourBar::default();
        let mut p = model.params().clone();
        p.set("k1", k1).unwrap();
        model.set_params(p).unwrap();
        let options = StaticsOptions {
            tolerance: 1e-13 * k1,
            ..StaticsOptions::default()
        };
        let eq = static_equilibrium(&model, &options).unwrap();
        static_sensitivity(&model, &eq, &options).unwrap().dq_dp
    };
    let (soft, stiff) = (at(2e6), at(2e14));
    println!(
        "dq/dl1 at k1 = 2e6: {:?}; at 2e14: {:?}",
        &soft[..3],
        &stiff[..3]
    );
    let crank = (stiff[0] * 1e8 - soft[0]).abs() / soft[0].abs();
    assert!(crank < 1e-6, "{crank:e}");
    for i in 1..3 {
        assert!((stiff[i] - soft[i]).abs() < 1e-6 * soft[i].abs(), "{i}");
    }
}

/// Sensitivities do not loosen the control of the motion: the error norm is the largest of
/// the motion's and each parameter's own (`Tolerances::groups`), where one RMS norm over
/// them all divided the motion's error by √3 when the sensitivities' errors were small
/// against their weights (DOPRI5 took 83, 208, 523 steps with sensitivities at rtol 1e-4,
/// 1e-6, 1e-8 where the plain run takes 90, 231, 585; Radau5 107, 229, 503 for 122, 262,
/// 579). The sensitivities dx/dk (6.6e-8 m per N/m, below atol at rtol 1e-4) come out with
/// a relative error 1–12 times the motion's (DOPRI5 at rtol 1e-4 the worst).
#[test]
fn sensitivities_do_not_loosen_the_motion_s_control() {
    use mbs::{Scheme, Sensitivities, simulate};
    let t_end = 0.05;
    let w = (1e6f64 + 0.5).sqrt();
    let x = 0.01 * (w * t_end).cos();
    let dx_dk = -0.01 * t_end * (w * t_end).sin() / (2.0 * w);
    for scheme in [
        Scheme::Dopri5,
        Scheme::Radau5,
        Scheme::Bdf(Default::default()),
    ] {
        for rtol in [1e-4, 1e-6, 1e-8] {
            let options = mbs::Options {
                t_end,
                output: mbs::Output::Last,
                ..mbs::Options::adaptive(t_end, rtol)
            };
            let model = Sensitivities::new(StiffSpring::default()).unwrap();
            let (tr, with) = simulate(model, scheme, options.clone()).unwrap();
            let (plain_tr, plain) = simulate(StiffSpring::default(), scheme, options).unwrap();
            let last = tr.len() - 1;
            let error = (tr.q(last)[0] - x).abs() / 0.01;
            let plain_error = (plain_tr.q(plain_tr.len() - 1)[0] - x).abs() / 0.01;
            let sk = Sensitivities::<StiffSpring>::dq_dp(&tr, last, 0)[0];
            let s_error = (sk - dx_dk).abs() / dx_dk.abs();
            println!(
                "{} at rtol {rtol:e}: {} steps with sensitivities, {} plain; x's error {error:.1e} \
                 ({plain_error:.1e} plain), dx/dk's {s_error:.1e}",
                scheme.name(),
                with.steps,
                plain.steps
            );
            // the implicit schemes iterate on the wrapper with other matrices: a few steps apart
            assert!(
                with.steps as f64 >= 0.97 * plain.steps as f64,
                "{} at {rtol:e}",
                scheme.name()
            );
            assert!(error <= 1.5 * plain_error, "{} at {rtol:e}", scheme.name());
            assert!(
                s_error <= 20.0 * error.max(rtol),
                "{} at {rtol:e}",
                scheme.name()
            );
        }
    }
}
