//! The hexapod walks (`models/src/hexapod_walker.rs`, `examples/hexapod_walk.rs`): the
//! figures the example prints, asserted with margins on the runs it makes, under the 1 kHz
//! sampled controller with the example's scheme (RKC, 0.5 ms: two steps per control period),
//! and that scheme against RK4 at 0.2 ms on the same walk.
//!
//! - tripod gait on flat ground: ≥ 2 m forward at ≥ 0.1 m/s, heading error ≤ 5°, no foot
//!   slipping more than 1 cm during one contact, base height within ±1 cm of its set point
//!   after the first cycle;
//! - a turn on the spot and the 5 cm step climbed;
//! - the continuous-time PIDs and the sampled controller walk alike;
//! - the leg's inverse kinematics inverts its forward kinematics;
//! - faults: an unreachable start is a typed error, an unreachable target during the walk
//!   is recorded (the controller holds its voltages) or, with the continuous PIDs, a typed
//!   failure that keeps the trajectory; saturated motors and feet that find no ground where
//!   the controller expects it are modelled, never a panic.

use mbs::{Options, Output, Scheme, StepControl};
use mbs_models::hexapod_walker::*;

#[path = "common/quoted.rs"]
mod quoted;

/// The README's table cells of a walk's heading error, slip, height error and energy:
/// `| 0.04° | 4.6 mm | 1.9 mm | 1,177 J`.
fn cells(f: &Figures) -> String {
    format!(
        "| {:.2}° | {:.1} mm | {:.1} mm | {} J",
        f.heading_error_deg,
        1e3 * f.max_slip,
        1e3 * f.height_error,
        quoted::thousands(f.energy.round() as usize)
    )
}

/// The example's scheme and step.
const SCHEME: Scheme = Scheme::Rkc;
const H: f64 = 5e-4;

fn options(t_end: f64) -> Options {
    options_at(t_end, H)
}

fn options_at(t_end: f64, h: f64) -> Options {
    Options {
        t_end,
        step: StepControl::Fixed { h },
        output: Output::Every { dt: 0.005 },
        ..Options::default()
    }
}

fn run(walker: &Walker, t_end: f64) -> (Walk, Figures) {
    let w = walk(walker, Control::Sampled, SCHEME, options(t_end)).expect("reachable start");
    if let Some(e) = &w.failure {
        panic!("the walk stopped: {e}");
    }
    let f = w.figures();
    println!("{f:#?}");
    (w, f)
}

#[test]
fn tripod_walks_two_metres_straight_on_flat_ground() {
    let walker = Walker::new(GaitParams::new(Gait::Tripod, 0.15));
    let (w, f) = run(&walker, 16.0);
    assert!(f.distance >= 2.0, "walked {} m", f.distance);
    assert!(f.speed >= 0.1, "speed {} m/s", f.speed);
    assert!(f.heading_error_deg <= 5.0, "{}°", f.heading_error_deg);
    assert!(f.lateral.abs() <= 0.02, "{} m sideways", f.lateral);
    assert!(f.max_slip <= 0.01, "a foot slipped {} m", f.max_slip);
    assert!(
        f.height_error <= 0.01,
        "base height off by {} m",
        f.height_error
    );
    // every foot stepped: about a contact per leg and cycle
    assert!(f.contacts >= 6 * 14, "{} contacts", f.contacts);
    assert!(w.log.failure.is_none());
    assert_eq!(w.stats.samples, 16_001);
    // the motors did the work: energy drawn, no voltage pinned at the supply
    assert!(f.energy > 0.0 && f.cost_of_transport.is_finite());
    assert!(f.saturated < 0.01, "{}", f.saturated);
    quoted::says(
        "README.md",
        &[format!(
            "| tripod, 0.15 m/s, flat, 16 s | {:.2} m, {:.3} m/s {}, {:.2} |",
            f.distance,
            f.speed,
            cells(&f),
            f.cost_of_transport
        )],
    );
}

/// Reads the base's angles at every output of `tr` in a chart tilted by the ZYX `angles`,
/// as the runtime would after re-centring it: q's angles change, the motion does not (the
/// rates are left as they are: the walk's figures read positions).
fn read_in_chart(tr: &mut mbs::Trajectory, angles: [f64; 3]) {
    use mbs::Model;
    use mbs::charts::{array, joint_rotation, quaternion_near, zyx, zyx_angles_of};
    let joint = HexapodWalker::default().info().rotation_joints[0];
    let chart = zyx(angles);
    let k = tr.charts[0].len() as u32;
    let zero = vec![0.0; tr.nq()];
    let c = joint_rotation(&array(&chart), &joint, &zero);
    tr.charts[0].push(quaternion_near(&c, None));
    let back = array(&chart.transpose());
    let (n, joints) = (tr.nq(), tr.joint_names.len());
    for i in 0..tr.len() {
        let r = joint_rotation(&back, &joint, tr.q(i));
        let a = zyx_angles_of(quaternion_near(&r, None));
        for (s, &j) in joint.angles.iter().enumerate() {
            tr.q_data[i * n + j] = a[s];
        }
        tr.chart_data[i * joints] = k;
    }
}

#[test]
fn turns_on_the_spot() {
    let mut gait = GaitParams::new(Gait::Tripod, 0.0);
    gait.yaw_rate = 0.2;
    let (mut w, f) = run(&Walker::new(gait.clone()), 8.0);

    // the figures of the same walk with the base's angles read in a chart tilted by 1 rad
    // (as after a re-centring) are the same: they read the base's orientation, not q
    let pitch = w.trajectory.q(100)[4];
    read_in_chart(&mut w.trajectory, [0.6, 1.0, -0.3]);
    assert!(
        (w.trajectory.q(100)[4] - pitch).abs() > 0.5,
        "the chart moved q"
    );
    let g = w.figures();
    println!("{f:?}\n{g:?}");
    for (a, b) in [
        (f.turned_deg, g.turned_deg),
        (f.heading_error_deg, g.heading_error_deg),
        (f.pitch_range_deg, g.pitch_range_deg),
        (f.roll_range_deg, g.roll_range_deg),
        (f.height_error, g.height_error),
        (f.max_slip, g.max_slip),
    ] {
        assert!((a - b).abs() < 1e-9, "{a} against {b}");
    }
    assert_eq!(f.contacts, g.contacts);

    let planned = (gait.yaw_rate * gait.ramp_integral(8.0)).to_degrees();
    assert!(planned > 75.0, "{planned}");
    assert!(
        (f.turned_deg - planned).abs() <= 5.0,
        "turned {}° of {planned}°",
        f.turned_deg
    );
    assert!(
        f.distance.hypot(f.lateral) <= 0.03,
        "{} {}",
        f.distance,
        f.lateral
    );
    assert!(f.max_slip <= 0.01, "{}", f.max_slip);
    quoted::says(
        "README.md",
        &[format!(
            "| turn on the spot, 0.2 rad/s, 8 s | turned {:.1}° (planned {planned:.1}°) {} |",
            f.turned_deg,
            cells(&f)
        )],
    );
}

#[test]
fn climbs_a_5_cm_step() {
    let mut walker = Walker::new(GaitParams::new(Gait::Tripod, 0.15));
    walker.gait.step_height = 0.08;
    walker.terrain = Terrain::step(0.6, 0.05);
    let (_, f) = run(&walker, 10.0);
    // every foot on the step at the end, the base at its set point above it
    assert!(
        f.lowest_foot_end >= 0.045,
        "lowest foot {} m",
        f.lowest_foot_end
    );
    assert!(f.distance >= 1.2, "{}", f.distance);
    assert!(f.height_error <= 0.01, "{}", f.height_error);
    assert!(f.max_slip <= 0.01, "{}", f.max_slip);
    quoted::says(
        "README.md",
        &[format!(
            "| tripod onto a 5 cm step, 10 s | {:.2} m, every foot on the step {}, {:.2} |",
            f.distance,
            cells(&f),
            f.cost_of_transport
        )],
    );
}

/// The largest differences of the base's x, z and pitch between two walks sampled alike.
fn largest_differences(a: &Walk, b: &Walk) -> [f64; 3] {
    let (a, b) = (&a.trajectory, &b.trajectory);
    assert_eq!(a.len(), b.len());
    let mut worst = [0.0f64; 3];
    for i in 0..a.len() {
        for (k, c) in [0, 2, 4].into_iter().enumerate() {
            worst[k] = worst[k].max((a.q(i)[c] - b.q(i)[c]).abs());
        }
    }
    worst
}

#[test]
fn rkc_walks_as_rk4_does() {
    // the example's RKC at 0.5 ms (4–5 stages: its fastest modes, friction and the motors'
    // electrical poles, decay) against RK4 at 0.2 ms (2.785/ρ for ρ up to 1.1e4 1/s)
    let walker = Walker::new(GaitParams::new(Gait::Tripod, 0.15));
    let rkc = walk(&walker, Control::Sampled, SCHEME, options(3.0)).unwrap();
    let rk4 = walk(
        &walker,
        Control::Sampled,
        Scheme::Rk4,
        options_at(3.0, 2e-4),
    )
    .unwrap();
    assert!(rkc.failure.is_none() && rk4.failure.is_none());
    let worst = largest_differences(&rkc, &rk4);
    let (ea, eb) = (rkc.figures().energy, rk4.figures().energy);
    println!(
        "RKC against RK4: x {:.2e} m, z {:.2e} m, pitch {:.2e} rad apart; energy {ea:.2} J against {eb:.2} J; evaluations {} against {}",
        worst[0],
        worst[1],
        worst[2],
        rkc.stats.evaluations(),
        rk4.stats.evaluations()
    );
    assert!(
        worst[0] < 2e-4 && worst[1] < 5e-5 && worst[2] < 1e-4,
        "{worst:?}"
    );
    assert!((ea - eb).abs() < 0.01 * eb, "{ea} J vs {eb} J");
    assert!(2 * rkc.stats.evaluations() < rk4.stats.evaluations());
    quoted::says(
        "README.md",
        &[format!(
            "RKC at 0.5 ms against RK4 at 0.2 ms over 3 s ({:.0} µm apart in x, energies within {:.1} %, asserted below 0.2 mm and 1 %, with {:.1}× fewer evaluations)",
            1e6 * worst[0],
            100.0 * (ea - eb).abs() / eb,
            rk4.stats.evaluations() as f64 / rkc.stats.evaluations() as f64
        )],
    );
}

#[test]
fn sampled_and_continuous_controllers_walk_alike() {
    let walker = Walker::new(GaitParams::new(Gait::Tripod, 0.15));
    let sampled = walk(&walker, Control::Sampled, SCHEME, options(3.0)).unwrap();
    let continuous = walk(&walker, Control::Continuous, SCHEME, options(3.0)).unwrap();
    assert!(sampled.failure.is_none() && continuous.failure.is_none());
    let worst = largest_differences(&sampled, &continuous);
    println!(
        "largest differences: x {:.2e} m, z {:.2e} m, pitch {:.2e} rad",
        worst[0], worst[1], worst[2]
    );
    // a 1 kHz zero-order hold against the continuous law: tenths of a millimetre at most
    assert!(
        worst[0] < 2e-4 && worst[1] < 5e-5 && worst[2] < 1e-4,
        "{worst:?}"
    );
    // but not the same run
    assert!(worst[1] > 0.0);
    let (ea, eb) = (sampled.figures().energy, continuous.figures().energy);
    assert!((ea - eb).abs() < 0.02 * ea, "{ea} J vs {eb} J");
    quoted::says(
        "README.md",
        &[format!(
            "the sampled and continuous controllers agreeing ({:.0e} m apart in x, asserted below 2e-4 m)",
            worst[0]
        )],
    );
}

#[test]
fn leg_inverse_kinematics_inverts_the_forward_kinematics() {
    for leg in 0..LEGS {
        for &(a, b, c) in &[(0.0, 0.3, -0.3), (0.2, -0.1, 0.4), (-0.3, 0.5, 0.1)] {
            let p = leg_fk(leg, a, b, c);
            let j = leg_ik(leg, p).unwrap();
            let back = leg_fk(leg, j[0], j[1], j[2]);
            for k in 0..3 {
                assert!(
                    (back[k] - p[k]).abs() < 1e-12,
                    "leg {leg}: {p:?} vs {back:?}"
                );
            }
            assert!(
                (j[0] - a).abs() < 1e-12 && (j[1] - b).abs() < 1e-12 && (j[2] - c).abs() < 1e-12
            );
        }
    }
    let e = leg_ik(2, [0.0, 2.0, -0.4]).unwrap_err();
    assert_eq!(e.leg, 2);
    assert!(e.to_string().contains("cannot reach"), "{e}");
}

#[test]
fn faults_are_modelled_or_typed() {
    // a start the legs cannot reach: a typed error before any step
    let mut gait = GaitParams::new(Gait::Tripod, 0.15);
    gait.height = 0.9;
    let e = walk(&Walker::new(gait), Control::Sampled, SCHEME, options(1.0)).err();
    assert!(e.is_some_and(|e| e.to_string().contains("cannot reach")));

    // strides the legs cannot reach (2.5 m/s asks for 1.4 m): the sampled controller holds
    // its voltages and says so; the continuous PIDs stop the run with a typed failure that
    // keeps the trajectory
    let walker = Walker::new(GaitParams::new(Gait::Tripod, 2.5));
    let w = walk(&walker, Control::Sampled, SCHEME, options(1.5)).unwrap();
    let (t, e) = w.log.failure.as_ref().expect("recorded");
    assert!(
        *t > walker.gait.start && e.to_string().contains("cannot reach"),
        "{t} {e}"
    );
    let w = walk(&walker, Control::Continuous, SCHEME, options(1.5)).unwrap();
    let failure = w.failure.as_ref().expect("a typed failure");
    assert!(
        matches!(failure.kind, mbs::Failure::UserEffort { .. }),
        "{failure}"
    );
    assert!(failure.to_string().contains("cannot reach"), "{failure}");
    assert!(w.trajectory.len() > 100 && *w.trajectory.t.last().unwrap() > walker.gait.start);

    // motors on a 6 V supply saturate: modelled (voltages clipped), no panic
    let mut walker = Walker::new(GaitParams::new(Gait::Tripod, 0.15));
    walker.motor.v_max = 6.0;
    let w = walk(&walker, Control::Sampled, SCHEME, options(3.0)).unwrap();
    let f = w.figures();
    assert!(f.saturated > 0.0 && f.peak_voltage <= 6.0, "{f:?}");

    // the controller expects a 5 cm step the ground does not have: feet lose their contact
    // where it plans them; whatever happens is a trajectory or a typed failure
    let mut walker = Walker::new(GaitParams::new(Gait::Tripod, 0.15));
    walker.terrain = Terrain::step(0.6, 0.05);
    let w = walk_on(
        &walker,
        &Terrain::default(),
        Control::Sampled,
        SCHEME,
        options(6.0),
    )
    .unwrap();
    assert!(w.trajectory.len() > 100);
    let f = w.figures();
    assert!(f.contacts > 0 && f.distance.is_finite());
}

#[test]
fn the_sampled_controller_reads_the_heading_in_the_base_chart() {
    use mbs::charts::{array, joint_rotation, quaternion_near, zyx, zyx_angles_of};
    use mbs::{Controller, Model, State};
    let walker = Walker::new(GaitParams::new(Gait::Tripod, 0.15));
    let n = HexapodWalker::NQ;
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    walker.initial_state(&mut q, &mut qd).unwrap();
    q[3] = 0.3; // off its planned heading: the controller turns it back
    let state = |q: &[f64]| State {
        t: 1.0,
        q: q.to_vec(),
        qd: qd.clone(),
        qdd: vec![0.0; n],
        lambda: Vec::new(),
    };
    // the same pose read in a chart tilted as after a re-centring
    let joint = HexapodWalker::default().info().rotation_joints[0];
    let chart = zyx([0.6, 1.0, -0.3]);
    let r = joint_rotation(&array(&chart.transpose()), &joint, &q);
    let mut tilted = q.clone();
    for (k, a) in zyx_angles_of(quaternion_near(&r, None))
        .into_iter()
        .enumerate()
    {
        tilted[joint.angles[k]] = a;
    }
    let start = array(&zyx([0.0; 3]));
    let volts = |q: &[f64], chart: Option<[[f64; 3]; 3]>| {
        let mut c = walker.sampled(1e-3, VoltageLog::default());
        let mut u = [0.0; 18];
        match chart {
            Some(chart) => c.sample_in_charts(1.0, &state(q), &[chart], &mut u),
            None => c.sample(1.0, &state(q), &mut u),
        }
        u
    };
    let (plain, read) = (volts(&q, Some(start)), volts(&tilted, Some(array(&chart))));
    let blind = volts(&tilted, None);
    let apart = |a: [f64; 18], b: [f64; 18]| {
        a.iter()
            .zip(&b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
    };
    println!(
        "voltages: read in the tilted chart {:.1e} V from the start's, q[3] taken as the heading {:.2} V",
        apart(plain, read),
        apart(plain, blind)
    );
    assert!(apart(plain, read) < 1e-9);
    assert!(apart(plain, blind) > 0.1);
}
