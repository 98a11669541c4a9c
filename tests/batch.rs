//! Four states at once (`option batch;`): `dynamics_x4` and `forward_dynamics_x4` agree with
//! the one-state functions lane by lane, to 1e-12 relative, on a model that uses every kind of
//! function the generated code may call (a free base with its chart, contacts with `pos`,
//! `step` and friction, a Rust function, an input, time) and on a 24-joint arm whose functions
//! are split into chunks; `dynamics_lanes` and `forward_dynamics_lanes` give each lane the
//! parameters and charts of its own model; a model without the option answers through the
//! trait's lane-by-lane default. The one-state chunks of that arm declared in a function's body compute what those
//! of the arm declared in a module compute.

#![allow(unused_macros)]

use mbs::{F64x4, Kinematics, LANES, Model};

include!("../benches/scaling/shapes.rs");

arm!(Arm24, 24, 11, 23, 22, batch);

#[path = "common/free_box.rs"]
mod free_box;
use free_box::Mixed;

/// Four states about the model's start (deterministic), as lanes and one slice per state.
fn states<M: Model>(model: &M, spread: f64) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let n = M::NQ;
    let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q0, &mut qd0);
    let mut qs = Vec::new();
    let mut qds = Vec::new();
    for k in 0..LANES {
        let s = |i: usize, j: usize| (((i * 7 + k * 13 + j) % 11) as f64 / 5.0 - 1.0) * spread;
        qs.push(q0.iter().enumerate().map(|(i, v)| v + s(i, 0)).collect());
        qds.push(
            qd0.iter()
                .enumerate()
                .map(|(i, v)| v + 3.0 * s(i, 5))
                .collect(),
        );
    }
    (qs, qds)
}

fn pack(states: &[Vec<f64>]) -> Vec<F64x4> {
    let mut out = vec![F64x4::ZERO; states[0].len()];
    mbs::lanes::pack([&states[0], &states[1], &states[2], &states[3]], &mut out);
    out
}

fn close(lane: f64, one: f64, scale: f64, what: &str) {
    assert!(
        (lane - one).abs() <= 1e-12 * scale,
        "{what}: batch {lane} vs one state {one} (scale {scale})"
    );
}

/// Both batch functions against the one-state functions at four states; returns the worst
/// relative difference.
fn compare<M: Model>(model: &M, spread: f64) -> f64 {
    compare_lanes([model; LANES], spread, false)
}

/// Both batch functions of four models, each lane's the one-state functions of its model
/// (`_lanes`, or `_x4` of the first when not `each`); returns the worst relative difference.
fn compare_lanes<M: Model>(models: [&M; LANES], spread: f64, each: bool) -> f64 {
    let n = M::NQ;
    let model = models[0];
    let (qs, qds) = states(model, spread);
    let us: Vec<Vec<f64>> = (0..LANES)
        .map(|k| vec![0.3 * k as f64 - 0.4; M::NU])
        .collect();
    let ts = [0.0, 0.1, 0.25, 1.3];
    let (q, qd) = (pack(&qs), pack(&qds));
    let u = if M::NU > 0 { pack(&us) } else { Vec::new() };
    let t = F64x4::from(ts);
    let (mut m4, mut h4) = (vec![F64x4::ZERO; n * n], vec![F64x4::ZERO; n]);
    let (mut a4, mut p4) = (vec![F64x4::ZERO; n], vec![F64x4::ZERO; n]);
    if each {
        M::dynamics_lanes(models, t, &q, &qd, &u, &mut m4, &mut h4);
        M::forward_dynamics_lanes(models, t, &q, &qd, &u, &mut a4, &mut p4);
    } else {
        model.dynamics_x4(t, &q, &qd, &u, &mut m4, &mut h4);
        model.forward_dynamics_x4(t, &q, &qd, &u, &mut a4, &mut p4);
    }
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    let (mut a, mut p) = (vec![0.0; n], vec![0.0; n]);
    let mut worst = 0.0f64;
    for k in 0..LANES {
        let model = models[k];
        model.dynamics(ts[k], &qs[k], &qds[k], &us[k], &mut m, &mut h);
        model.forward_dynamics(ts[k], &qs[k], &qds[k], &us[k], &mut a, &mut p);
        let max = |v: &[f64]| v.iter().fold(f64::MIN_POSITIVE, |s, x| s.max(x.abs()));
        for (what, lanes, one) in [
            ("M", &m4, &m),
            ("h", &h4, &h),
            ("qdd", &a4, &a),
            ("pivots", &p4, &p),
        ] {
            let scale = max(one);
            for (i, (l, o)) in lanes.iter().zip(one.iter()).enumerate() {
                close(l.lane(k), *o, scale, &format!("{what}[{i}] of lane {k}"));
                worst = worst.max((l.lane(k) - o).abs() / scale);
            }
        }
    }
    worst
}

#[test]
fn every_function_of_the_language_on_lanes() {
    const { assert!(Mixed::BATCH_GENERATED) };
    let model = Mixed::default();
    // the corners are in contact in some lanes and not in others
    let (qs, qds) = states(&model, 0.05);
    let mut kin = Kinematics::new::<Mixed>();
    let mut heights = Vec::new();
    for (q, qd) in qs.iter().zip(&qds) {
        model.kinematics(0.0, q, qd, &mut kin);
        heights.extend(kin.points.iter().map(|p| p.position[2]));
    }
    assert!(
        heights.iter().any(|z| *z < 0.0) && heights.iter().any(|z| *z > 0.0),
        "{heights:?}"
    );
    let worst = compare(&model, 0.05);
    println!("Mixed: worst relative difference {worst:.1e}");
}

#[test]
fn chunked_functions_on_lanes() {
    let model = Arm24::default();
    const { assert!(Arm24::BATCH_GENERATED) };
    // more temporaries than one function holds (1,500): the code is split into chunks that
    // pass values through a workspace of lanes
    assert!(dynamics_lets(&model) > 1500);
    let worst = compare(&model, 0.3);
    println!("Arm24: worst relative difference {worst:.1e}");
}

/// Four models of one type in the four lanes (`dynamics_lanes`, `forward_dynamics_lanes`),
/// each with its parameters and its chart, as the members of an ensemble: each lane is its
/// model's; the model that differs from the others in one lane changes that lane alone.
#[test]
fn four_models_in_the_four_lanes() {
    let mixed: Vec<Mixed> = (0..LANES)
        .map(|k| {
            let mut m = Mixed::default();
            let mut p = m.params().clone();
            p.k *= 1.0 + 0.5 * k as f64;
            p.c *= 1.0 - 0.2 * k as f64;
            p.mu += 0.1 * k as f64;
            p.g -= 0.7 * k as f64;
            m.set_params(p).unwrap();
            // a chart turned about z by k·0.4 rad
            let (s, c) = (0.4 * k as f64).sin_cos();
            m.set_chart(0, [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]);
            m
        })
        .collect();
    let each: [&Mixed; LANES] = std::array::from_fn(|k| &mixed[k]);
    let worst = compare_lanes(each, 0.05, true);
    println!("Mixed, four models: worst relative difference {worst:.1e}");
    // a lane's model is its own: the first lane's results differ from the model's own x4's
    let (qs, qds) = states(&mixed[0], 0.05);
    let (q, qd) = (pack(&qs), pack(&qds));
    let u = pack(&vec![vec![0.1]; LANES]);
    let t = F64x4::from(0.2);
    let n = Mixed::NQ;
    let (mut a_each, mut p) = (vec![F64x4::ZERO; n], vec![F64x4::ZERO; n]);
    let mut a_first = a_each.clone();
    Mixed::forward_dynamics_lanes(each, t, &q, &qd, &u, &mut a_each, &mut p);
    mixed[0].forward_dynamics_x4(t, &q, &qd, &u, &mut a_first, &mut p);
    let lane = |a: &[F64x4], k: usize| a.iter().map(|v| v.lane(k)).collect::<Vec<_>>();
    assert_eq!(lane(&a_each, 0), lane(&a_first, 0));
    for k in 1..LANES {
        assert_ne!(lane(&a_each, k), lane(&a_first, k), "lane {k}");
    }

    let arms: Vec<Arm24> = (0..LANES)
        .map(|k| {
            let mut m = Arm24::default();
            let mut p = m.params().clone();
            p.len *= 1.0 + 0.1 * k as f64;
            p.m *= 1.0 + 0.3 * k as f64;
            m.set_params(p).unwrap();
            m
        })
        .collect();
    let worst = compare_lanes(std::array::from_fn(|k| &arms[k]), 0.3, true);
    println!("Arm24, four models: worst relative difference {worst:.1e}");
    // and the trait's default, lane by lane, for a model without the option
    let pendulums: Vec<mbs_models::dpend::DoublePendulum> = (0..LANES)
        .map(|k| {
            let mut m = mbs_models::dpend::DoublePendulum::default();
            let mut p = m.params().clone();
            p.g += k as f64;
            m.set_params(p).unwrap();
            m
        })
        .collect();
    let each = std::array::from_fn(|k| &pendulums[k]);
    assert_eq!(compare_lanes(each, 0.3, true), 0.0);
}

#[test]
fn models_without_the_option_answer_lane_by_lane() {
    let model = mbs_models::dpend::DoublePendulum::default();
    const { assert!(!mbs_models::dpend::DoublePendulum::BATCH_GENERATED) };
    assert_eq!(compare(&model, 0.3), 0.0);
}

/// One-state chunks are methods of types declared in modules of their own (the compiler puts
/// each module's code in a code-generation unit of its own), given their methods where the
/// model is: a model declared in a function's body, whose types no module can name, compiles
/// too, and its chunks compute what the same model's compute in a module.
#[test]
fn a_chunked_model_declared_in_a_function_body() {
    arm!(Arm24Here, 24, 11, 23, 22);
    let (here, there) = (Arm24Here::default(), Arm24::default());
    assert!(dynamics_lets(&here) > 1500);
    let (qs, qds) = states(&here, 0.3);
    for (q, qd) in qs.iter().zip(&qds) {
        let a = one_state(&here, q, qd);
        assert_eq!(a, one_state(&there, q, qd));
        assert!(a.2.iter().all(|v| v.is_finite()) && a.2.iter().any(|&v| v != 0.0));
    }
}

/// M, h and qdd at one state.
fn one_state<M: Model>(model: &M, q: &[f64], qd: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = M::NQ;
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    let (mut qdd, mut pivots) = (vec![0.0; n], vec![0.0; n]);
    model.dynamics(0.0, q, qd, &[], &mut m, &mut h);
    model.forward_dynamics(0.0, q, qd, &[], &mut qdd, &mut pivots);
    (m, h, qdd)
}

/// The `let`s of a model's generated `dynamics`.
fn dynamics_lets<M: Model>(model: &M) -> usize {
    let (_, dynamics) = model
        .info()
        .ops
        .iter()
        .find(|(label, _)| label.starts_with("dynamics"))
        .unwrap();
    dynamics.lets
}
