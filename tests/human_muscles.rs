//! The legs' muscles (`mbs::muscle`, `mbs::elements::Path`, `mbs_models::human::Muscles`):
//!
//! - De Groote 2016's curves meet their anchor points and invert exactly; a unit's tendon
//!   force and fibre length rate and the activation rate equal SymPy's
//!   `physics.biomechanics` (values below, computed with SymPy 1.14's
//!   `MusculotendonDeGroote2016.with_defaults(…, FIBER_LENGTH_EXPLICIT)` and
//!   `FirstOrderActivationDeGroote2016.with_defaults`, v_max = 10 l_opt), and the
//!   activation dynamics inverted (`excitation_for_rate`) gives back the rate asked;
//! - the quadriceps' insertions on the patella follow OpenSim's moving points on the tibia;
//! - the paths' ∂l/∂q from the generated point Jacobians equal central differences of the
//!   length, and l̇ = ∂l/∂q · q̇;
//! - the moment arms in the anatomical posture have each muscle's anatomical action (sign)
//!   and a size of a few centimetres, on both legs alike;
//! - a fibre at rest from `equilibrium` has zero length rate; the tension applied along a
//!   path is the generalised force −T ∂l/∂q;
//! - a muscle stretched beyond its fibre's range stops a run with a typed failure
//!   (`EffortRejected`: the state is rejected, smaller steps tried, since a Newton
//!   iteration's trial state can overshoot where the motion never goes), the trajectory
//!   kept; a unit's invalid parameters, non-finite inputs and a tendon no fibre speed
//!   balances are typed errors;
//! - standing on the muscles (mode 2): excitations from the statics of the held body and a
//!   static optimisation (co-contraction about 0.5), the equilibrium under them by statics
//!   with the fibres at rest; the body stands 2 s on constant excitations within 1e-6 of it.
//!   That equilibrium is unstable (no feedback): its linearisation has one growing pole, and
//!   a pushed body departs at the rate that pole gives (within 20 %).

use mbs::elements::Path;
use mbs::muscle::{self, MuscleError, Musculotendon};
use mbs::{Effort, Efforts, Failure, Kinematics, Model, Options, Output, Scheme, WithEfforts};
use mbs_models::human::*;

#[path = "common/quoted.rs"]
mod quoted;

#[test]
fn curves_meet_their_anchor_points_and_sympy() {
    assert!((muscle::active_force(1.0) - 1.0).abs() < 1e-2);
    assert!(muscle::passive_force(1.0).abs() < 1e-15);
    assert!((muscle::force_velocity(0.0) - 1.0).abs() < 3e-3);
    assert!(muscle::force_velocity(-1.0).abs() < 0.02);
    assert!(muscle::force_velocity(0.5) > 1.2);
    // the tendon carries F_max at about 4.9 % strain
    assert!((muscle::tendon_length(1.0) - 1.049).abs() < 1e-3);
    for x in [-0.2, 0.0, 0.4, 1.0, 1.3] {
        let lt = muscle::tendon_length(x);
        assert!((muscle::tendon_force(lt) - x).abs() < 1e-12);
    }
    for v in [-0.9, -0.3, 0.0, 0.2, 0.8] {
        let fv = muscle::force_velocity(v);
        assert!((muscle::force_velocity_inverse(fv) - v).abs() < 1e-12);
    }
    let rel = |a: f64, b: f64| ((a - b) / b).abs();
    assert!(
        rel(
            muscle::activation_rate(0.7, 0.2, [0.015, 0.06]),
            41.6650777412621
        ) < 1e-12
    );
    // the activation dynamics inverted: the excitation found gives the rate asked, or the
    // bound nearest it where none can
    for a in [0.01, 0.2, 0.5, 0.9] {
        for rate in [-10.0, -1.0, 0.0, 3.0, 40.0] {
            let times = [0.015, 0.06];
            let e = muscle::excitation_for_rate(a, rate, times);
            let (least, most) = (
                muscle::activation_rate(0.0, a, times),
                muscle::activation_rate(1.0, a, times),
            );
            let asked = rate.clamp(least, most);
            let made = muscle::activation_rate(e, a, times);
            assert!(
                (made - asked).abs() < 1e-9 * (1.0 + asked.abs()),
                "{a} {rate}: {made}"
            );
        }
    }
    assert_eq!(muscle::excitation_for_rate(0.5, 1e3, [0.015, 0.06]), 1.0);
    assert_eq!(muscle::excitation_for_rate(0.5, -1e3, [0.015, 0.06]), 0.0);
    // a NaN asked is a NaN answered, not an excitation of 0
    assert!(muscle::excitation_for_rate(f64::NAN, 1.0, [0.015, 0.06]).is_nan());
    assert!(muscle::excitation_for_rate(0.5, f64::NAN, [0.015, 0.06]).is_nan());
    let soleus = Musculotendon::new("soleus", 5137.0, 0.05, 0.25, 0.43633231);
    let vasti = Musculotendon::new("vasti", 5000.0, 0.087, 0.136, 0.05235988);
    for (unit, l, a, lm, force, rate) in [
        (&soleus, 0.30, 0.5, 1.0, 1015.12095423252, -2.81373031198483),
        (
            &soleus,
            0.296,
            0.2,
            0.95,
            662.704494931253,
            -0.915104015066037,
        ),
        (&vasti, 0.226, 0.5, 0.95, 6402.88334287846, 160.609458436052),
    ] {
        let f = unit.fibre(l, a, lm).unwrap();
        assert!(rel(f.tendon_force, force) < 1e-10, "{f:?}");
        assert!(rel(f.length_rate, rate) < 1e-9, "{f:?}");
    }
}

fn posture(model: &Human, joints: &[(&str, f64)]) -> (Vec<f64>, Vec<f64>) {
    let n = Human::NQ;
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    for (name, v) in joints {
        q[model.info().dofs.iter().position(|d| d == name).unwrap()] = *v;
    }
    (q, qd)
}

/// A posture of walking with every coordinate moving.
fn walking_state(model: &Human) -> (Vec<f64>, Vec<f64>) {
    let (mut q, mut qd) = (vec![0.0; Human::NQ], vec![0.0; Human::NQ]);
    model.initial_state(&mut q, &mut qd);
    for i in 0..Human::NQ {
        q[i] += 0.2 * ((1.7 * i as f64).sin());
        qd[i] = (0.9 * i as f64 + 0.3).cos();
    }
    (q, qd)
}

#[test]
fn path_gradients_are_the_derivatives_of_the_lengths() {
    let model = Human::default();
    let muscles = Muscles::new(model.info()).unwrap();
    let (q, qd) = walking_state(&model);
    let n = Human::NQ;
    let mut kin = Kinematics::new::<Human>();
    let length = |q: &[f64], kin: &mut Kinematics| {
        model.kinematics(0.0, q, &qd, kin);
        muscles.lengths(kin)
    };
    model.kinematics(0.0, &q, &qd, &mut kin);
    let mut grads = vec![vec![0.0; n]; NM];
    for (g, (_, path)) in grads.iter_mut().zip(&muscles.units) {
        path.gradient(&kin, g);
        let (_, ld) = path.length(&kin);
        let chain: f64 = g.iter().zip(&qd).map(|(a, b)| a * b).sum();
        assert!(
            (ld - chain).abs() < 1e-12 * (1.0 + ld.abs()),
            "{ld} {chain}"
        );
    }
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for i in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[i] += h;
        qm[i] -= h;
        let (lp, lm) = (length(&qp, &mut kin), length(&qm, &mut kin));
        for m in 0..NM {
            let fd = (lp[m] - lm[m]) / (2.0 * h);
            worst = worst.max((fd - grads[m][i]).abs());
        }
    }
    assert!(worst < 1e-8, "worst difference {worst:e}");
}

#[test]
fn moment_arms_have_the_muscles_anatomical_actions() {
    let model = Human::default();
    let muscles = Muscles::new(model.info()).unwrap();
    let (q, qd) = posture(&model, &[]);
    let mut kin = Kinematics::new::<Human>();
    model.kinematics(0.0, &q, &qd, &mut kin);
    // (joint, muscle, sign of the moment arm about the coordinate): flexion of the hip,
    // extension of the knee and dorsiflexion of the ankle are positive
    let actions = [
        ("hip_flexion", "hamstrings", -1.0),
        ("knee", "hamstrings", -1.0),
        ("knee", "bifemsh", -1.0),
        ("hip_flexion", "glut_max", -1.0),
        ("hip_flexion", "iliopsoas", 1.0),
        ("hip_flexion", "rect_fem", 1.0),
        ("knee", "rect_fem", 1.0),
        ("knee", "vasti", 1.0),
        ("knee", "gastroc", -1.0),
        ("ankle", "gastroc", -1.0),
        ("ankle", "soleus", -1.0),
        ("ankle", "tib_ant", 1.0),
    ];
    for k in 0..2 {
        for (joint, name, sign) in actions {
            let arms = moment_arms(&muscles, model.info(), &kin, &format!("{joint}[{k}]")).unwrap();
            let m = muscles.index(&format!("{name}[{k}]")).unwrap();
            let r = arms[m] * sign;
            assert!(
                (0.01..0.1).contains(&r),
                "{name}[{k}] about {joint}[{k}]: moment arm {:.4} m",
                arms[m]
            );
            // the other leg's muscles do not act on this joint
            assert_eq!(arms[(m + NM / 2) % NM], 0.0);
        }
    }
    // the legs mirror each other
    for (a, b) in muscles.lengths(&kin)[..9]
        .iter()
        .zip(&muscles.lengths(&kin)[9..])
    {
        assert!((a - b).abs() < 1e-12);
    }
}

#[test]
fn a_fibre_at_rest_has_no_length_rate_and_its_tension_is_the_generalised_force() {
    let model = Human::default();
    let (q, qd) = walking_state(&model);
    let mut driven = MuscleDriven {
        passive: PassiveJoints::new(model.info(), 0.1, 0.01).unwrap(),
        muscles: Muscles::new(model.info()).unwrap(),
    };
    driven.muscles.excitation = (0..NM).map(|i| 0.05 + 0.05 * i as f64).collect();
    let mut kin = Kinematics::new::<Human>();
    model.kinematics(0.0, &q, &qd, &mut kin);
    let x = driven.initial_states(0.0, &kin, &qd).unwrap();
    for (i, (unit, path)) in driven.muscles.units.iter().enumerate() {
        let f = unit
            .fibre(path.length(&kin).0, x[17 + i], x[17 + NM + i])
            .unwrap();
        assert!(f.length_rate.abs() < 1e-9, "{}: {f:?}", unit.name);
    }
    // the tension along a path: −T ∂l/∂q
    let n = Human::NQ;
    let pull = Pull {
        path: driven.muscles.units[3].1.clone(),
        tension: 800.0,
    };
    let wrapped = WithEfforts::new(Human::default(), pull.clone());
    let (mut m, mut h, mut h0) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
    wrapped.dynamics(0.0, &q, &qd, &[], &mut m, &mut h);
    model.dynamics(0.0, &q, &qd, &[], &mut m, &mut h0);
    let mut g = vec![0.0; n];
    pull.path.gradient(&kin, &mut g);
    for i in 0..n {
        let q_path = h[i] - h0[i];
        assert!(
            (q_path + pull.tension * g[i]).abs() < 1e-9,
            "{i}: {q_path} {}",
            g[i]
        );
    }
}

/// A constant tension along a path.
#[derive(Clone)]
struct Pull {
    path: Path,
    tension: f64,
}

impl Efforts for Pull {
    const FRAMES: bool = false;
    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        self.path.apply(e, self.tension);
        Ok(())
    }
}

#[test]
fn a_fibre_beyond_its_range_is_a_typed_failure() {
    let unit = Musculotendon::new("soleus", 5137.0, 0.05, 0.25, 0.43633231);
    match unit.fibre(0.3, 0.5, 1.9) {
        Err(MuscleError::FibreOutOfRange { muscle, .. }) => assert_eq!(muscle, "soleus"),
        other => panic!("{other:?}"),
    }
    // a run: the right knee driven into flexion stretches the vasti beyond their range
    let model = Human::default();
    let info = model.info();
    let mut driven = MuscleDriven {
        passive: PassiveJoints::new(info, 0.1, 0.01).unwrap(),
        muscles: Muscles::new(info).unwrap(),
    };
    driven.muscles.excitation = vec![0.02; NM];
    let (mut q, mut qd) = posture(&model, &[]);
    q[1] = 1.5; // in the air
    let knee = info.dofs.iter().position(|d| *d == "knee[0]").unwrap();
    qd[knee] = -6.0;
    let mut kin = Kinematics::new::<Human>();
    model.kinematics(0.0, &q, &qd, &mut kin);
    let x = driven.initial_states(0.0, &kin, &qd).unwrap();
    // the vasti may lengthen by a tenth of their optimal length
    let vasti = driven.muscles.index("vasti[0]").unwrap();
    driven.muscles.units[vasti].0.fibre_range = [0.4, x[17 + NM + vasti] + 0.1];
    let (mut q0, mut qd0) = (q.clone(), qd.clone());
    q0.extend(vec![0.0; x.len()]);
    qd0.extend(x);
    let options = Options {
        q0: Some(q0),
        qd0: Some(qd0),
        output: Output::Every { dt: 0.01 },
        ..Options::adaptive(0.2, 1e-5)
    };
    let err = mbs::simulate(
        WithEfforts::new(Human::default(), driven),
        Scheme::Radau5,
        options,
    )
    .expect_err("the vasti leave their range");
    println!("{err}");
    match &err.kind {
        Failure::EffortRejected { .. } => {}
        other => panic!("{other:?}"),
    }
    let message = err.to_string();
    assert!(
        message.contains("vasti[0]") && message.contains("range"),
        "{message}"
    );
    assert!(err.t > 0.01 && err.trajectory.len() > 1, "{}", err.t);
}

#[test]
fn the_model_stands_on_its_muscles_with_constant_excitations() {
    let model = Human::default();
    let info = model.info();
    let n = Human::NQ;
    // co-contraction: the activations nearest 0.5 that produce the moments (the least Σ a²
    // leaves the knees and ankles with less stiffness, and more poles grow)
    let stance = muscle_stance(&model, 0.1, &[0.5; NM]).unwrap();
    let (driven, moments) = (&stance.driven, &stance.moments);
    let muscles = &driven.muscles;
    // the muscles produce the moments asked, at the held body's posture
    let held = &stance.held;
    let mut kin = Kinematics::new::<Human>();
    model.kinematics(0.0, held, &vec![0.0; n], &mut kin);
    let forces = muscles.forces_at_rest(&kin, &muscles.excitation).unwrap();
    for k in 0..2 {
        for (dof, (_, asked)) in ["hip_flexion", "knee", "ankle"]
            .iter()
            .zip(&moments[3 * k..])
        {
            let arms = moment_arms(muscles, info, &kin, &format!("{dof}[{k}]")).unwrap();
            let made: f64 = arms.iter().zip(&forces).map(|(r, f)| r * f).sum();
            assert!(
                (made - asked).abs() < 1e-6 * (1.0 + asked.abs()),
                "{dof}[{k}]: {made} for {asked}"
            );
        }
    }
    println!("moments asked of the muscles (N·m): {moments:.2?}");
    println!("excitations: {:.3?}", muscles.excitation);
    let (q, qs, qds) = (stance.q[..n].to_vec(), stance.q.clone(), stance.qd.clone());
    // its stability with the fibres' and activations' dynamics: the linearisation's poles
    let lin = mbs::linearize(
        &WithEfforts::new(Human::default(), driven.clone()),
        0.0,
        &qs,
        &qds,
        &[],
        mbs::IterationMatrix::Auto,
    )
    .unwrap();
    let poles = mbs::modes(&lin, None).unwrap();
    let growing: Vec<f64> = poles
        .modes
        .iter()
        .filter(|m| m.re > 0.1)
        .map(|m| m.re)
        .collect();
    let eq = &stance.equilibrium;
    println!(
        "equilibrium on the muscles: {:.2e} from the held body's, {} (stiffness eigenvalues from {:.1}); \
         poles with Re > 0.1/s: {growing:.2?}",
        (0..n)
            .map(|i| (eq.q[i] - held[i]).abs())
            .fold(0.0, f64::max),
        format!("{:?}", eq.stability).to_lowercase(),
        eq.stiffness_eigenvalues[0]
    );
    let wrapped = WithEfforts::new(Human::default(), driven.clone());
    let run = |push: f64, t_end: f64| {
        let mut qd0 = qds.clone();
        qd0[3] += push;
        let options = Options {
            q0: Some(qs.clone()),
            qd0: Some(qd0),
            output: Output::Every { dt: 0.01 },
            ..Options::adaptive(t_end, 1e-6)
        };
        let clock = std::time::Instant::now();
        match mbs::simulate(wrapped.clone(), Scheme::Radau5, options) {
            Ok((tr, stats)) => (tr, stats, clock.elapsed().as_secs_f64()),
            Err(e) => panic!("standing on the muscles failed: {e}"),
        }
    };
    // the largest departure of any body coordinate from the equilibrium at output s
    let departure = |tr: &mbs::Trajectory, s: usize| {
        tr.q(s)[..n]
            .iter()
            .zip(&q)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    let (tr, stats, cpu) = run(0.0, 2.0);
    let last = tr.len() - 1;
    let still = (0..tr.len()).map(|s| departure(&tr, s)).fold(0.0, f64::max);
    let (ql, qdl) = (&tr.q(last)[..n], &tr.qd(last)[..n]);
    let f = ground_forces(&model, tr.t[last], ql, qdl, &mut kin);
    let weight = (75.1646 + 2.0 * 0.0862) * 9.80665;
    println!(
        "standing on 18 muscles at constant excitations 2 s, radau5 rtol 1e-6: {} steps, {cpu:.3} s CPU; \
         largest departure from the equilibrium {still:.1e}; the ground carries {:.6} of the weight",
        stats.steps,
        (f[0][1] + f[1][1]) / weight
    );
    assert!(still < 1e-6, "{still}");
    assert!(((f[0][1] + f[1][1]) / weight - 1.0).abs() < 1e-3);
    // pushed (pelvis pitch rate 1e-4 rad/s), the body departs as the growing pole says
    let (tr, pushed, cpu) = run(1e-4, 1.0);
    let at = |t: f64| departure(&tr, (t / 0.01).round() as usize);
    let lambda = growing.iter().copied().fold(0.0, f64::max);
    let ratio = at(1.0) / at(0.5);
    println!(
        "pushed: departure {:.2e} at 0.5 s, {:.2e} at 1 s: × {ratio:.2} (the pole {lambda:.2}/s says × {:.2}); \
         1 s in {} steps, {cpu:.3} s CPU",
        at(0.5),
        at(1.0),
        (0.5 * lambda).exp(),
        pushed.steps
    );
    assert_eq!(growing.len(), 1, "{growing:?}");
    assert!((ratio / (0.5 * lambda).exp() - 1.0).abs() < 0.2, "{ratio}");
    let says = (0.5 * lambda).exp();
    quoted::says(
        "docs/human_gait.md",
        &[
            format!("(asserted < 1e-6) in {} Radau5 steps", stats.steps),
            format!(
                "the linearisation one growing pole ({lambda:.2}/s), and a body pushed at 1e-4 rad/s departs × {ratio:.2} between 0.5 s and 1 s where the pole says × {says:.2} (asserted within 20 %)"
            ),
        ],
    );
    quoted::says(
        "README.md",
        &[format!(
            "one growing pole of {lambda:.2}/s, and a pushed body departs × {ratio:.2} between 0.5 s and 1 s where the pole says × {says:.2}"
        )],
    );
}

/// OpenSim's moving insertion points of the quadriceps in the tibia's axes (gait10dof18musc,
/// `rect_fem_r-P3` and `vas_int_r-P4`): the knee angles and their x and y (m); the source's
/// table values, not π fractions.
#[allow(clippy::approx_constant)]
const MOVING_KNEE: [f64; 17] = [
    -2.0944, -1.99997, -1.5708, -1.45752, -1.39626, -1.0472, -0.698132, -0.526391, -0.349066,
    -0.174533, 0.0, 0.00017453, 0.00034907, 0.0279253, 0.0872665, 0.174533, 2.0944,
];
const MOVING_POINTS: [(&str, [f64; 17], [f64; 17]); 2] = [
    (
        "rf_i[0]",
        [
            0.0155805, 0.0179938, 0.0275081, 0.0296564, 0.0307615, 0.0365695, 0.0422074, 0.0450902,
            0.048391, 0.0534299, 0.0617576, 0.0617669, 0.0617762, 0.0633083, 0.066994, 0.0733035,
            0.0573481,
        ],
        [
            0.0234116, 0.0237613, 0.0251141, 0.0252795, 0.0253146, 0.0249184, 0.0242373, 0.0238447,
            0.0234197, 0.0227644, 0.020984, 0.0209814, 0.0209788, 0.0205225, 0.0191754, 0.0159554,
            -0.0673774,
        ],
    ),
    (
        "vas_i[0]",
        [
            0.0082733, 0.0106866, 0.0202042, 0.022353, 0.0234583, 0.0292715, 0.0349465, 0.037871,
            0.0412569, 0.0465287, 0.0554632, 0.0554735, 0.0554837, 0.0571717, 0.061272, 0.0684368,
            0.0648818,
        ],
        [
            0.025599, 0.0259487, 0.0273124, 0.0274796, 0.0275151, 0.0271363, 0.0265737, 0.0263073,
            0.0261187, 0.0260129, 0.0252923, 0.0252911, 0.0252898, 0.0250526, 0.0242191, 0.0218288,
            -0.0685706,
        ],
    ),
];

#[test]
fn the_quadriceps_insert_where_opensims_moving_points_are() {
    use mbs::spline::{evaluate, natural_coefficients};
    let model = Human::default();
    let info = model.info();
    let n = Human::NQ;
    let knee = info.dofs.iter().position(|d| *d == "knee[0]").unwrap();
    let tibia = info.frame_index("tibia_o[0]").unwrap();
    let mut kin = Kinematics::new::<Human>();
    let mut worst: f64 = 0.0;
    for (point, xs, ys) in MOVING_POINTS {
        let p = info.point_index(point).unwrap();
        let table =
            |v: [f64; 17]| -> Vec<(f64, f64)> { MOVING_KNEE.iter().copied().zip(v).collect() };
        let (cx, cy) = (
            natural_coefficients(&table(xs)).unwrap(),
            natural_coefficients(&table(ys)).unwrap(),
        );
        // knee flexion from 3° of extension to 75°
        for s in 0..=60 {
            let a = 0.0524 - (0.0524 + 1.309) * s as f64 / 60.0;
            let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
            model.initial_state(&mut q, &mut qd);
            q[knee] = a;
            model.kinematics(0.0, &q, &qd, &mut kin);
            // the point in the tibia's axes
            let f = &kin.frames[tibia].pose;
            let d = [0, 1, 2].map(|i| kin.points[p].position[i] - f.position[i]);
            let local = [0, 1].map(|j| (0..3).map(|i| f.rotation[i][j] * d[i]).sum::<f64>());
            let opensim = [
                evaluate(&MOVING_KNEE, &cx, 0, a),
                evaluate(&MOVING_KNEE, &cy, 0, a),
            ];
            worst = worst.max((local[0] - opensim[0]).hypot(local[1] - opensim[1]));
        }
    }
    println!(
        "quadriceps' insertions on the patella against OpenSim's moving points (natural cubic splines), knee −75°…3°: within {:.2} mm",
        1e3 * worst
    );
    assert!(worst < 1.5e-3, "{worst}");
    let mm = 1e3 * worst;
    quoted::says(
        "docs/human_gait.md",
        &[
            format!("which follows OpenSim's moving insertion points within {mm:.1} mm"),
            format!("insertions against OpenSim's moving points ({mm:.2} mm, asserted < 1.5 mm)"),
        ],
    );
    quoted::says(
        "README.md",
        &[format!(
            "the quadriceps' moving insertions against OpenSim's ({mm:.2} mm)"
        )],
    );
}

/// A unit's invalid parameters, a non-finite input, and a tendon pulling more than any fibre
/// speed balances are typed errors (before: a NaN path length gave the fibre range's lower
/// end as an equilibrium, and a stretched tendon at low activation an infinite rate).
#[test]
fn a_units_bad_parameters_and_inputs_are_typed_errors() {
    let unit = Musculotendon::new("soleus", 5137.0, 0.05, 0.25, 0.43633);
    let e = unit.equilibrium(f64::NAN, 0.5).unwrap_err();
    assert!(matches!(e, MuscleError::NotFinite { .. }), "{e}");
    let e = unit.fibre(0.3, f64::INFINITY, 1.0).unwrap_err();
    assert!(matches!(e, MuscleError::NotFinite { .. }), "{e}");
    for (bad, name) in [
        (
            Musculotendon {
                tendon_slack_length: 0.0,
                ..unit.clone()
            },
            "tendon_slack_length",
        ),
        (
            Musculotendon {
                pennation_angle: f64::NAN,
                ..unit.clone()
            },
            "pennation_angle",
        ),
        (
            Musculotendon {
                activation_times: [0.0, 0.06],
                ..unit.clone()
            },
            "activation_times[0]",
        ),
        (
            Musculotendon {
                fibre_range: [0.4, f64::NAN],
                ..unit.clone()
            },
            "fibre_range[1]",
        ),
    ] {
        for e in [
            bad.fibre(0.3, 0.5, 1.0).unwrap_err(),
            bad.equilibrium(0.3, 0.5).unwrap_err(),
        ] {
            assert!(
                matches!(&e, MuscleError::InvalidParameter { name: n, .. } if *n == name),
                "{name}: {e}"
            );
        }
    }
    // at the lowest activation, a tendon stretched by 8 %: its pull is beyond any fibre speed
    let e = unit.fibre(0.3153, 0.0, 1.0).unwrap_err();
    assert!(matches!(e, MuscleError::NoFibreSpeed { .. }), "{e}");
    assert!(unit.fibre(0.3153, 1.0, 1.0).is_ok());
}
