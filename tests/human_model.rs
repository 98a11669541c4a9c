//! The human lower-limb model (`mbs_models::human`): its data, its spline knee and patella,
//! its foot contacts, and standing on them.
//!
//! - the mass matrix' translation block is the total mass of gait2392's segments plus the
//!   patellas;
//! - the tibia's origin and the patella sit on their splines' points;
//! - the ground reaction recomputed from the kinematics equals the generated contacts';
//! - the gait table's Fourier fit reproduces the samples;
//! - with its joints held (ankles dorsiflexed 0.1 rad, the body leaning forward as one
//!   piece) the model stands on its twelve ellipsoids: the ground carries its weight, half on
//!   each foot, the pelvis stays within a centimetre;
//! - passive joint moments: the law by hand, the viscous states' relaxation along a run,
//!   and a collapsing body caught near its joints' ranges (without them its toes spin);
//! - a knee beyond its splines' tables, a foot through the ground and a body fallen through
//!   it are typed failures;
//! - the symmetric grounded cycle levels the feet in double support and keeps them from
//!   sliding apart, lifts the swinging foot and keeps the centre of mass' acceleration
//!   within the bounds asked, at nearly the published walking speed;
//! - the prescribed cycle (mode 1, as the gait program runs it) gives each foot a normal
//!   double hump, braking then propulsion, and the weight's vertical impulse; on muscles
//!   (the tracking as reserves, the excitations made to lead the activations by their
//!   dynamics) the reserves carry less than 40 % of the moments (rms), the walk unchanged;
//! - with its residual torques reduced by corrections of the leg joints, the pressed cycle
//!   walks a normal cycle with the pelvis wholly free, where the cycle as it was does not;
//! - residual torques hold the pelvis on its reference orientation;
//! - in flight, the angular momentum about the centre of mass (`Centroid`) is conserved.

// the knots below are the sources' numbers (−1.0472 is a table value, not −π/3)
#![allow(clippy::approx_constant)]

use mbs::{Efforts, Kinematics, Model, Options, Output, Scheme};
use mbs_models::human::*;

#[path = "common/quoted.rs"]
mod quoted;
use quoted::thousands;

/// `x` to `digits` decimals with its sign, a minus as the documents write it: −0.15, +0.28.
fn signed(x: f64, digits: usize) -> String {
    quoted::minus(format!("{x:+.digits$}"))
}

/// A foot's figure to two decimals, as the documents write it.
fn two(x: Option<f64>) -> String {
    format!("{:.2}", x.expect("the figure was reached"))
}

/// A foot's force figure to two decimals with its sign: −0.15, +0.28.
fn two_signed(x: Option<f64>) -> String {
    signed(x.expect("the figure was reached"), 2)
}

/// `[lo, hi]` as the documents write it: −0.15…+0.18, or ±0.10 when symmetric.
fn span([lo, hi]: [f64; 2], digits: usize) -> String {
    let (l, h) = (signed(lo, digits), signed(hi, digits));
    if l.strip_prefix('−') == h.strip_prefix('+') {
        format!("±{}", &h[1..])
    } else {
        format!("{l}…{h}")
    }
}

const G: f64 = 9.80665;
/// gait2392's 75.1646 kg and two patellas of 0.0862 kg (Rajagopal 2015)
const MASS: f64 = 75.1646 + 2.0 * 0.0862;

fn frame(model: &Human, kin: &Kinematics, name: &str) -> mbs::Pose {
    kin.frames[model.info().frame_index(name).expect(name)].pose
}

/// `b`'s origin in `a`'s axes.
fn relative(a: &mbs::Pose, b: &mbs::Pose) -> [f64; 3] {
    let d = [0, 1, 2].map(|i| b.position[i] - a.position[i]);
    [0, 1, 2].map(|j| (0..3).map(|i| a.rotation[i][j] * d[i]).sum())
}

/// Whether a figure was reached and lies in [lo, hi].
fn within(x: Option<f64>, lo: f64, hi: f64) -> bool {
    x.is_some_and(|v| v >= lo && v <= hi)
}

/// The model as mode 1 runs it: its feet dissipating [`GAIT_DISSIPATION`].
fn gait_model() -> Human {
    let mut model = Human::default();
    let mut params = model.params().clone();
    params.d_foot = GAIT_DISSIPATION;
    model.set_params(params).unwrap();
    model
}

/// A foot's double hump in the normal ranges, its first peak within `first` (1.0–1.3 is
/// normal): a trough of 0.6–0.9 and a second peak of 1.0–1.3 body weights, braking then
/// propulsion.
fn double_hump(g: &FootFigures, first: [f64; 2]) -> bool {
    within(g.first_peak, first[0], first[1])
        && within(g.trough, 0.6, 0.9)
        && within(g.second_peak, 1.0, 1.3)
        && within(g.braking, -0.3, -0.05)
        && within(g.propulsion, 0.05, 0.4)
}

/// Every joint held on `reference` by stiff spring–dampers (the toes' too), the pelvis free.
fn held(reference: GaitReference) -> Tracking {
    Tracking::new(reference, Human::default().info(), 3000.0, 30.0).unwrap()
}

#[test]
fn masses_and_the_knee_follow_their_sources() {
    let model = Human::default();
    let n = Human::NQ;
    assert_eq!(n, 23);
    assert_eq!(
        model
            .info()
            .frames
            .iter()
            .zip(model.info().is_body)
            .filter(|(_, b)| **b)
            .count(),
        14
    );
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    let mut m = vec![0.0; n * n];
    model.mass_matrix(0.0, &q, &mut m);
    for i in 0..3 {
        assert!(
            (m[i + n * i] - MASS).abs() < 1e-9,
            "M[{i}][{i}] = {}",
            m[i + n * i]
        );
    }
    // the tibia's origin in the femur's axes at knee angles on the knots of gait2392's
    // splines; the patella's on Rajagopal's (flexion b = −knee)
    let knee = model
        .info()
        .dofs
        .iter()
        .position(|d| *d == "knee[0]")
        .unwrap();
    let mut kin = Kinematics::new::<Human>();
    // knots of both splines: −0.174533 and −0.349066 (x: −0.0031, −0.001; y: −0.3966,
    // −0.3976); −1.0472 is a knot of x only (0.0041)
    for (a, x, y) in [
        (-0.174533, -0.0031, Some(-0.3966)),
        (-0.349066, -0.001, Some(-0.3976)),
        (-1.0472, 0.0041, None),
    ] {
        q[knee] = a;
        model.kinematics(0.0, &q, &qd, &mut kin);
        let femur = frame(&model, &kin, "femur_o[0]");
        let r = relative(&femur, &frame(&model, &kin, "tibia_o[0]"));
        assert!((r[0] - x).abs() < 1e-12, "knee_x({a}) = {}", r[0]);
        if let Some(y) = y {
            assert!((r[1] - y).abs() < 1e-12, "knee_y({a}) = {}", r[1]);
        }
    }
    // patella at b = 1.0472 (knee −1.0472): origin (−0.00809 + 0.0136, −0.40796 − 0.0408)
    // then turned by −0.747244 about z, its centre of mass (0.0018, 0.0264) from there
    q[knee] = -1.0472;
    model.kinematics(0.0, &q, &qd, &mut kin);
    let femur = frame(&model, &kin, "femur_o[0]");
    let p = relative(&femur, &frame(&model, &kin, "patella[0]"));
    let (s, c) = (-0.747244f64).sin_cos();
    let expect = [
        -0.00809 + 0.0136 + c * 0.0018 - s * 0.0264,
        -0.40796 - 0.0408 + s * 0.0018 + c * 0.0264,
    ];
    assert!(
        (p[0] - expect[0]).abs() < 1e-12 && (p[1] - expect[1]).abs() < 1e-12,
        "{p:?} vs {expect:?}"
    );
}

#[test]
fn recomputed_ground_forces_equal_the_generated_contacts() {
    // at rest (qd = 0) the translation rows of the static forces are m g plus the contacts'
    // total force: compare with the sum over both feet of the Rust recomputation, at poses
    // of the gait cycle pressed into the ground
    let model = Human::default();
    let n = Human::NQ;
    let reference = GaitReference::fit(&GaitTable::normal(), model.info(), 1.1, 8).unwrap();
    let mut kin = Kinematics::new::<Human>();
    let mut checked = 0;
    for phase in [0.0, 0.1, 0.3, 0.5, 0.8] {
        let mut r = reference.clone();
        r.offset = phase * r.period;
        let (mut q, _) = cycle_start(&model, &r);
        q[1] -= 0.004;
        let qd = vec![0.0; n];
        let mut h = vec![0.0; n];
        model.static_forces(0.0, &q, &[], &mut h);
        let f = ground_forces(&model, 0.0, &q, &qd, &mut kin);
        let total = [0, 1, 2].map(|j| f[0][j] + f[1][j]);
        let generated = [h[0], h[1] + MASS * G, h[2]];
        assert!(
            total[1] > 100.0,
            "pressed into the ground at phase {phase}: {total:?}"
        );
        for j in 0..3 {
            assert!(
                (total[j] - generated[j]).abs() < 1e-9 * total[1],
                "phase {phase}, axis {j}: {} vs {}",
                total[j],
                generated[j]
            );
        }
        checked += 1;
    }
    assert_eq!(checked, 5);
}

#[test]
fn the_fourier_fit_reproduces_the_gait_table() {
    let table = GaitTable::normal();
    assert_eq!(table.rows.len(), 51);
    let t = table.column("time").unwrap();
    let mut worst = 0.0f64;
    for name in [
        "hip_flexion_r",
        "knee_angle_r",
        "ankle_angle_r",
        "hip_adduction_l",
        "lumbar_extension",
    ] {
        let col = table.column(name).unwrap();
        let f = Fourier::fit(&col[..50], 8, 1.0);
        for (ti, y) in t.iter().zip(&col).take(50) {
            worst = worst.max((f.eval(*ti)[0] - y).abs());
            // the value alone is the same sum, to the bit
            assert_eq!(f.value(*ti), f.eval(*ti)[0]);
        }
        // derivatives: central differences of the series itself
        let d = 1e-5;
        let [_, v, a] = f.eval(0.37);
        let fd = (f.eval(0.37 + d)[0] - f.eval(0.37 - d)[0]) / (2.0 * d);
        let fdd = (f.eval(0.37 + d)[1] - f.eval(0.37 - d)[1]) / (2.0 * d);
        assert!(
            (v - fd).abs() < 1e-5 * v.abs().max(1.0) && (a - fdd).abs() < 1e-4 * a.abs().max(1.0)
        );
    }
    println!("8 harmonics: largest deviation from the table {worst:.3}°");
    assert!(worst < 1.0, "{worst}°");
    quoted::says(
        "docs/human_gait.md",
        &[format!(
            "deviation from the table ({worst:.2}° with 8 harmonics, asserted < 1°)"
        )],
    );
}

#[test]
fn the_model_stands_on_its_feet() {
    let model = Human::default();
    let n = Human::NQ;
    let reference = GaitReference::still(model.info(), 0.1).unwrap();
    let (q0, qd0) = cycle_start(&model, &reference);
    assert!(qd0.iter().all(|v| *v == 0.0));
    let tracking = held(reference);
    let mut q = q0.clone();
    q.resize(n, 0.0);
    let options = Options {
        q0: Some(q0.clone()),
        qd0: Some(qd0),
        output: Output::Every { dt: 0.01 },
        ..Options::adaptive(3.0, 1e-5)
    };
    let (tr, stats) = mbs::simulate(
        mbs::WithEfforts::new(Human::default(), tracking),
        Scheme::Radau5,
        options,
    )
    .expect("standing is a regular run");
    // no walking speed to normalise the angular momentum by
    assert!(normalised_angular_momentum(&model, &tr, 1.1).is_none());
    let last = tr.len() - 1;
    let (ql, qdl) = (&tr.q(last)[..n], &tr.qd(last)[..n]);
    let mut kin = Kinematics::new::<Human>();
    let f = ground_forces(&model, tr.t[last], ql, qdl, &mut kin);
    let weight = MASS * G;
    println!(
        "standing 3 s, radau5 rtol 1e-5: {} steps; pelvis pitch {:+.3e} rad, moved ({:+.2e}, {:+.2e}, {:+.2e}) m; \
         ground carries {:.4} and {:.4} of the weight (right, left)",
        stats.steps,
        ql[3],
        ql[0] - q0[0],
        ql[1] - q0[1],
        ql[2] - q0[2],
        f[0][1] / weight,
        f[1][1] / weight
    );
    println!(
        "at the end: pelvis velocity ({:+.2e}, {:+.2e}) m/s, pitch rate {:+.2e} rad/s (a slow rocking that decays)",
        qdl[0], qdl[1], qdl[3]
    );
    assert!(((f[0][1] + f[1][1]) / weight - 1.0).abs() < 0.01);
    // symmetric stance: each foot about half
    assert!((f[0][1] / weight - 0.5).abs() < 0.05 && (f[1][1] / weight - 0.5).abs() < 0.05);
    let shares = [f[0][1] / weight, f[1][1] / weight].map(|s| format!("{s:.4}"));
    assert_eq!(
        shares[0], shares[1],
        "the documents say each foot carries as much"
    );
    let moved = (0..3).map(|j| (ql[j] - q0[j]).abs()).fold(0.0, f64::max);
    quoted::says(
        "docs/human_gait.md",
        &[format!(
            "({} Radau5 steps; the ground carries {} of the weight on each foot, asserted within 1 % in total and 5 % per foot; the pelvis moves {:.1} mm, asserted < 1 cm)",
            stats.steps,
            shares[0],
            1e3 * moved
        )],
    );
    quoted::says(
        "README.md",
        &[format!(
            "the model stands 3 s on its twelve ellipsoids with its joints held, the ground carrying {} of the weight on each foot",
            shares[0]
        )],
    );
    for j in 0..3 {
        assert!((ql[j] - q0[j]).abs() < 0.01, "pelvis drifted along {j}");
        assert!(
            qdl[j].abs() < 1e-2,
            "pelvis still moving along {j}: {}",
            qdl[j]
        );
    }
}

#[test]
fn passive_moments_follow_their_law_and_relax_toward_it() {
    let model = Human::default();
    let info = model.info();
    let passive = PassiveJoints::new(info, 0.1, 0.01).unwrap();
    // the law by hand: the knee 0.07 rad beyond its upper end pushes back into flexion
    let knee = PASSIVE_LAWS.iter().find(|(n, _)| *n == "knee").unwrap().1;
    let by_hand = -6.09 * (33.94f64 * 0.07).exp() + 11.03 * (-11.33f64 * 2.6).exp();
    assert!((knee.elastic(0.2) - by_hand).abs() < 1e-12 * by_hand.abs());
    assert!(knee.elastic(0.2) < -60.0 && knee.elastic(-1.0).abs() < 0.2);
    // the viscous states, started at 0.5 N·m, relax toward −d q̇ with T = 10 ms: compared
    // along a run (joints held by stiff tracking) with v' = −(v + d q̇)/T integrated between
    // outputs (exponential integrator, q̇ linear between them)
    let n = Human::NQ;
    let reference = GaitReference::still(info, 0.1).unwrap();
    let (q0, qd0) = cycle_start(&model, &reference);
    let mut drive = passive.clone();
    drive.tracking = Some(held(reference));
    let (mut q, mut qd) = (q0.clone(), qd0.clone());
    q.resize(n + 17, 0.0);
    qd.resize(n + 17, 0.5);
    let options = Options {
        q0: Some(q),
        qd0: Some(qd),
        output: Output::Every { dt: 1e-4 },
        ..Options::adaptive(0.05, 1e-8)
    };
    let (tr, _) = mbs::simulate(
        mbs::WithEfforts::new(Human::default(), drive),
        Scheme::Radau5,
        options,
    )
    .expect("a regular run");
    let mut worst = 0.0f64;
    for (s, (k, _)) in passive.joints.iter().enumerate() {
        let target = |i: usize| -passive.damping * tr.qd(i)[*k];
        let mut v = 0.5;
        for i in 1..tr.len() {
            let h = tr.t[i] - tr.t[i - 1];
            let e = (-h / 0.01f64).exp();
            v = e * v + (1.0 - e) * 0.5 * (target(i - 1) + target(i));
            worst = worst.max((tr.qd(i)[n + s] - v).abs());
        }
    }
    let last = tr.len() - 1;
    println!(
        "viscous states from 0.5 N·m: {:.4} N·m at t = 5T (e^-5 · 0.5 = {:.4}); largest \
         difference from their relaxation along the run, over 17 joints, {worst:.2e} N·m",
        tr.qd(last)[n + 9],
        0.5 * (-5.0f64).exp()
    );
    assert!(worst < 1e-3, "{worst}");
}

/// The farthest any of the 17 joints goes beyond its passive range, in a run (rad), and
/// which joint.
fn beyond_range(
    tr: &mbs::Trajectory,
    passive: &PassiveJoints,
    info: &mbs::ModelInfo,
) -> (f64, String) {
    let mut worst = (0.0f64, String::new());
    for i in 0..tr.len() {
        for (j, l) in &passive.joints {
            let q = tr.q(i)[*j];
            let out = (l.range[0] - q).max(q - l.range[1]);
            if out > worst.0 {
                worst = (out, info.dofs[*j].to_string());
            }
        }
    }
    worst
}

#[test]
fn passive_moments_catch_a_collapsing_body_near_its_joints_ranges() {
    let model = Human::default();
    let info = model.info();
    let n = Human::NQ;
    let passive = PassiveJoints::new(info, 0.1, 0.01).unwrap();
    let reference = GaitReference::still(info, 0.1).unwrap();
    let (q0, qd0) = cycle_start(&model, &reference);
    // until the knees, flexing, near the end of the tables of their splines (the guard stops
    // the run there: see the next test)
    let t_end = 0.4;
    let options = |q: Vec<f64>, qd: Vec<f64>| Options {
        q0: Some(q),
        qd0: Some(qd),
        output: Output::Every { dt: 0.005 },
        ..Options::adaptive(t_end, 1e-5)
    };
    // without passive moments the body folds freely
    let free = mbs::simulate(
        Human::default(),
        Scheme::Radau5,
        options(q0.clone(), qd0.clone()),
    );
    let free = match free {
        Ok((tr, _)) => tr,
        Err(e) => (*e.trajectory).clone(),
    };
    let (mut q, mut qd) = (q0.clone(), qd0.clone());
    q.resize(n + 17, 0.0);
    qd.extend(passive.relaxed(&qd0));
    let held = mbs::simulate(
        mbs::WithEfforts::new(Human::default(), passive.clone()),
        Scheme::Radau5,
        options(q, qd),
    );
    let (held, stats) = match held {
        Ok((tr, st)) => (tr, st),
        Err(e) => panic!("with passive moments the collapse is a regular run: {e}"),
    };
    let (a, wa) = beyond_range(&free, &passive, info);
    let (b, wb) = beyond_range(&held, &passive, info);
    println!(
        "collapse for {t_end} s: without passive moments a joint goes {a:.3} rad beyond its range ({wa}, to t = {:.2}); with them {b:.3} rad ({wb}, to t = {:.2}, {} steps)",
        free.t.last().unwrap(),
        held.t.last().unwrap(),
        stats.steps
    );
    // the toes spin freely without them; with them the run goes to its end
    assert!(a > 3.0, "{a}");
    assert_eq!(*held.t.last().unwrap(), t_end);
    assert!(b < 0.5, "{b} rad beyond ({wb})");
    assert!(
        wa.starts_with("mtp"),
        "the documents say the toes spin: {wa}"
    );
    quoted::says(
        "docs/human_gait.md",
        &[format!(
            "in 0.4 s of a collapse they keep every joint within {b:.2} rad of its range (asserted < 0.5) where without them the toes spin {a:.1} rad beyond theirs"
        )],
    );
}

#[test]
fn a_knee_beyond_its_tables_or_a_foot_through_the_ground_is_a_typed_failure() {
    let model = Human::default();
    let info = model.info();
    let n = Human::NQ;
    let run = |tracking: Tracking, q0: Vec<f64>, qd0: Vec<f64>| {
        let options = Options {
            q0: Some(q0),
            qd0: Some(qd0),
            output: Output::Every { dt: 0.01 },
            ..Options::adaptive(1.0, 1e-5)
        };
        mbs::simulate(
            mbs::WithEfforts::new(Human::default(), tracking),
            Scheme::Radau5,
            options,
        )
        .expect_err("the guard stops the run")
    };
    // the right knee driven toward −2.3 rad (flexion beyond the tables' −2.0944)
    let mut bent = GaitReference::still(info, 0.1).unwrap();
    let (q0, qd0) = cycle_start(&model, &bent);
    let knee = info.dofs.iter().position(|d| *d == "knee[0]").unwrap();
    let k = bent.joints.iter().position(|(i, _)| *i == knee).unwrap();
    bent.joints[k].1 = Fourier::fit(&[-2.3; 4], 0, 1.0);
    // in the air, so that the knee passes its tables before a foot lands
    let mut up = q0.clone();
    up[1] += 0.3;
    let e = run(held(bent), up, qd0.clone());
    println!("{e}");
    assert!(matches!(e.kind, mbs::Failure::EffortRejected { .. }), "{e}");
    assert!(e.to_string().contains("knee[0]"), "{e}");
    assert!(
        e.t > 0.0 && e.trajectory.len() > 1,
        "the run until then is kept"
    );
    // the standing body started 3 cm into the ground
    let reference = GaitReference::still(info, 0.1).unwrap();
    let mut q = q0.clone();
    q[1] -= 0.03;
    let e = run(held(reference), q, qd0);
    println!("{e}");
    assert!(matches!(e.kind, mbs::Failure::EffortRejected { .. }), "{e}");
    assert!(e.to_string().contains("into the ground"), "{e}");
    // the body dropped upside down from a metre: its torso reaches the ground first, and
    // nothing but the feet meets the ground
    let reference = GaitReference::still(info, 0.1).unwrap();
    let mut q = q0.clone();
    q[1] = 1.0;
    q[5] = std::f64::consts::PI;
    let e = run(held(reference), q, vec![0.0; n]);
    println!("{e}");
    assert!(matches!(e.kind, mbs::Failure::EffortRejected { .. }), "{e}");
    assert!(e.to_string().contains("frame torso"), "{e}");
    assert!(e.t > 0.3 && e.trajectory.len() > 1, "the fall is kept");
}

/// The lowest support point of each foot at `t` on `reference` (pelvis at the model's start).
/// OpenSim's normal cycle over `period`, fitted and made symmetric as mode 1 runs it.
fn normal_cycle(model: &Human, period: f64) -> GaitReference {
    let info = model.info();
    GaitReference::fit(&GaitTable::normal(), info, period, FIT_HARMONICS)
        .unwrap()
        .symmetric(info)
        .unwrap()
}

fn lowest_points(model: &Human, reference: &GaitReference, t: f64) -> [f64; 2] {
    let (q, qd) = reference_state(model, reference, t);
    let mut kin = Kinematics::new::<Human>();
    model.kinematics(0.0, &q, &qd, &mut kin);
    let sp = support_points(model, &kin);
    [0, 1].map(|k| {
        sp[k]
            .iter()
            .map(|(x, _)| x[1])
            .fold(f64::INFINITY, f64::min)
    })
}

#[test]
fn the_grounded_cycle_levels_the_feet_keeps_them_together_and_bounds_the_centre_of_mass() {
    let model = Human::default();
    let fitted = normal_cycle(&model, 1.1);
    // no iteration: the measures of the fitted cycle itself
    let raw = fitted
        .grounded(
            &model,
            &Grounding {
                iterations: 0,
                ..Default::default()
            },
        )
        .unwrap();
    let how = Grounding::default();
    let g = fitted.grounded(&model, &how).unwrap();
    for (what, g) in [("fitted", &raw), ("grounded", &g)] {
        println!(
            "{what} cycle ({} iterations, angles corrected by up to {:.1}°): {:.2} m/s; in double support feet \
             level within {:.1} mm, sliding apart at up to {:.2} m/s; swing clearance at least {:+.1} mm from \
             the asked; centre of mass accelerating within {:.2?} g (fore–aft, vertical, lateral)",
            g.iterations,
            g.largest_change.to_degrees(),
            g.speed,
            1e3 * g.level,
            g.slip,
            1e3 * g.clearance,
            g.acceleration,
        );
    }
    assert!(
        raw.level > 0.02 && raw.clearance < -0.02 && raw.slip > 0.5,
        "{raw:?}"
    );
    assert!(
        g.level < 0.005 && g.clearance > -0.002 && g.slip < 0.05,
        "{g:?}"
    );
    for (axis, (a, bound)) in g.acceleration.iter().zip(how.max_acceleration).enumerate() {
        assert!(
            a[0] > -bound - 0.02 && a[1] < bound + 0.02,
            "axis {axis}: {a:?} against ± {bound}"
        );
    }
    // converged, not stopped by the bound on iterations; the walking speed within 10 %
    assert!(g.iterations < how.iterations, "{}", g.iterations);
    assert!(
        (g.speed / raw.speed - 1.0).abs() < 0.1,
        "{} {}",
        g.speed,
        raw.speed
    );
    assert!(g.largest_change < 20f64.to_radians());
    let [ra, rv, _] = raw.acceleration;
    let [ga, gv, gl] = g.acceleration;
    let widest = g
        .acceleration
        .iter()
        .flatten()
        .fold(0.0f64, |m, a| m.max(a.abs()));
    quoted::says(
        "docs/human_gait.md",
        &[
            format!(
                "in double support one foot is up to {:.1} cm above the other and the two slide apart at up to {:.2} m/s, the swinging foot falls up to {:.1} cm short of the clearance asked (2 cm at mid-swing), and the centre of mass, carried by the standing foot, accelerates by {} g fore–aft and {} g vertically",
                1e2 * raw.level,
                raw.slip,
                -1e2 * raw.clearance,
                span(ra, 1),
                span(rv, 1)
            ),
            format!(
                "(Levenberg–Marquardt over the cycle, up to {:.1}°, {} iterations,",
                g.largest_change.to_degrees(),
                g.iterations
            ),
            format!(
                "in double support the feet are level within {:.1} mm and slide apart at {:.2} m/s at most, the swinging foot clears within {:.1} mm of the height asked, the centre of mass accelerates within {} g fore–aft, {} g vertically and {} g laterally",
                1e3 * g.level,
                g.slip,
                -1e3 * g.clearance,
                span(ga, 2),
                span(gv, 2),
                span(gl, 2)
            ),
            format!(
                "the walking speed stays near the published one ({:.2} against {:.2} m/s)",
                g.speed, raw.speed
            ),
        ],
    );
    quoted::says(
        "README.md",
        &[format!(
            "(Levenberg–Marquardt over the cycle, up to {:.1}°) until the feet are level and together in double support and the centre of mass accelerates within ±{widest:.2} g",
            g.largest_change.to_degrees()
        )],
    );
    // what the cycle still asks of the ground: the centre of pressure its motion needs lies
    // beyond the standing feet (the residual torques supply that moment), less so than the
    // fitted cycle's, whose vertical force nearly vanishes at instants
    println!(
        "centre of pressure beyond the standing feet (fore–aft, lateral): fitted {:.2?} m, grounded {:.3?} m; \
         free moment up to {:.0} and {:.0} N·m",
        raw.pressure_beyond, g.pressure_beyond, raw.free_moment, g.free_moment
    );
    assert!(
        (0..2)
            .all(|k| g.pressure_beyond[k].is_finite()
                && g.pressure_beyond[k] < raw.pressure_beyond[k])
            && g.free_moment.is_finite(),
        "{:?} {:?}",
        g.pressure_beyond,
        raw.pressure_beyond
    );
    quoted::says(
        "docs/human_gait.md",
        &[format!(
            "It lies up to {:.2} m beside the standing foot's support (the soft maximum of its ellipsoids' support points within about 1 mm of its lowest) and {:.2} m beyond it fore–aft, and the motion needs a free moment about the vertical of up to {:.0} N·m (the published cycle before the corrections: {:.1} and {:.1} m,",
            g.pressure_beyond[1],
            g.pressure_beyond[0],
            g.free_moment,
            raw.pressure_beyond[0],
            raw.pressure_beyond[1]
        )],
    );
    quoted::says(
        "docs/status.md",
        &[format!(
            "because the cycle needs its centre of pressure up to {:.2} m beside the standing foot",
            g.pressure_beyond[1]
        )],
    );
    // asked of the grounded cycle, the pass puts that centre of pressure within the feet
    // and lowers the free moment, keeping the feet level and together and the speed
    let clock = std::time::Instant::now();
    let pressed = g
        .reference
        .grounded(
            &model,
            &Grounding {
                pressure: [30.0, 10.0],
                ..Default::default()
            },
        )
        .unwrap();
    println!(
        "pressed ({} iterations, {:.1} s, angles corrected by up to {:.1}° more): centre of pressure beyond \
         the standing feet {:.4?} m, free moment up to {:.0} N·m; {:.2} m/s, feet level within {:.1} mm, \
         sliding apart at up to {:.2} m/s, clearance {:+.1} mm, accelerations {:.2?} g",
        pressed.iterations,
        clock.elapsed().as_secs_f64(),
        pressed.largest_change.to_degrees(),
        pressed.pressure_beyond,
        pressed.free_moment,
        pressed.speed,
        1e3 * pressed.level,
        pressed.slip,
        1e3 * pressed.clearance,
        pressed.acceleration
    );
    assert!(
        pressed.pressure_beyond.iter().all(|b| *b < 0.005)
            && pressed.free_moment < 0.5 * g.free_moment,
        "{pressed:?}"
    );
    assert!(
        pressed.level < 0.005 && pressed.clearance > -0.002 && pressed.slip < 0.05,
        "{pressed:?}"
    );
    assert!(
        (pressed.speed / raw.speed - 1.0).abs() < 0.15,
        "{}",
        pressed.speed
    );
    quoted::says(
        "docs/human_gait.md",
        &[
            format!("in {} more iterations (", pressed.iterations),
            format!(
                "up to {:.1}° more of angle) the centre of pressure lies within {:.1} mm of the feet's support and the free moment needed falls to {:.0} N·m, the feet stay level within {:.1} mm and together within {:.2} m/s, the speed {:.2} m/s",
                pressed.largest_change.to_degrees(),
                1e3 * pressed.pressure_beyond[0].max(pressed.pressure_beyond[1]),
                pressed.free_moment,
                1e3 * pressed.level,
                pressed.slip,
                pressed.speed
            ),
        ],
    );
    // the corrected series are what the pass measured: the reference at an instant of
    // double support has its feet level
    let [right, left] = lowest_points(&model, &g.reference, 0.05 * 1.1);
    assert!((right - left).abs() < 0.005, "{right} {left}");

    // the pressed cycle walks with the pelvis free to pitch and roll on the balance
    // controller, the residual torque about the vertical alone holding its turn, into a
    // steady walk (`human_gait -- --pressure 30 --free 10 --pelvis-axes 0,1,0 --balance
    // --cycles 4`)
    let walker = gait_model();
    let info = walker.info();
    let reference = pressed.reference;
    let mut tracking = Tracking::new(reference.clone(), info, GAIT_KP, GAIT_KP / 100.0).unwrap();
    tracking.pelvis_kp = GAIT_PELVIS_KP;
    tracking.pelvis_kd = GAIT_PELVIS_KP / 10.0;
    tracking.pelvis_axes = [0.0, 1.0, 0.0];
    tracking.balance = Some(Balance::new(&walker, &reference, [1.0, 0.1], [1.0, 0.5]).unwrap());
    let balanced = Balanced::new(&walker, tracking.clone(), 0.1).unwrap();
    let (q0, qd0) = cycle_start(&walker, &reference);
    let cycles = 4.0;
    let options = Options {
        q0: Some([q0, vec![0.0; Balanced::NX]].concat()),
        qd0: Some([qd0, vec![0.0; Balanced::NX]].concat()),
        output: Output::Every { dt: 0.005 },
        frames: true,
        ..Options::adaptive(cycles * 1.1, 1e-5)
    };
    let (tr, _) = mbs::simulate(
        mbs::WithEfforts::new(walker.clone(), balanced),
        Scheme::Radau5,
        options,
    )
    .unwrap();
    let weight = total_mass(&walker) * 9.80665;
    let c = CycleForces::of(&walker, &tracking, &tr, weight);
    let (right, left) = (c.figures(0), c.figures(1));
    // the pelvis' pitch and roll (ZYX angles a and c) over the last cycle
    let start = last_cycle_start(&tr, 1.1);
    let last: Vec<usize> = (0..tr.len()).filter(|s| tr.t[*s] >= start).collect();
    let range = |j: usize| {
        last.iter()
            .map(|s| tr.q(*s)[j])
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], v| {
                [lo.min(v), hi.max(v)]
            })
    };
    let (pitch, roll) = (range(3), range(5));
    println!(
        "balanced, pelvis free to pitch and roll, last of {cycles} cycles: right {right:.2?}, left {left:.2?}; \
         pitch {pitch:.3?}, roll {roll:.3?} rad; residual {:.1?} N·m",
        c.residual_axes
    );
    // the feet land faster than the held cycle's (the test above): the placement's offsets
    // still move when the heel touches
    println!(
        "landing velocities (fore–aft, vertical, lateral; m/s): {:.3?}",
        c.landing
    );
    for v in c.landing {
        let [x, y, z] = v.expect("each foot lands in the cycle");
        assert!(y < -0.3 && x < -0.2 && z.abs() > 0.3, "{v:?}");
    }
    for f in [right, left] {
        // a double hump, its first peak above the normal range
        assert!(double_hump(&f, [1.0, 1.8]), "{f:?}");
    }
    assert!((c.impulse_ratio - 1.0).abs() < 0.05, "{}", c.impulse_ratio);
    assert!(c.airborne < 0.01, "{}", c.airborne);
    // steady: the pelvis near its reference's pitch and roll
    assert!(pitch[0] > -0.1 && pitch[1] < 0.05, "{pitch:?}");
    assert!(roll[0] > -0.15 && roll[1] < 0.15, "{roll:?}");
    let axes = c.residual_axes;
    assert!(
        axes[0] == 0.0 && axes[2] == 0.0 && axes[1] > 0.0,
        "{axes:?}"
    );
    let peaks = format!("{} and {}", two(right.first_peak), two(left.first_peak));
    let sideways = c.landing.map(|v| format!("{:.2}", v.unwrap()[2].abs()));
    // a bound: the largest |angle| rounded up to hundredths
    let largest = |[lo, hi]: [f64; 2]| (100.0 * lo.abs().max(hi.abs())).ceil() / 100.0;
    quoted::says(
        "docs/human_gait.md",
        &[
            format!(
                "asserts the last of four cycles: first peaks {peaks}, troughs {} and {}, pitch and roll within {:.2} and {:.2} rad)",
                two(right.trough),
                two(left.trough),
                largest(pitch),
                largest(roll)
            ),
            format!(
                "against that walk's first peaks of {peaks} and heels landing at {} and {} m/s sideways",
                sideways[0], sideways[1]
            ),
            format!("({peaks} without the feedforward at 3·10⁴"),
        ],
    );
}

/// Mode 1 with the pelvis wholly free: the pressed cycle's residual torques reduced with the
/// feet's own contacts (`Tracking::reduced`), then one cycle run from the held run's state at
/// its second cycle with nothing holding the pelvis (`human_gait -- --pressure 30 --free 10
/// --reduce 6 --cycles 1`).
#[test]
fn with_its_residuals_reduced_the_cycle_walks_with_the_pelvis_free() {
    let model = gait_model();
    let info = model.info();
    let grounded = normal_cycle(&model, 1.1)
        .grounded(&model, &Grounding::default())
        .unwrap();
    let pressed = grounded
        .reference
        .grounded(
            &model,
            &Grounding {
                pressure: [30.0, 10.0],
                ..Default::default()
            },
        )
        .unwrap()
        .reference;
    let mut held = Tracking::new(pressed, info, GAIT_KP, GAIT_KP / 100.0).unwrap();
    held.pelvis_kp = GAIT_PELVIS_KP;
    held.pelvis_kd = GAIT_PELVIS_KP / 10.0;
    // what it lowers are the torques holding the pelvis about every axis
    let mut turn_only = held.clone();
    turn_only.pelvis_axes = [0.0, 1.0, 0.0];
    let e = turn_only
        .reduced(&model, &Reduction::default())
        .unwrap_err();
    assert!(e.contains("pelvis_axes"), "{e}");
    // no iteration: the held run on the cycle as given, and where it starts its second cycle
    let given = held
        .reduced(
            &model,
            &Reduction {
                iterations: 0,
                ..Default::default()
            },
        )
        .unwrap();
    let clock = std::time::Instant::now();
    let reduced = held
        .reduced(
            &model,
            &Reduction {
                iterations: 6,
                ..Default::default()
            },
        )
        .unwrap();
    println!(
        "reduced in {} iterations, {:.0} s: residual torques {:.1} → {:.1} N·m rms, angles corrected by up to {:.1}° \
         (per joint, rad: {:.3?})",
        reduced.iterations,
        clock.elapsed().as_secs_f64(),
        reduced.residual_rms[0],
        reduced.residual_rms[1],
        reduced.largest_change.to_degrees(),
        reduced.changes
    );
    assert_eq!(given.residual_rms[0], given.residual_rms[1]);
    assert_eq!(given.residual_rms[0], reduced.residual_rms[0]);
    assert!(
        reduced.residual_rms[1] < 0.1 * reduced.residual_rms[0],
        "{:?}",
        reduced.residual_rms
    );
    assert!(reduced.largest_change < 0.35, "{}", reduced.largest_change);
    let weight = total_mass(&model) * G;
    // one cycle with the pelvis free; the largest angle between the pelvis' orientation and
    // its reference's over it
    let free = |cycle: &Reduced| {
        let mut free = held.clone();
        free.reference = cycle.reference.clone();
        free.pelvis_kp = 0.0;
        free.pelvis_kd = 0.0;
        let (t0, q0, qd0) = cycle.start.clone();
        let options = Options {
            t0,
            q0: Some(q0),
            qd0: Some(qd0),
            output: Output::Every { dt: 0.005 },
            ..Options::adaptive(t0 + 1.1, 1e-5)
        };
        let tr = match mbs::simulate(
            mbs::WithEfforts::new(model.clone(), free.clone()),
            Scheme::Radau5,
            options,
        ) {
            Ok((tr, _)) => tr,
            Err(e) => *e.trajectory,
        };
        let tilt = cycle.reference.pelvis_departure(&model, &tr);
        (CycleForces::of(&model, &free, &tr, weight), tilt)
    };
    let (c, tilt) = free(&reduced);
    let (right, left) = (c.figures(0), c.figures(1));
    println!(
        "pelvis free, reduced: right {right:.2?}; left {left:.2?}; impulse ratio {:.4}, covered {:.2}, the pelvis \
         within {tilt:.3} rad of its reference",
        c.impulse_ratio, c.covered
    );
    assert!(c.covered > 0.999, "{}", c.covered);
    for g in [right, left] {
        assert!(double_hump(&g, [1.0, 1.3]), "{g:?}");
    }
    assert!((c.impulse_ratio - 1.0).abs() < 0.05, "{}", c.impulse_ratio);
    assert!(c.airborne < 0.01, "{}", c.airborne);
    assert!(tilt < 0.1, "{tilt}");
    // the corrections per joint (degrees) and the free cycle's figures, as the documents
    // write them
    let degrees = |joint: &str| {
        reduced
            .changes
            .iter()
            .find(|(name, _)| name.starts_with(joint))
            .unwrap_or_else(|| panic!("no {joint} in {:?}", reduced.changes))
            .1
            .to_degrees()
    };
    let others = ["knee", "ankle", "mtp"].map(degrees);
    let (least, most) = (
        others.iter().copied().fold(f64::INFINITY, f64::min),
        others.iter().copied().fold(0.0, f64::max),
    );
    // every joint but the hip's rotation and adduction
    let rest = reduced
        .changes
        .iter()
        .filter(|(name, _)| !name.starts_with("hip_rotation") && !name.starts_with("hip_adduction"))
        .map(|(_, c)| c.to_degrees())
        .fold(0.0, f64::max);
    let alike = |a: String, b: String| if a == b { a } else { format!("{a} and {b}") };
    let [from, to] = reduced.residual_rms;
    let free_cycle = (
        format!(
            "first peaks {} and {} body weights, troughs {}, second peaks {}, braking {} and {} then propulsion {}, a vertical impulse of {:.3} × weight × time, the pelvis within {tilt:.3} rad of its reference orientation over the cycle",
            two(right.first_peak),
            two(left.first_peak),
            alike(two(right.trough), two(left.trough)),
            alike(two(right.second_peak), two(left.second_peak)),
            two_signed(right.braking),
            two_signed(left.braking),
            alike(two_signed(right.propulsion), two_signed(left.propulsion)),
            c.impulse_ratio
        ),
        format!(
            "double humps of {}, {}, {} and {}, {}, {} body weights, braking then propulsion ({} and {}, {}), a vertical impulse of {:.3} × weight × time, the pelvis within {tilt:.3} rad of its reference orientation",
            two(right.first_peak),
            two(right.trough),
            two(right.second_peak),
            two(left.first_peak),
            two(left.trough),
            two(left.second_peak),
            two_signed(right.braking),
            two_signed(left.braking),
            alike(two_signed(right.propulsion), two_signed(left.propulsion)),
            c.impulse_ratio
        ),
        format!(
            "walks a normal cycle (humps {}, {}, {} body weights",
            two(right.first_peak),
            two(right.trough),
            two(right.second_peak)
        ),
    );
    // the cycle as given, free from the same instant of its own held run: out of the normal
    // ranges, the pelvis turned away from its reference
    let (c, tilt) = free(&given);
    let (right, left) = (c.figures(0), c.figures(1));
    println!(
        "pelvis free, as given: right {right:.2?}; left {left:.2?}; the pelvis within {tilt:.3} rad"
    );
    let normal = [right, left].iter().all(|g| double_hump(g, [1.0, 1.3]));
    assert!(!normal && tilt > 0.2, "{right:?} {left:?} {tilt}");
    // the right foot's trough falls to 0, as the documents say
    assert!(right.trough.unwrap() < 0.005, "{right:?}");
    quoted::says(
        "docs/human_gait.md",
        &[
            format!("six iterations take the residual torques from {from:.1} to {to:.1} N·m rms ("),
            format!(
                "mostly by turning the hips (rotation by up to {:.1}°, adduction {:.1}°; knee, ankle and toes {least:.1}–{most:.1}°, hip flexion {:.1}°, subtalar {:.1}°)",
                degrees("hip_rotation"),
                degrees("hip_adduction"),
                degrees("hip_flexion"),
                degrees("subtalar")
            ),
            free_cycle.0,
            format!(
                "from the same instant of the pressed cycle as it was, the left heel strikes at {} body weights, the right foot's trough falls to 0 and the pelvis turns {tilt:.2} rad away",
                two(left.first_peak)
            ),
            format!(
                "(up to 18.7°, and {:.1}° more to reduce its residuals)",
                reduced.largest_change.to_degrees()
            ),
        ],
    );
    quoted::says(
        "README.md",
        &[
            format!("iterations lower the residual torques from {from:.1} to {to:.1} N·m rms ("),
            format!(
                "the hips' rotation corrected by up to {:.1}°, their adduction {:.1}°, the other joints {rest:.1}° at most)",
                degrees("hip_rotation"),
                degrees("hip_adduction")
            ),
            free_cycle.1,
            format!(
                "from the same instant of the cycle as given, first peaks of {} and {}, a trough of 0, the pelvis {tilt:.2} rad off",
                two(right.first_peak),
                two(left.first_peak)
            ),
            format!("residual torques {from:.1} → {to:.1} N·m rms) the pelvis wholly free"),
            format!(
                "(up to 18.7° grounding it, {:.1}° more reducing its residuals)",
                reduced.largest_change.to_degrees()
            ),
        ],
    );
    quoted::says("docs/status.md", &[free_cycle.2]);
}

/// Mode 1 as the gait program runs it: the grounded normal cycle tracked, the pelvis held by
/// residual torques, two cycles; the last one's forces. Then the same on muscles, the
/// tracking as reserves.
#[test]
fn the_prescribed_cycle_gives_a_normal_double_hump_braking_then_propulsion_also_on_muscles() {
    let model = gait_model();
    let info = model.info();
    let period = 1.1;
    let fitted = normal_cycle(&model, period);
    let reference = fitted
        .grounded(&model, &Grounding::default())
        .unwrap()
        .reference;
    let (q0, qd0) = cycle_start(&model, &reference);
    let mut tracking = Tracking::new(reference, info, GAIT_KP, GAIT_KP / 100.0).unwrap();
    tracking.pelvis_kp = GAIT_PELVIS_KP;
    tracking.pelvis_kd = GAIT_PELVIS_KP / 10.0;
    let options = Options {
        q0: Some(q0),
        qd0: Some(qd0),
        output: Output::Every { dt: 0.005 },
        ..Options::adaptive(2.0 * period, 1e-5)
    };
    let (tr, stats) = mbs::simulate(
        mbs::WithEfforts::new(model.clone(), tracking.clone()),
        Scheme::Radau5,
        options.clone(),
    )
    .unwrap();
    let weight = total_mass(&model) * G;
    // the whole-body angular momentum over the cycle, normalised by mass, speed and height
    let (h, [_, speed, height]) = normalised_angular_momentum(&model, &tr, period).unwrap();
    println!("angular momentum / (M V H), V = {speed:.2} m/s, H = {height:.2} m: {h:?}");
    assert!((1.0..1.3).contains(&speed) && (0.85..1.0).contains(&height));
    assert!(
        h.iter()
            .all(|[lo, hi]| lo < hi && lo.abs() < 0.2 && hi.abs() < 0.2),
        "{h:?}"
    );
    let c = CycleForces::of(&model, &tracking, &tr, weight);
    let (right, left) = (c.figures(0), c.figures(1));
    println!(
        "{} steps; right {right:.2?}; left {left:.2?}; impulse ratio {:.4}, airborne {:.3}, residual rms {:.0} N·m \
         (about the fore–aft, vertical and lateral axes {:.0?})",
        stats.steps, c.impulse_ratio, c.airborne, c.residual_rms, c.residual_axes
    );
    let mass = total_mass(&model);
    let hump = |g: &FootFigures| {
        format!(
            "{} and {} body weights over a trough of {}",
            two(g.first_peak),
            two(g.second_peak),
            two(g.trough)
        )
    };
    assert_eq!(hump(&right), hump(&left), "the documents say each foot");
    assert_eq!(format!("{right:.2?}"), format!("{left:.2?}"));
    let [fore_aft, vertical, lateral] = h;
    quoted::says(
        "docs/human_gait.md",
        &[
            format!(
                "the second cycle gives each foot a double hump of {}, braking then propulsion (peaks {} and {}, means {} and {} body weights over the stance's halves), a vertical impulse of {:.3} × weight × time, always a foot on the ground, and residual torques of {:.2} N·m/kg rms ({:.2} peak): {:.0} N·m rms about the fore–aft axis, {:.0} about the vertical and {:.0} about the lateral.",
                hump(&right),
                two_signed(right.braking),
                two_signed(right.propulsion),
                two_signed(right.first_half),
                two_signed(right.second_half),
                c.impulse_ratio,
                c.residual_rms / mass,
                c.residual_peak / mass,
                c.residual_axes[0],
                c.residual_axes[1],
                c.residual_axes[2]
            ),
            format!(
                "walking speed and the centre of mass' height as Herr & Popovic (2008) do: {} about the lateral axis, {} fore–aft, {} vertical",
                span(lateral, 3),
                span(fore_aft, 3),
                span(vertical, 3)
            ),
        ],
    );
    quoted::says(
        "README.md",
        &[format!(
            "each foot shows the double hump, {}, braking then propulsion ({}, {}), a vertical impulse of {:.3} × weight × time, residual torques {:.2} N·m/kg rms",
            hump(&right),
            two_signed(right.braking),
            two_signed(right.propulsion),
            c.impulse_ratio,
            c.residual_rms / mass
        )],
    );
    quoted::says(
        "docs/status.md",
        &[format!(
            "residual torques {:.2} N·m/kg rms, because",
            c.residual_rms / mass
        )],
    );
    // the axes' parts make up the whole
    let parts = c.residual_axes.iter().map(|a| a * a).sum::<f64>().sqrt();
    assert!(
        (parts / c.residual_rms - 1.0).abs() < 1e-9,
        "{parts} {}",
        c.residual_rms
    );
    // each foot: the double hump in the normal ranges, braking then propulsion
    for g in [right, left] {
        assert!(double_hump(&g, [1.0, 1.3]), "{g:?}");
        assert!(within(g.first_half, -0.3, -0.02), "{g:?}");
        assert!(within(g.second_half, 0.02, 0.3), "{g:?}");
    }
    // the heels come down gently, hardly sliding fore–aft, as in the reference (whose
    // swinging foot still moves toward the midline at 0.12 m/s when it lands)
    println!(
        "landing velocities (fore–aft, vertical, lateral; m/s): {:.3?}",
        c.landing
    );
    let landing = c
        .landing
        .map(|v| v.unwrap().map(|x| format!("{:.2}", x.abs())));
    assert_eq!(
        landing[0], landing[1],
        "the documents say the heels land alike"
    );
    quoted::says(
        "docs/human_gait.md",
        &[format!(
            "asserts its landing: {} m/s down, {} fore–aft, {} sideways",
            landing[0][1], landing[0][0], landing[0][2]
        )],
    );
    for v in c.landing {
        let [x, y, z] = v.expect("each foot lands in the cycle");
        assert!(
            (-0.3..-0.05).contains(&y) && x.abs() < 0.1 && z.abs() < 0.2,
            "{v:?}"
        );
    }
    // residual torques below 2 N·m/kg rms
    assert!(
        c.residual_rms < 2.0 * total_mass(&model),
        "{}",
        c.residual_rms
    );
    // the vertical impulse is the weight's over the cycle, and a foot is always down
    assert!((c.impulse_ratio - 1.0).abs() < 0.05, "{}", c.impulse_ratio);
    assert!(c.airborne < 0.01, "{}", c.airborne);

    // a tracking thirty times softer (10³ N·m/rad) walks the same cycle with the same forces
    // when this run's joint torques are its feedforward; without them the legs lag the
    // reference and the forces leave the normal ranges
    let stiff = [right, left];
    let soft = |feedforward: Vec<Fourier>| {
        let mut t = tracking.clone();
        (t.kp, t.kd, t.toes_kp, t.toes_kd) = (
            GAIT_KP / 30.0,
            GAIT_KP / 3000.0,
            GAIT_KP / 30.0,
            GAIT_KP / 3000.0,
        );
        t.feedforward = feedforward;
        // the stiff run's start, outputs and tolerance
        let (run, st) = mbs::simulate(
            mbs::WithEfforts::new(model.clone(), t.clone()),
            Scheme::Radau5,
            options.clone(),
        )
        .unwrap();
        let c = CycleForces::of(&model, &t, &run, weight);
        ([c.figures(0), c.figures(1)], c.landing, st.steps)
    };
    let (fed, fed_landing, fed_steps) = soft(tracking.feedforward_of(&tr, 20).unwrap());
    let (unfed, unfed_landing, _) = soft(Vec::new());
    println!("softer tracking with feedforward: {fed:.2?}\n without: {unfed:.2?}");
    println!(
        "landing velocities with feedforward: {fed_landing:.3?}; without: {unfed_landing:.3?}; {fed_steps} steps with feedforward"
    );
    let pair = |f: fn(&FootFigures) -> Option<f64>, sign: bool| {
        let v = fed.map(|g| if sign { two_signed(f(&g)) } else { two(f(&g)) });
        format!("{} and {}", v[0], v[1])
    };
    let down = fed_landing.map(|v| format!("{:.2}", -v.unwrap()[1]));
    let lag = unfed_landing
        .iter()
        .map(|v| -v.unwrap()[1])
        .fold(0.0f64, f64::max);
    quoted::says(
        "docs/human_gait.md",
        &[
            format!(
                "thirty times softer, the tracking gives first peaks of {} body weights, troughs of {}, second peaks of {}, braking {}, propulsion {}, the heels landing at {} and {} m/s downward",
                pair(|g| g.first_peak, false),
                pair(|g| g.trough, false),
                pair(|g| g.second_peak, false),
                pair(|g| g.braking, true),
                pair(|g| g.propulsion, true),
                down[0],
                down[1]
            ),
            format!(
                "a heel lands at {lag:.2} m/s, and the forces leave the normal ranges (first peaks {} and {}, troughs {} and {}, propulsion {} under the right foot;",
                two(unfed[0].first_peak),
                two(unfed[1].first_peak),
                two(unfed[0].trough),
                two(unfed[1].trough),
                two_signed(unfed[0].propulsion)
            ),
            format!(
                "The two cycles take {} Radau5 steps where the stiff tracking takes {}.",
                thousands(fed_steps),
                thousands(stats.steps)
            ),
        ],
    );
    quoted::says(
        "README.md",
        &[
            format!(
                "gives the same double hump within 0.05 body weights ({}, troughs {}, braking {})",
                pair(|g| g.first_peak, false),
                pair(|g| g.trough, false),
                pair(|g| g.braking, true)
            ),
            format!(
                "a heel lands at {lag:.2} m/s (first peaks {} and {}, troughs {} and {};",
                two(unfed[0].first_peak),
                two(unfed[1].first_peak),
                two(unfed[0].trough),
                two(unfed[1].trough)
            ),
        ],
    );
    for (g, s) in fed.iter().zip(stiff) {
        let close =
            |a: Option<f64>, b: Option<f64>| a.zip(b).is_some_and(|(a, b)| (a - b).abs() < 0.1);
        assert!(
            close(g.first_peak, s.first_peak)
                && close(g.trough, s.trough)
                && close(g.second_peak, s.second_peak),
            "{g:?} {s:?}"
        );
        assert!(
            close(g.braking, s.braking) && close(g.propulsion, s.propulsion),
            "{g:?} {s:?}"
        );
    }
    assert!(
        unfed
            .iter()
            .any(|g| !within(g.first_peak, 1.0, 1.3) || !within(g.trough, 0.6, 0.9)),
        "{unfed:?}"
    );
    // fewer harmonics than samples are asked of a whole cycle
    assert!(tracking.feedforward_of(&tr, 120).is_err());

    // on muscles: excitations from this cycle's moments, the tracking as reserves; the
    // muscles' 36 states and the passive moments' 17 integrated with the body for two
    // cycles, which must end without a muscle leaving its fibre's range
    let cycle = muscle_cycle(&model, &tracking, &tr, &[0.0; NM], 8).unwrap();
    let (q0, qd0) = cycle.start(&model).unwrap();
    let options = Options {
        q0: Some(q0),
        qd0: Some(qd0),
        output: Output::Every { dt: 0.005 },
        ..Options::adaptive(2.0 * period, 1e-4)
    };
    let (tr_m, stats_m) = mbs::simulate(
        mbs::WithEfforts::new(model.clone(), cycle.driven.clone()),
        Scheme::Radau5,
        options,
    )
    .unwrap();
    let reserves = tracking
        .rms_over_last_cycle(info, &tr_m, &MUSCLE_JOINTS)
        .unwrap();
    let alone = tracking
        .rms_over_last_cycle(info, &tr, &MUSCLE_JOINTS)
        .unwrap();
    let share = cycle.share();
    let m = CycleForces::of(&model, &tracking, &tr_m, weight);
    let g = m.figures(0);
    println!(
        "on muscles: {} steps; reserves rms {reserves:.1} N·m against {alone:.1} N·m tracked alone; \
         muscles at rest supply {:.0} % of the moments (rms over the cycle); right {g:.2?}",
        stats_m.steps,
        100.0 * share
    );
    // the muscles take over more than 60 % of the moments (rms: 18.5 of 50.3 N·m left to
    // the reserves; 22.0 when the excitations were the activations, their lag ignored), and
    // the walk stays normal
    assert!(reserves < 0.4 * alone, "{reserves} {alone}");
    let forces = format!(
        "({}, {}, {})",
        two(g.first_peak),
        two(g.trough),
        two(g.second_peak)
    );
    quoted::says(
        "docs/human_gait.md",
        &[
            format!(
                "the reserves' torques at hip, knee and ankle fall from {alone:.1} to {reserves:.1} N·m rms with the forces unchanged {forces}"
            ),
            format!("walk alone (the reserves carry {reserves:.1} N·m rms"),
        ],
    );
    quoted::says(
        "README.md",
        &[format!(
            "nearly the same forces {forces}, the reserves falling from {alone:.1} to {reserves:.1} N·m rms"
        )],
    );
    assert!(
        within(g.first_peak, 1.0, 1.3) && within(g.second_peak, 1.0, 1.3),
        "{g:?}"
    );
    assert!(within(g.trough, 0.6, 0.9), "{g:?}");
}

#[test]
fn residual_torques_hold_the_pelvis_on_its_reference_orientation() {
    let model = Human::default();
    let info = model.info();
    let reference = GaitReference::still(info, 0.1).unwrap();
    let (mut q0, qd0) = cycle_start(&model, &reference);
    // in the air (no contact), tilted by 0.05 rad from the reference
    q0[1] += 1.0;
    q0[3] += 0.05;
    let mut tracking = Tracking::new(reference.clone(), info, 3000.0, 30.0).unwrap();
    let run = |tracking: Tracking| {
        let options = Options {
            q0: Some(q0.clone()),
            qd0: Some(qd0.clone()),
            output: Output::Every { dt: 0.01 },
            ..Options::adaptive(0.4, 1e-6)
        };
        let (tr, _) = mbs::simulate(
            mbs::WithEfforts::new(Human::default(), tracking),
            Scheme::Radau5,
            options,
        )
        .unwrap();
        let last = tr.len() - 1;
        tr.q(last)[3] - reference.pelvis[0].eval(0.4)[0]
    };
    let free = run(tracking.clone());
    tracking.pelvis_kp = 3000.0;
    tracking.pelvis_kd = 300.0;
    let held = run(tracking.clone());
    // held about the fore–aft and vertical axes only, the pitch (about the lateral axis) is
    // left free
    tracking.pelvis_axes = [1.0, 1.0, 0.0];
    let unpitched = run(tracking);
    println!(
        "pelvis pitch error after 0.4 s in the air: free {free:+.4} rad, held {held:+.2e} rad, \
         held about the other axes {unpitched:+.4} rad"
    );
    // free, the tilt stays (no torque acts on the whole body in the air); held, it decays
    assert!((free - 0.05).abs() < 0.01, "{free}");
    assert!(held.abs() < 0.1 * 0.05, "{held}");
    assert!((unpitched - 0.05).abs() < 0.01, "{unpitched}");
}

/// In flight the ground pushes nowhere: under gravity and the tracking's internal torques
/// the angular momentum about the centre of mass ([`Centroid`]) stays what it was while the
/// legs swing through half a cycle, and the momentum changes by the weight's impulse.
#[test]
fn in_flight_the_angular_momentum_about_the_centre_of_mass_is_conserved() {
    let model = Human::default();
    let info = model.info();
    let n = Human::NQ;
    let reference = normal_cycle(&model, 1.1);
    let (mut q0, mut qd0) = reference_state(&model, &reference, 0.0);
    q0[1] = 10.0;
    qd0[0] = 1.2;
    qd0[3] = 0.3;
    qd0[5] = -0.2;
    let tracking = Tracking::new(reference, info, 3000.0, 30.0).unwrap();
    let t_end = 0.55;
    let options = Options {
        q0: Some(q0),
        qd0: Some(qd0),
        output: Output::Every { dt: 0.05 },
        ..Options::adaptive(t_end, 1e-9)
    };
    let (tr, _) = mbs::simulate(
        mbs::WithEfforts::new(model.clone(), tracking),
        Scheme::Radau5,
        options,
    )
    .unwrap();
    let mass = total_mass(&model);
    let at = |s: usize| {
        let (q, qd) = (&tr.q(s)[..n], &tr.qd(s)[..n]);
        Centroid::of(&model, tr.t[s], q, qd).expect("the pelvis away from its angles' singularity")
    };
    let first = at(0);
    let scale = first
        .angular_momentum
        .iter()
        .map(|h| h.abs())
        .fold(1.0, f64::max);
    let mut worst = 0.0f64;
    let mut swing = 0.0f64;
    for s in 1..tr.len() {
        let c = at(s);
        for k in 0..3 {
            worst = worst.max((c.angular_momentum[k] - first.angular_momentum[k]).abs() / scale);
        }
        let dt = tr.t[s] - tr.t[0];
        let expected = [
            first.momentum[0],
            first.momentum[1] - mass * G * dt,
            first.momentum[2],
        ];
        for (k, (got, want)) in c.momentum.iter().zip(expected).enumerate() {
            assert!(
                (got - want).abs() < 1e-6 * mass,
                "momentum {k} at t = {}: {got} against {want}",
                tr.t[s],
            );
        }
        let (q, q0) = (&tr.q(s)[..n], &tr.q(0)[..n]);
        swing = swing.max((6..n).map(|j| (q[j] - q0[j]).abs()).fold(0.0, f64::max));
    }
    println!(
        "in flight {t_end} s: angular momentum about the centre of mass {:?} kg·m²/s, its largest change {worst:.2e} of the largest component; joints swung up to {swing:.2} rad",
        first.angular_momentum
    );
    assert!(swing > 0.3, "the legs hardly moved: {swing}");
    quoted::says(
        "docs/human_gait.md",
        &[format!(
            "conserved in flight to {worst:.1e} of itself while the legs swing"
        )],
    );
    assert!(
        worst < 1e-6,
        "angular momentum changed by {worst:.2e} of it"
    );
}

/// A body turned 69° about the vertical is read in a re-centred chart (the pelvis' ZYX
/// angles lock at 90° of yaw, and the run moves the chart where |cos b| < 0.5): the forces and
/// the centroid computed from its trajectory are those of the same stance unturned, and the
/// centroid does not depend on the chart a state is read in.
#[test]
fn a_run_read_in_a_re_centred_chart_is_post_processed_in_it() {
    let model = Human::default();
    let n = Human::NQ;
    let reference = GaitReference::still(model.info(), 0.1).unwrap();
    let (q0, qd0) = cycle_start(&model, &reference);
    let tracking = held(reference);
    // the pelvis' rotation Rz(a) Ry(b) Rx(c) turned by `yaw` about the world's vertical (y)
    let pelvis = model.info().rotation_joints[0];
    let turn = |q: &mut [f64], yaw: f64| {
        use mbs::charts::{array, joint_rotation, quaternion_near, zyx, zyx_angles_of};
        let r = joint_rotation(&array(&zyx([0.0, yaw, 0.0])), &pelvis, q);
        for (k, a) in zyx_angles_of(quaternion_near(&r, None))
            .into_iter()
            .enumerate()
        {
            q[pelvis.angles[k]] = a;
        }
    };
    let run = |yaw: f64| {
        let mut q = q0.clone();
        turn(&mut q, yaw);
        let options = Options {
            q0: Some(q),
            qd0: Some(qd0.clone()),
            output: Output::Every { dt: 0.01 },
            ..Options::adaptive(0.2, 1e-8)
        };
        mbs::simulate(
            mbs::WithEfforts::new(model.clone(), tracking.clone()),
            Scheme::Radau5,
            options,
        )
        .unwrap()
        .0
    };
    let (straight, turned) = (run(0.0), run(1.2));
    // the turned run is read in a chart turned with it (re-centred from the start on), the
    // straight one in the model's own
    let identity = |tr: &mbs::Trajectory| {
        let c = tr.chart(tr.len() - 1, 0);
        (0..3).all(|i| (0..3).all(|j| (c[i][j] - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12))
    };
    assert!(identity(&straight));
    assert!(!identity(&turned), "the turned run kept the model's chart");
    let weight = total_mass(&model) * G;
    let (a, b) = (
        CycleForces::of(&model, &tracking, &straight, weight),
        CycleForces::of(&model, &tracking, &turned, weight),
    );
    let mut worst = 0.0f64;
    for ((_, r0, l0), (_, r1, l1)) in a.grf.iter().zip(&b.grf) {
        worst = worst.max((r0[1] - r1[1]).abs()).max((l0[1] - l1[1]).abs());
    }
    println!(
        "standing turned by 1.2 rad (its pelvis' angles at the end {:+.3} {:+.3} {:+.3} in a re-centred chart): vertical forces within {worst:.1e} body weights of the unturned stance's (impulse {:.4} and {:.4} of weight × time)",
        turned.q(turned.len() - 1)[3],
        turned.q(turned.len() - 1)[4],
        turned.q(turned.len() - 1)[5],
        a.impulse_ratio,
        b.impulse_ratio
    );
    assert!(worst < 1e-4, "{worst}");
    assert!((a.impulse_ratio - b.impulse_ratio).abs() < 1e-4);
    // the centroid: the same height and spin in both runs; and one state read in two charts
    let mut read = model.clone();
    let last = turned.len() - 1;
    mbs::charts::use_charts_of(&mut read, &turned, last);
    let (q, qd) = (&turned.q(last)[..n], &turned.qd(last)[..n]);
    let c = Centroid::of(&read, turned.t[last], q, qd).unwrap();
    let s = Centroid::of(&model, 0.2, &straight.q(last)[..n], &straight.qd(last)[..n]).unwrap();
    assert!((c.position[1] - s.position[1]).abs() < 1e-6, "{c:?} {s:?}");
    assert!((c.angular_momentum[1] - s.angular_momentum[1]).abs() < 1e-6);
    let (mut q2, mut qd2) = (q.to_vec(), qd.to_vec());
    let mut other = read.clone();
    mbs::charts::recentre(&mut other, &mut q2, &mut qd2, &[]);
    let d = Centroid::of(&other, turned.t[last], &q2, &qd2).unwrap();
    for k in 0..3 {
        assert!((c.position[k] - d.position[k]).abs() < 1e-12);
        assert!((c.momentum[k] - d.momentum[k]).abs() < 1e-12);
        assert!((c.angular_momentum[k] - d.angular_momentum[k]).abs() < 1e-12);
    }
}

/// What `GaitReference::grounded` asks of the ground, checked against the model's inverse
/// dynamics: along the fitted cycle (the body lifted clear of the ground, the pelvis' translation
/// still), the external force and moment about the pelvis' origin that produce the motion
/// (τ = M q̈ − h on the pelvis' coordinates, q̈ by differences of the reference's rates) are
/// those of the momentum, m (a_G + g ŷ) and Ḣ_G + (G − O) × F (`Centroid` differenced); and
/// the centre of pressure `pressure_point` places has no horizontal moment about it.
#[test]
fn the_ground_wrench_a_cycle_needs_is_its_inverse_dynamics() {
    let model = Human::default();
    let reference = normal_cycle(&model, 1.1);
    let n = Human::NQ;
    let mass = total_mass(&model);
    let weight = mass * G;
    let state = |t: f64| {
        let (mut q, qd) = reference_state(&model, &reference, t);
        q[1] += 2.0;
        (q, qd)
    };
    let cross = |u: [f64; 3], v: [f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let dt = 1e-4;
    let (mut worst_force, mut worst_moment, mut worst_point) = (0.0f64, 0.0f64, 0.0f64);
    for s in 0..20 {
        let t = s as f64 * 1.1 / 20.0;
        let (q, qd) = state(t);
        let ((_, qd_m), (_, qd_p)) = (state(t - dt), state(t + dt));
        let qdd: Vec<f64> = (0..n).map(|i| (qd_p[i] - qd_m[i]) / (2.0 * dt)).collect();
        let mut tau = vec![0.0; n];
        model.inverse_dynamics(t, &q, &qd, &qdd, &[], &mut tau);
        // the pelvis' angles turn about a₁ = z, a₂ = Rz(a) y, a₃ = Rz(a) Ry(b) x
        let (sa, ca) = q[3].sin_cos();
        let (sb, cb) = q[4].sin_cos();
        let axes = [[0.0, 0.0, 1.0], [-sa, ca, 0.0], [ca * cb, sa * cb, -sb]];
        let a = mbs::DMatrix::from_fn(3, 3, |i, j| axes[i][j]);
        let m_o = a
            .lu()
            .solve(&mbs::DMatrix::from_column_slice(3, 1, &tau[3..6]))
            .unwrap();
        let force = [tau[0], tau[1], tau[2]];
        // the momentum's side
        let centroid = |t: f64| {
            let (q, qd) = state(t);
            Centroid::of(&model, t, &q, &qd).unwrap()
        };
        let (cm, c0, cp) = (centroid(t - dt), centroid(t), centroid(t + dt));
        let a_g: [f64; 3] = std::array::from_fn(|k| {
            (cp.position[k] - 2.0 * c0.position[k] + cm.position[k]) / (dt * dt)
        });
        let hd: [f64; 3] =
            std::array::from_fn(|k| (cp.angular_momentum[k] - cm.angular_momentum[k]) / (2.0 * dt));
        let f_c: [f64; 3] = std::array::from_fn(|k| mass * (a_g[k] + if k == 1 { G } else { 0.0 }));
        let arm: [f64; 3] = std::array::from_fn(|k| c0.position[k] - q[k]);
        let moment = cross(arm, f_c);
        for k in 0..3 {
            worst_force = worst_force.max((force[k] - f_c[k]).abs() / weight);
            worst_moment = worst_moment.max((m_o[k] - hd[k] - moment[k]).abs() / weight);
        }
        // the centre of pressure on a plane 0.9 m below the centre of mass, from the
        // dynamics' force and moment about the centre of mass
        let m_g: [f64; 3] = {
            let back = cross(arm, force);
            std::array::from_fn(|k| m_o[k] - back[k])
        };
        let ground = c0.position[1] - 0.9;
        let (c, free) = pressure_point(force, m_g, c0.position, ground);
        let about = cross(
            [
                c0.position[0] - c[0],
                c0.position[1] - ground,
                c0.position[2] - c[1],
            ],
            force,
        );
        let at_c: [f64; 3] = std::array::from_fn(|k| m_g[k] + about[k]);
        worst_point = worst_point
            .max(at_c[0].abs() / weight)
            .max(at_c[2].abs() / weight)
            .max((at_c[1] - free).abs() / weight);
    }
    println!(
        "over the cycle, per body weight: force {worst_force:.1e}, moment about the pelvis {worst_moment:.1e} m, \
         the centre of pressure's moment {worst_point:.1e} m"
    );
    assert!(
        worst_force < 1e-5 && worst_moment < 1e-5,
        "{worst_force} {worst_moment}"
    );
    assert!(worst_point < 1e-12, "{worst_point}");
    quoted::says(
        "docs/human_gait.md",
        &[format!(
            "checks that force and moment against the model's inverse dynamics along the cycle, to {worst_force:.1e} of the body's weight, asserted 1e-5"
        )],
    );
}
