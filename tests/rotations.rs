//! Rotation joints (`Tball`, `Tfree`) run through every orientation: the runtime re-centres
//! their charts before gimbal lock, and conserved quantities, computed without charts (the
//! joint's quaternion and its angular velocity in its own axes), stay conserved.
//!
//! - the intermediate-axis tumble (`TumbleBall`), 20 s at rtol 1e-10: energy and angular
//!   momentum drift ≤ 1e-8 with DOPRI5 and Radau5, ≤ 1e-5 with generalized-α;
//! - every scheme, fixed and adaptive, runs the tumble through its flips;
//! - a fast top whose axis passes through the vertical (`Top`), where its Euler-angle twin
//!   stops: energy and vertical angular momentum drift ≤ 1e-8 over 2 s at rtol 1e-10;
//! - a spherical pendulum swinging through the bottom (`SphericalPendulum`), likewise.

use mbs::{Failure, Model, Options, Output, Scheme, StepControl, simulate};
use mbs_models::conserved::{drifts, energy_drift, from_vertical, rotation};
use mbs_models::spherical_pendulum::{SphericalPendulum, SphericalPendulumZyx};
use mbs_models::top::{Top, TopZyx};
use mbs_models::tumble::{INERTIA, PHI0, TumbleBall, turned_start};

#[path = "common/quoted.rs"]
mod quoted;
use quoted::thousands;

/// Adaptive steps at `rtol` (atol = rtol/100), an output at every step.
fn adaptive(t_end: f64, rtol: f64) -> Options {
    Options {
        output: Output::Steps,
        ..Options::adaptive(t_end, rtol)
    }
}

#[test]
fn tumble_on_a_ball_joint_keeps_energy_and_momentum_through_its_flips() {
    // (re-centrings, energy drift, momentum drift, steps) per scheme, as docs/rotations.md
    // quotes them
    let mut rows = Vec::new();
    for (scheme, bound) in [
        (Scheme::Dopri5, 1e-8),
        (Scheme::Radau5, 1e-8),
        (Scheme::GenAlpha(mbs::GenAlphaParams::default()), 1e-5),
    ] {
        let (tr, st) = simulate(TumbleBall::default(), scheme, adaptive(20.0, 1e-10))
            .unwrap_or_else(|e| panic!("{}: {e}", scheme.name()));
        let (de, dl) = drifts(&tr, INERTIA, None);
        println!(
            "tumble, {}: {} re-centrings, energy drift {de:.2e}, momentum drift {dl:.2e}; {} steps",
            scheme.name(),
            st.chart_switches,
            st.steps
        );
        assert!(st.chart_switches >= 2, "{}", st.chart_switches);
        assert!(
            de <= bound && dl <= bound,
            "{}: {de:e} {dl:e}",
            scheme.name()
        );
        rows.push((st.chart_switches, de, dl, thousands(st.steps)));
    }
    let [(s0, e0, l0, n0), (s1, e1, l1, n1), (s2, e2, l2, n2)] = &rows[..] else {
        unreachable!()
    };
    quoted::says(
        "docs/rotations.md",
        &[
            format!(
                "| tumble, MODELS.md's start, DOPRI5 | {s0} re-centrings, E {e0:.1e}, L {l0:.1e}, {n0} steps |"
            ),
            format!("| same, Radau5 | {s1}, {e1:.1e}, {l1:.1e}, {n1} steps |"),
            format!(
                "| same, generalized-α adaptive (ρ∞ 0.8) | {s2}, {e2:.1e}, {l2:.1e}, {n2} steps |"
            ),
            format!(
                "adaptive steps at rtol 1e-10: {e2:.1e} (energy) and {l2:.1e} (momentum), {n2} steps"
            ),
        ],
    );
}

#[test]
fn top_runs_through_the_vertical_where_its_euler_angles_stop() {
    let (m, l, i1, i3) = (0.1, 0.04, 2e-5, 4e-5);
    let inertia = [i3, i1 + m * l * l, i1 + m * l * l];
    // (passages, closest, re-centrings, energy drift, L_z drift) with DOPRI5 and Radau5
    let mut rows = Vec::new();
    for scheme in [Scheme::Dopri5, Scheme::Radau5] {
        let (tr, st) = simulate(Top::default(), scheme, adaptive(2.0, 1e-10))
            .unwrap_or_else(|e| panic!("{}: {e}", scheme.name()));
        let (de, dlz) = drifts(&tr, inertia, Some(2));
        // the angle of the axis (body x) to the vertical, its passages within 0.05 rad of it
        // (local minima) and the closest one
        let theta = from_vertical(&tr, false);
        let passages = (1..theta.len() - 1)
            .filter(|&i| theta[i] < 0.05 && theta[i] <= theta[i - 1] && theta[i] < theta[i + 1])
            .count();
        let closest = theta.iter().copied().fold(f64::INFINITY, f64::min);
        println!(
            "top, {}: {passages} passages through the vertical (closest {closest:.2e} rad), {} re-centrings, energy drift {de:.2e}, L_z drift {dlz:.2e}; {} steps",
            scheme.name(),
            st.chart_switches,
            st.steps
        );
        assert!(closest < 1e-3 && passages >= 10, "{closest} {passages}");
        // a chart re-centred near the vertical has it at its centre
        assert!(st.chart_switches >= 1);
        assert!(de <= 1e-8 && dlz <= 1e-8, "{de:e} {dlz:e}");
        rows.push((passages, closest, st.chart_switches, de, dlz));
    }
    let Err(e) = simulate(TopZyx::default(), Scheme::Dopri5, adaptive(2.0, 1e-10)) else {
        panic!("the Euler angles stop at the vertical")
    };
    println!("top on Euler angles: {e}");
    assert!(
        matches!(e.kind, Failure::SingularConfiguration { .. }),
        "{e}"
    );
    let [(p0, c0, s0, e0, l0), (p1, c1, s1, e1, l1)] = rows[..] else {
        unreachable!()
    };
    let passages = if p0 == p1 {
        p0.to_string()
    } else {
        format!("{p0} / {p1}")
    };
    let stop = e.t;
    quoted::says(
        "docs/rotations.md",
        &[format!(
            "| fast top through the vertical, 2 s, DOPRI5 / Radau5 | {passages} passages within {c0:.1e} / {c1:.1e} rad of the vertical, {s0} / {s1} re-centrings, E {e0:.1e} / {e1:.1e}, L_z {l0:.1e} / {l1:.1e} | — | stops at t = {stop:.3} s |"
        )],
    );
    quoted::says(
        "README.md",
        &[format!(
            "| {passages} passages; DOPRI5 {s0} re-centrings, energy {e0:.1e}, vertical momentum {l0:.1e}; Radau5 {s1} re-centrings, {e1:.1e}, {l1:.1e}; on ZYX angles it stops at t = {stop:.3} s |"
        )],
    );
}

#[test]
fn spherical_pendulum_swings_through_the_bottom() {
    let (m, l, r) = (1.0, 1.0, 0.05);
    let ig = 0.4 * m * r * r;
    let inertia = [ig, ig + m * l * l, ig + m * l * l];
    // (energy drift, L_z drift) with DOPRI5 and Radau5
    let mut rows = Vec::new();
    for scheme in [Scheme::Dopri5, Scheme::Radau5] {
        let (tr, st) = simulate(SphericalPendulum::default(), scheme, adaptive(3.0, 1e-10))
            .unwrap_or_else(|e| panic!("{}: {e}", scheme.name()));
        let (de, dlz) = drifts(&tr, inertia, Some(2));
        let closest = from_vertical(&tr, true)
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        println!(
            "spherical pendulum, {}: {} re-centrings, closest to the bottom {closest:.2e} rad, energy drift {de:.2e}, L_z drift {dlz:.2e}; {} steps",
            scheme.name(),
            st.chart_switches,
            st.steps
        );
        assert!(closest < 2e-2, "{closest}");
        assert!(st.chart_switches >= 2);
        assert!(de <= 1e-8 && dlz <= 1e-8, "{de:e} {dlz:e}");
        rows.push((de, dlz));
    }
    let model = SphericalPendulumZyx::default();
    let Err(e) = simulate(model, Scheme::Dopri5, adaptive(3.0, 1e-10)) else {
        panic!("the Euler angles stop at the bottom")
    };
    println!("spherical pendulum on Euler angles: {e}");
    assert!(
        matches!(e.kind, Failure::SingularConfiguration { .. }),
        "{e}"
    );
    let _ = SphericalPendulum::default().info();
    let [(e0, l0), (e1, l1)] = rows[..] else {
        unreachable!()
    };
    let stop = e.t;
    quoted::says(
        "docs/rotations.md",
        &[format!(
            "| spherical pendulum through the bottom, 3 s | E {e0:.1e} / {e1:.1e}, L_z {l0:.1e} / {l1:.1e} | — | stops at t = {stop:.3} s (DOPRI5)"
        )],
    );
    quoted::says(
        "README.md",
        &[format!(
            "| spherical pendulum through the bottom, 3 s | DOPRI5 {e0:.1e}, {l0:.1e}; Radau5 {e1:.1e}, {l1:.1e}; on ZYX angles it stops at t = {stop:.3} s (DOPRI5)"
        )],
    );
}

/// The tumble's start turned by φ0 about world x, whose accurate flip meets the singularity
/// of its ZYX twin at t ≈ 8.0 s (`tests/hard_cases/tumble.rs`).
fn turned(mut o: Options) -> Options {
    let (q0, qd0) = turned_start(PHI0);
    (o.q0, o.qd0) = (Some(q0), Some(qd0));
    o
}

/// Every scheme, at a fixed step and (where it has an error estimate) adaptive, carries the
/// tumble through the flips that stop its ZYX twin (`tests/hard_cases/singular.rs`): no
/// typed error, the charts re-centred, energy and momentum within each scheme's accuracy.
#[test]
fn every_scheme_runs_the_tumble_through_its_flips() {
    use mbs::{BdfParams, GenAlphaParams, HhtParams, NewmarkParams};
    // (scheme, bound at h = 1e-3, (rtol, bound) adaptive): the bounds are about 5 times the
    // drifts measured (printed), each scheme's accuracy at that step or tolerance
    let schemes = [
        (Scheme::ExplicitEuler, 0.2, None),
        (Scheme::Rk4, 5e-8, None),
        (Scheme::Rkc, 5e-4, Some((1e-6, 3e-6))),
        (Scheme::Dopri5, 1e-11, Some((1e-6, 2e-5))),
        (Scheme::Newmark(NewmarkParams::default()), 5e-4, None),
        (Scheme::Hht(HhtParams::default()), 1e-3, Some((1e-6, 2e-3))),
        (
            Scheme::GenAlpha(GenAlphaParams::default()),
            1e-3,
            Some((1e-6, 3e-3)),
        ),
        (Scheme::Bdf(BdfParams::default()), 1e-3, Some((1e-6, 3e-6))),
        (Scheme::Radau3, 5e-7, Some((1e-6, 1e-5))),
        (Scheme::Radau5, 5e-9, Some((1e-6, 1e-6))),
        (Scheme::ImplicitMidpoint, 5e-4, None),
    ];
    // (re-centrings, the larger drift, scheme, how) of every run
    let mut runs_made = Vec::new();
    for (scheme, bound_fixed, adaptive_run) in schemes {
        let fixed = Options {
            t_end: 20.0,
            step: StepControl::Fixed { h: 1e-3 },
            output: Output::Every { dt: 0.01 },
            ..Options::default()
        };
        let mut runs = vec![("h 1e-3", fixed, bound_fixed)];
        if let Some((rtol, bound)) = adaptive_run {
            let mut o = adaptive(20.0, rtol);
            o.output = Output::Every { dt: 0.01 };
            runs.push(("adaptive", o, bound));
        }
        for (how, o, bound) in runs {
            let (tr, st) = simulate(TumbleBall::default(), scheme, turned(o))
                .unwrap_or_else(|e| panic!("{} {how}: {e}", scheme.name()));
            let (de, dl) = drifts(&tr, INERTIA, None);
            println!(
                "tumble turned by φ0, {:<9} {how:<8}: {:>2} re-centrings, energy drift {de:.1e}, momentum drift {dl:.1e}, {} steps",
                scheme.name(),
                st.chart_switches,
                st.steps
            );
            assert!(st.chart_switches >= 2, "{}", scheme.name());
            assert!(
                de < bound && dl < bound,
                "{} {how}: {de:e} {dl:e}",
                scheme.name()
            );
            runs_made.push((st.chart_switches, de.max(dl), scheme, how));
        }
    }
    let fewest = runs_made.iter().map(|r| r.0).min().unwrap();
    let most = runs_made.iter().map(|r| r.0).max().unwrap();
    let least = runs_made.iter().min_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
    let worst = runs_made.iter().max_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
    assert_eq!((least.2, least.3), (Scheme::Dopri5, "h 1e-3"));
    assert_eq!(worst.2, Scheme::ExplicitEuler);
    quoted::says(
        "docs/rotations.md",
        &[format!(
            "completes with {fewest}–{most} re-centrings; drifts from {:.0e} (DOPRI5 at h 1e-3) to {:.0e} (explicit Euler)",
            least.1, worst.1
        )],
    );
}

/// The sleeping top — spinning upright, exactly where its ZYX angles lock — linearised in the
/// chart centred on it: the poles are the closed form's, ±iω± with
/// I1' ω² − L3 ω + m g l = 0 (L3 = I3 ω3, I1' the transverse inertia about the tip), and a
/// double zero for the spin angle, which the equations do not depend on.
#[test]
fn the_sleeping_top_linearised_through_gimbal_lock_has_the_closed_form_poles() {
    let (m, l, i1, i3, g, w3) = (0.1, 0.04, 2e-5, 4e-5, 9.81, 200.0);
    let it = i1 + m * l * l;
    let model = Top::default();
    // upright: body x along world z, b = −π/2 in the identity chart; spin ω3 about body x
    let q = [0.0, -std::f64::consts::FRAC_PI_2, 0.0];
    let qd = [0.0, 0.0, w3];
    let lin = mbs::linearize(&model, 0.0, &q, &qd, &[], mbs::IterationMatrix::Auto).unwrap();
    assert_eq!(lin.charts.len(), 1);
    assert_eq!(lin.q, vec![0.0; 3]);
    let poles = mbs::modes(&lin, None).unwrap();
    let mut im: Vec<f64> = poles.modes.iter().map(|p| p.im.abs()).collect();
    im.sort_by(f64::total_cmp);
    let l3 = i3 * w3;
    let disc = (l3 * l3 - 4.0 * it * m * g * l).sqrt();
    let (slow, fast) = ((l3 - disc) / (2.0 * it), (l3 + disc) / (2.0 * it));
    println!(
        "sleeping top: poles {:?}; closed form ±{slow:.6}i, ±{fast:.6}i",
        poles.modes.iter().map(|p| (p.re, p.im)).collect::<Vec<_>>()
    );
    let re = poles.modes.iter().fold(0.0f64, |a, p| a.max(p.re.abs()));
    assert!(re < 1e-9 * fast, "{re}");
    let found: Vec<f64> = im.iter().copied().filter(|&w| w > 1e-6).collect();
    assert_eq!(found.len(), 2, "{im:?}");
    assert!((found[0] - slow).abs() < 1e-9 * slow && (found[1] - fast).abs() < 1e-9 * fast);
    quoted::says(
        "docs/rotations.md",
        &[format!(
            "in a chart centred on it, has the closed-form poles ±{slow:.6}i, ±{fast:.6}i to 1e-9"
        )],
    );
    // slower, below L3² = 4 I1' m g l, the upright top is unstable: a real pole pair
    let slow_top = mbs_models::top::TopParams {
        w3: 50.0,
        ..Default::default()
    };
    let model = Top::new(slow_top).unwrap();
    let lin = mbs::linearize(
        &model,
        0.0,
        &q,
        &[0.0, 0.0, 50.0],
        &[],
        mbs::IterationMatrix::Auto,
    )
    .unwrap();
    let unstable = mbs::modes(&lin, None)
        .unwrap()
        .modes
        .iter()
        .any(|p| p.re > 1.0);
    assert!(unstable);
}

mbs::multibody! {
    /// A spherical pendulum whose bob sits off the rod's axis (so that its spin about the rod
    /// lifts it; only turning about the vertical is free): the ZYX angles of its start chart
    /// are singular where the rod points down.
    model OffsetPendulum {
        dof a = 0.0; dof b = 0.0; dof c = 0.0;
        body bob { mass = 1.0; inertia = (0.01, 0.02, 0.02); }
        TOG[bob] = Tball(a, b, c) * Tdisp(1.0, 0.0, 0.2);
        gravity(0, 0, -9.81);
    }
}

/// The equilibrium of a spherical pendulum from a start 0.5 rad from hanging, the hanging
/// position being where its ZYX chart at the start locks: Newton in a chart centred on the
/// start finds it, stable in its two tilts.
#[test]
fn statics_find_an_equilibrium_where_the_starting_chart_locks() {
    let model = OffsetPendulum::default();
    let options = mbs::StaticsOptions {
        q0: Some(vec![0.4, std::f64::consts::FRAC_PI_2 - 0.5, -0.3]),
        ..Default::default()
    };
    let eq = mbs::static_equilibrium(&model, &options).unwrap();
    println!("{eq}");
    assert_eq!(eq.charts.len(), 1);
    // the bob's centre hangs right below the pivot, at its distance √(1 + 0.2²)
    let mut posed = model.clone();
    posed.set_chart(0, eq.charts[0]);
    let mut poses = vec![mbs::Pose::default(); 1];
    posed.frames(0.0, &eq.q, &mut poses);
    let p = poses[0].position;
    let d = (1.0f64 + 0.04).sqrt();
    assert!(
        p[0].abs() < 1e-9 && p[1].abs() < 1e-9 && (p[2] + d).abs() < 1e-9,
        "{p:?}"
    );
    // two stiff tilts; turning about the vertical through the pivot costs nothing
    assert_eq!(eq.stability, mbs::Stability::Neutral);
    let e = &eq.stiffness_eigenvalues;
    assert!(e[0].abs() < 1e-9 && e[1] > 1.0 && e[2] > 1.0, "{e:?}");
}

/// Statics that stop short of converging give their last q in the model's charts, where a
/// retry starts, not in the chart they re-centred on (read in the model's, those small
/// angles put the bob out level beside the pivot): from a hair off the equilibrium, one
/// Newton step at an unreachable tolerance stops with the bob hanging below the pivot.
#[test]
fn statics_that_stop_short_give_q_in_the_models_charts() {
    let model = OffsetPendulum::default();
    let options = mbs::StaticsOptions {
        q0: Some(vec![0.4, std::f64::consts::FRAC_PI_2 - 0.5, -0.3]),
        ..Default::default()
    };
    let eq = mbs::static_equilibrium(&model, &options).unwrap();
    // its angles in the model's chart (the identity), a hair off
    let mut posed = model.clone();
    posed.set_chart(0, eq.charts[0]);
    let mut q0 = eq.q.clone();
    mbs::charts::reread_angles(&posed, &model, &mut q0);
    q0.iter_mut().for_each(|x| *x += 1e-7);
    let err = mbs::static_equilibrium(
        &model,
        &mbs::StaticsOptions {
            q0: Some(q0),
            tolerance: 1e-300,
            max_iterations: 1,
            ..Default::default()
        },
    )
    .unwrap_err();
    let mbs::AnalysisError::NotConverged { q, .. } = err else {
        panic!("{err}");
    };
    let mut poses = vec![mbs::Pose::default(); 1];
    model.frames(0.0, &q, &mut poses);
    let p = poses[0].position;
    let d = (1.0f64 + 0.04).sqrt();
    assert!(
        p[0].abs() < 1e-6 && p[1].abs() < 1e-6 && (p[2] + d).abs() < 1e-6,
        "{p:?} at q = {q:?}"
    );
}

/// What a trajectory says of a rotation joint is continuous across re-centrings: the poses
/// (which the HTML animation and the glTF file play) and the quaternion columns, while the
/// angles jump; each output's chart and angles give its pose back.
#[test]
fn outputs_are_continuous_across_recentrings() {
    let o = Options {
        t_end: 20.0,
        output: Output::Every { dt: 0.01 },
        frames: true,
        ..adaptive(20.0, 1e-8)
    };
    let (tr, st) = simulate(TumbleBall::default(), Scheme::Dopri5, turned(o)).unwrap();
    assert!(st.chart_switches >= 2);
    assert_eq!(tr.joint_names, vec!["b".to_string()]);
    let charts: Vec<u32> = (0..tr.len()).map(|i| tr.chart_numbers(i)[0]).collect();
    assert_eq!(*charts.last().unwrap() as usize, st.chart_switches);
    assert_eq!(tr.charts[0].len(), st.chart_switches + 1);
    let (mut jumps, mut worst_pose, mut worst_step) = (0, 0.0f64, 0.0f64);
    for i in 0..tr.len() {
        // the pose, the quaternion and chart · Rz(a) Ry(b) Rx(c) agree
        let pose = tr.poses_at(i)[0].rotation;
        let quat = rotation(tr.orientation(i));
        let c = tr.chart(i, 0);
        let q = tr.q(i);
        let e = mbs::charts::zyx([q[0], q[1], q[2]]);
        for r in 0..3 {
            for k in 0..3 {
                let ce: f64 = (0..3).map(|m| c[r][m] * e[(m, k)]).sum();
                worst_pose = worst_pose
                    .max((pose[r][k] - quat[r][k]).abs())
                    .max((ce - quat[r][k]).abs());
            }
        }
        if i > 0 {
            // |ω| ≤ 10.1 rad/s: a quaternion moves by at most ½|ω|dt per output
            let dq: f64 = (0..4)
                .map(|k| (tr.orientation(i)[k] - tr.orientation(i - 1)[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            worst_step = worst_step.max(dq);
            let da = (0..3)
                .map(|k| (q[k] - tr.q(i - 1)[k]).abs())
                .fold(0.0, f64::max);
            jumps += (charts[i] != charts[i - 1] && da > 0.2) as usize;
        }
    }
    println!(
        "{} outputs, {} charts: poses vs quaternions vs chart·E(q) {worst_pose:.1e}, largest quaternion step {worst_step:.3}, {jumps} jumps of the angles at re-centrings",
        tr.len(),
        st.chart_switches + 1
    );
    assert!(worst_pose < 1e-12);
    assert!(worst_step < 0.5 * 10.1 * 0.01 * 1.01);
    assert!(jumps >= 1);
    // the CSV carries the quaternion and the chart number
    let mut csv = Vec::new();
    tr.write_csv(&mut csv).unwrap();
    let text = String::from_utf8(csv).unwrap();
    let header = text.lines().next().unwrap();
    assert!(header.contains(",b.qx,b.qy,b.qz,b.qw,b.chart,"), "{header}");
}

mbs::multibody! {
    /// A double spherical pendulum: a rod on a ball joint at the pivot, a second rod on a
    /// ball joint at its end (a joint inside a chain), each with its mass at its far end.
    model DoubleBall {
        dof a1 = 0.0, qd = 1.5; dof b1 = 0.9; dof c1 = 0.0;
        dof a2 = 0.0, qd = 1.0; dof b2 = 0.2, qd = 6.0; dof c2 = 0.0, qd = 0.5;
        body upper { mass = 1.0; inertia = (0.001, 0.02, 0.02); }
        body lower { mass = 0.5; inertia = (0.001, 0.01, 0.01); }
        TOG[upper] = Tball(a1, b1, c1) * Tdisp(0.5, 0, 0);
        TOG[lower] = TOG[upper] * Tdisp(0.5, 0, 0) * Tball(a2, b2, c2) * Tdisp(0.4, 0, 0);
        gravity(0, 0, -9.81);
    }
}

mbs::multibody! {
    /// [`DoubleBall`] with both charts fixed at the rotations of `charts()` (as constant
    /// `Trotn` factors), to compare the generated code of a chart with its constant.
    model DoubleFixed {
        dof a1 = 0.0; dof b1 = 0.0; dof c1 = 0.0;
        dof a2 = 0.0; dof b2 = 0.0; dof c2 = 0.0;
        body upper { mass = 1.0; inertia = (0.001, 0.02, 0.02); }
        body lower { mass = 0.5; inertia = (0.001, 0.01, 0.01); }
        TOG[upper] = Trotn(0.6, 0.0, 0.8, 0.7) * Trotz(a1) * Troty(b1) * Trotx(c1) * Tdisp(0.5, 0, 0);
        TOG[lower] = TOG[upper] * Tdisp(0.5, 0, 0) * Trotn(0.0, 0.6, -0.8, -1.1) * Trotz(a2) * Troty(b2) * Trotx(c2) * Tdisp(0.4, 0, 0);
        gravity(0, 0, -9.81);
    }
}

/// Rodrigues' rotation about the unit axis `n`.
fn rodrigues(n: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let (s, c) = angle.sin_cos();
    let k = [[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let kk: f64 = (0..3).map(|m| k[i][m] * k[m][j]).sum();
            r[i][j] = f64::from(u8::from(i == j)) + s * k[i][j] + (1.0 - c) * kk;
        }
    }
    r
}

/// A chart read at run time gives the generated code of the same rotation written as a
/// constant: M, h and the poses of a chain with a ball joint at its root and one inside it.
#[test]
fn charts_inside_a_chain_are_their_rotations() {
    let mut ball = DoubleBall::default();
    ball.set_chart(0, rodrigues([0.6, 0.0, 0.8], 0.7));
    ball.set_chart(1, rodrigues([0.0, 0.6, -0.8], -1.1));
    let fixed = DoubleFixed::default();
    let n = 6;
    let mut worst = 0.0f64;
    for k in 0..5 {
        let q: Vec<f64> = (0..n)
            .map(|i| (1.3 * (i + 7 * k) as f64 + 0.4).sin())
            .collect();
        let qd: Vec<f64> = (0..n)
            .map(|i| 2.0 * (0.9 * (i + 3 * k) as f64).cos())
            .collect();
        let (mut m1, mut h1, mut m2, mut h2) =
            (vec![0.0; 36], vec![0.0; 6], vec![0.0; 36], vec![0.0; 6]);
        ball.dynamics(0.0, &q, &qd, &[], &mut m1, &mut h1);
        fixed.dynamics(0.0, &q, &qd, &[], &mut m2, &mut h2);
        let mut p1 = vec![mbs::Pose::default(); 2];
        let mut p2 = vec![mbs::Pose::default(); 2];
        ball.frames(0.0, &q, &mut p1);
        fixed.frames(0.0, &q, &mut p2);
        let scale = m2.iter().chain(&h2).fold(1.0f64, |s, x| s.max(x.abs()));
        for (x, y) in m1.iter().chain(&h1).zip(m2.iter().chain(&h2)) {
            worst = worst.max((x - y).abs() / scale);
        }
        for (a, b) in p1.iter().zip(&p2) {
            for i in 0..3 {
                worst = worst.max((a.position[i] - b.position[i]).abs());
            }
        }
    }
    println!("a ball joint's chart against its constant rotation: {worst:.1e}");
    assert!(worst < 1e-13, "{worst:e}");
}

/// A double spherical pendulum, one joint inside the chain, through its chaotic motion: both
/// charts re-centred, energy conserved.
#[test]
fn a_ball_joint_inside_a_chain_runs_through() {
    let (tr, st) = simulate(DoubleBall::default(), Scheme::Dopri5, adaptive(5.0, 1e-10)).unwrap();
    let de = energy_drift(&tr);
    let per_joint: Vec<u32> = (0..2).map(|j| tr.chart_numbers(tr.len() - 1)[j]).collect();
    println!(
        "double spherical pendulum, 5 s: re-centrings per joint {per_joint:?}, energy drift {de:.1e}, {} steps",
        st.steps
    );
    assert!(per_joint.iter().all(|&c| c >= 1), "{per_joint:?}");
    assert!(de < 1e-8, "{de:e}");
}

mbs::multibody! {
    /// A spherical pendulum held in the x–z plane by a constraint on its bob (y = 0) against
    /// gravity leaning out of it: a planar pendulum on a ball joint, swinging through the
    /// bottom, where the joint's first chart locks; the loop is closed through the joint's
    /// angles.
    model PlanarBall {
        dof a = 0.0; dof b = 0.5; dof c = 0.0;
        body bob { mass = 1.0; inertia = (0.001, 0.001, 0.001); }
        TOG[bob] = Tball(a, b, c) * Tdisp(1.0, 0, 0);
        constraint plane: coincide(bob, ground, along = [y]);
        // gravity leans out of the plane: the constraint holds the bob against it
        gravity(0, -3.0, -9.81);
    }
}

/// Closed loops through a ball joint run through its re-centrings with every constraint
/// method a scheme offers: index 3 (generalized-α, Radau5), stabilized index 2, projection.
#[test]
fn closed_loops_through_a_ball_joint_run_through() {
    use mbs::{ConstraintMethod, ConstraintOptions, GenAlphaParams};
    let gen_alpha = Scheme::GenAlpha(GenAlphaParams::default());
    for (scheme, method, bound) in [
        // the energy bounds are about 5 times the drifts measured at rtol 1e-8
        (Scheme::Dopri5, ConstraintMethod::Projection, 2e-7),
        (Scheme::Radau5, ConstraintMethod::Projection, 1e-7),
        (Scheme::Radau5, ConstraintMethod::Index3, 2e-7),
        (Scheme::Radau5, ConstraintMethod::Index2, 1e-7),
        (gen_alpha, ConstraintMethod::Index3, 5e-6),
        (gen_alpha, ConstraintMethod::Index2, 2e-8),
    ] {
        let o = Options {
            constraints: ConstraintOptions {
                method,
                ..ConstraintOptions::default()
            },
            ..adaptive(3.0, 1e-8)
        };
        let (tr, st) = simulate(PlanarBall::default(), scheme, o)
            .unwrap_or_else(|e| panic!("{} {method:?}: {e}", scheme.name()));
        let de = energy_drift(&tr);
        let model = PlanarBall::default();
        let mut drift = 0.0f64;
        let mut m = model.clone();
        for i in 0..tr.len() {
            mbs::charts::use_charts_of(&mut m, &tr, i);
            let mut phi = [0.0];
            m.constraints(tr.t[i], tr.q(i), &mut phi);
            drift = drift.max(phi[0].abs());
        }
        let closest = from_vertical(&tr, true)
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        println!(
            "planar ball, {} {method:?}: {} re-centrings, closest to the bottom {closest:.1e} rad, energy drift {de:.1e}, max |Φ| {drift:.1e}, {} steps",
            scheme.name(),
            st.chart_switches,
            st.steps
        );
        assert!(st.chart_switches >= 2 && closest < 0.05);
        assert!(de < bound, "{de:e}");
        assert!(drift < 1e-9, "{drift:e}");
        // the trajectory's own measure reads each output in its charts alike
        assert_eq!(tr.constraint_residual(&model), drift);
    }
}

/// Inverse dynamics along the top's run, each output read in its own charts, is zero (the
/// motion is free): the accelerations the driver maps at a re-centring are the motion's.
#[test]
fn inverse_dynamics_along_a_recentred_run_is_zero() {
    let (tr, st) = simulate(
        Top::default(),
        Scheme::Dopri5,
        Options {
            output: Output::Every { dt: 0.001 },
            ..Options::adaptive(2.0, 1e-10)
        },
    )
    .unwrap();
    assert!(st.chart_switches >= 1);
    let mut model = Top::default();
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    let mut tau = [0.0; 3];
    for i in 0..tr.len() {
        mbs::charts::use_charts_of(&mut model, &tr, i);
        model.inverse_dynamics(tr.t[i], tr.q(i), tr.qd(i), tr.qdd(i), &[], &mut tau);
        let (mut m, mut h) = ([0.0; 9], [0.0; 3]);
        model.dynamics(tr.t[i], tr.q(i), tr.qd(i), &[], &mut m, &mut h);
        scale = h.iter().fold(scale, |s, x| s.max(x.abs()));
        worst = tau.iter().fold(worst, |w, x| w.max(x.abs()));
    }
    // the library's τ along a trajectory reads each output in its charts alike
    let efforts = mbs::analysis::inverse_dynamics_of(&Top::default(), &tr, &[]).unwrap();
    let along = efforts.tau.iter().fold(0.0f64, |w, x| w.max(x.abs()));
    println!(
        "top: largest |τ| along the run {worst:.1e}, by inverse_dynamics_of {along:.1e} (largest |h| {scale:.1e}; {} re-centrings)",
        st.chart_switches
    );
    assert!(worst < 1e-6 * scale, "{worst:e}");
    assert_eq!(efforts.t.len(), tr.len());
    assert!(along < 1e-6 * scale, "{along:e}");
    quoted::says(
        "README.md",
        &[format!(
            "τ along the top's free run, through {} re-centrings, is at most {along:.1e} N·m",
            quoted::word(st.chart_switches)
        )],
    );
}
