//! Inputs driven by time functions and sampled controllers ([`mbs::Inputs`]): a PI speed
//! controller sampled every 10 ms brings a damped rotor to its set-point, the integrators
//! stop exactly at every sample instant, and a time function drives a mass as the exact
//! solution says.

use mbs::{Inputs, Options, Output, Scheme, State, simulate_with};
use std::cell::RefCell;
use std::rc::Rc;

#[path = "common/quoted.rs"]
mod quoted;

mbs::multibody! {
    /// A rotor (J = 0.01 kg m²) with viscous friction 0.02 N m s, driven by the torque u[0].
    model Rotor {
        dof phi = 0.0; input torque;
        body wheel { mass = 1.0; inertia = (0.01, 0.01, 0.01); }
        TOG[wheel] = Trotz(phi);
        generalized_force(phi, u[0] - 0.02 * qd[0]);
    }
}

mbs::multibody! {
    /// A unit mass pushed by u[0].
    model Pushed {
        dof x = 0.0; input push;
        body block { mass = 1.0; }
        TOG[block] = Tdisp(x, 0, 0);
        generalized_force(x, u[0]);
    }
}

/// A PI speed controller: u = Kp e + Ki ∫e, e = ω_ref − ω, the integral by the rectangle rule
/// over the sample period; records its sample times.
fn pi(period: f64, times: Rc<RefCell<Vec<f64>>>) -> impl FnMut(f64, &State, &mut [f64]) {
    let (kp, ki, w_ref) = (0.5, 2.0, 10.0);
    let mut integral = 0.0;
    move |t, s, u| {
        let e = w_ref - s.qd[0];
        integral += e * period;
        u[0] = kp * e + ki * integral;
        times.borrow_mut().push(t);
    }
}

#[test]
fn pi_controller_reaches_its_set_point_at_exact_sample_instants() {
    let period = 0.01;
    for scheme in [
        Scheme::Dopri5,
        Scheme::Rk4,
        Scheme::from_name("gen-alpha").unwrap(),
        Scheme::from_name("bdf").unwrap(),
        Scheme::Radau5,
    ] {
        let times = Rc::new(RefCell::new(Vec::new()));
        let o = if scheme.is_adaptive() {
            Options::adaptive(5.0, 1e-8)
        } else {
            Options::fixed(5.0, 2e-3)
        };
        let o = Options {
            output: Output::Steps,
            ..o
        };
        let inputs = Inputs::new().controller(period, pi(period, times.clone()));
        let (tr, st) = simulate_with(Rotor::default(), scheme, o, inputs).unwrap();
        let times = times.borrow();
        // sampled at t0 and at every k·T up to the end
        assert_eq!(times.len(), 501, "{}", scheme.name());
        for (k, &t) in times.iter().enumerate() {
            assert_eq!(t, k as f64 * period, "{}: sample {k}", scheme.name());
            // a step ends exactly there
            assert!(tr.t.contains(&t), "{}: no step ends at {t}", scheme.name());
        }
        assert_eq!(st.samples, 501);
        let w = tr.qd(tr.len() - 1)[0];
        println!(
            "{:>10}: ω(5) = {w:.9} rad/s, {} steps, {} samples",
            scheme.name(),
            st.steps,
            st.samples
        );
        assert!((w - 10.0).abs() < 1e-4, "{}: ω = {w}", scheme.name());
    }
}

#[test]
fn a_time_function_drives_the_inputs() {
    // x'' = sin t from rest: x = t − sin t
    for scheme in [
        Scheme::Dopri5,
        Scheme::Radau5,
        Scheme::from_name("newmark").unwrap(),
    ] {
        let o = if scheme.is_adaptive() {
            Options::adaptive(3.0, 1e-10)
        } else {
            Options::fixed(3.0, 1e-3)
        };
        let o = Options {
            output: Output::Last,
            ..o
        };
        let inputs = Inputs::new().function(|t, u| u[0] = t.sin());
        let (tr, _) = simulate_with(Pushed::default(), scheme, o, inputs).unwrap();
        let e = (tr.q(0)[0] - (3.0 - 3f64.sin())).abs();
        println!("{:>10}: |Δx(3)| {e:.1e}", scheme.name());
        assert!(e < 1e-6, "{}", scheme.name());
    }
}

#[test]
fn inputs_on_a_model_without_inputs_are_refused() {
    mbs::multibody! {
        model Free {
            dof x = 0.0;
            body b { mass = 1.0; }
            TOG[b] = Tdisp(x, 0, 0);
        }
    }
    let inputs = Inputs::new().function(|_, _| {});
    let e = simulate_with(
        Free::default(),
        Scheme::Rk4,
        Options::fixed(1.0, 0.1),
        inputs,
    )
    .unwrap_err();
    assert!(
        matches!(e.kind, mbs::Failure::InvalidOption { name: "inputs", .. }),
        "{e}"
    );
    let bad = Inputs::new().controller(0.0, |_: f64, _: &State, _: &mut [f64]| {});
    let e = simulate_with(
        Pushed::default(),
        Scheme::Rk4,
        Options::fixed(1.0, 0.1),
        bad,
    )
    .unwrap_err();
    assert!(matches!(
        e.kind,
        mbs::Failure::InvalidOption {
            name: "controller period",
            ..
        }
    ));
}

use mbs_models::dc_motor;

/// The DC-motor arm of `examples/dc_motor.rs`: the PI controller (sampled at 1 kHz) brings the
/// arm to 20 rad/s; the current (an extra state) settles to the friction torque's share.
#[test]
fn dc_motor_reaches_its_speed_set_point() {
    let period = 1e-3;
    for scheme in [
        Scheme::Radau5,
        Scheme::from_name("bdf").unwrap(),
        Scheme::Dopri5,
    ] {
        let model = mbs::WithEfforts::new(dc_motor::Arm::default(), dc_motor::Motor::default());
        let inputs = Inputs::new().controller(period, dc_motor::PiSpeed::new(20.0, period));
        let o = Options {
            output: Output::Last,
            ..Options::adaptive(1.5, 1e-8)
        };
        let (tr, st) = simulate_with(model, scheme, o, inputs).unwrap();
        let (w, i) = (tr.qd(0)[0], tr.qd(0)[1]);
        // at steady speed the motor torque N k i balances the friction 0.01 ω
        let i_steady = 0.01 * 20.0 / (10.0 * 0.05);
        println!(
            "{:>8}: ω(1.5) = {w:.6}, i = {i:.6} A (steady {i_steady}), {} steps, {} samples",
            scheme.name(),
            st.steps,
            st.samples
        );
        assert!((w - 20.0).abs() < 1e-4, "{}: ω = {w}", scheme.name());
        assert!((i - i_steady).abs() < 1e-3, "{}: i = {i}", scheme.name());
        assert_eq!(st.samples, 1501);
    }
}

mbs::multibody! {
    /// A brick (three unequal inertias) on a spherical joint without gravity, pitching at
    /// 3 rad/s from rest: its ZYX pitch passes 60° within half a second and the runtime
    /// re-centres its chart. An input torque about world z, held at zero.
    model Brick {
        dof a = 0.0;
        dof b = 0.0, qd = 3.0;
        dof c = 0.0, qd = 0.5;
        input torque;
        body brick { mass = 1.0; inertia = (0.1, 0.2, 0.3); }
        TOG[brick] = Tball(a, b, c);
        torque(brick, axis = z, u[0]);
    }
}

/// At a sample: its time, the brick's ZYX angles read in the charts, and the angles in q.
type Seen = (f64, [f64; 3], [f64; 3]);

/// Records, at every sample, the brick's ZYX angles read in the charts it is handed, and
/// the angles in q.
struct Attitude {
    seen: Rc<RefCell<Vec<Seen>>>,
}

impl mbs::Controller for Attitude {
    fn sample(&mut self, _: f64, _: &State, _: &mut [f64]) {
        panic!("a controller that takes the charts is handed them");
    }

    fn sample_in_charts(&mut self, t: f64, s: &State, charts: &[[[f64; 3]; 3]], u: &mut [f64]) {
        use mbs::Model;
        use mbs::charts::{joint_rotation, quaternion_near, zyx_angles_of};
        let joint = &Brick::default().info().rotation_joints[0];
        let r = joint_rotation(&charts[0], joint, &s.q);
        let world = zyx_angles_of(quaternion_near(&r, None));
        self.seen
            .borrow_mut()
            .push((t, world, [s.q[0], s.q[1], s.q[2]]));
        u[0] = 0.0;
    }
}

#[test]
fn a_controller_reads_a_rotation_in_the_charts_it_is_handed() {
    use std::f64::consts::PI;
    let seen = Rc::new(RefCell::new(Vec::new()));
    let inputs = Inputs::new().controller(0.01, Attitude { seen: seen.clone() });
    let options = Options {
        output: Output::Every { dt: 0.01 },
        ..Options::adaptive(2.0, 1e-10)
    };
    let (tr, st) = simulate_with(Brick::default(), Scheme::Dopri5, options, inputs).unwrap();
    assert!(st.chart_switches >= 1, "{}", st.chart_switches);
    let (mut worst, mut moved, mut compared) = (0.0f64, 0.0f64, 0);
    for (t, world, in_q) in seen.borrow().iter() {
        let Some(i) = (0..tr.len()).find(|&i| (tr.t[i] - t).abs() < 1e-9) else {
            continue;
        };
        let o = tr.orientation(i);
        let recorded = mbs::charts::zyx_angles_of([o[0], o[1], o[2], o[3]]);
        let apart = |x: f64, y: f64| (x - y + PI).rem_euclid(2.0 * PI) - PI;
        for k in 0..3 {
            worst = worst.max(apart(world[k], recorded[k]).abs());
            moved = moved.max(apart(in_q[k], recorded[k]).abs());
        }
        compared += 1;
    }
    println!(
        "{compared} samples, {} re-centrings: the angles read in the charts within {worst:.1e} rad of the recorded orientation's, q's up to {moved:.2} rad from them",
        st.chart_switches
    );
    assert!(compared > 150, "{compared}");
    assert!(worst < 1e-9, "{worst:e}");
    // the test would not see a controller that read q alone
    assert!(moved > 0.5, "{moved}");
    let read = if worst == 0.0 {
        "equal to".to_string()
    } else {
        format!("within {worst:.1e} rad of")
    };
    quoted::says(
        "README.md",
        &[format!(
            "a tumbling brick re-centred {} times, its angles so read by a controller {read} the \
             recorded orientation's at all {compared} samples",
            st.chart_switches
        )],
    );
}

/// Efforts that read the brick's rotation from q in the chart they are handed and compare it
/// with its frame's pose; they apply nothing.
#[derive(Clone)]
struct ReadsCharts {
    worst: Rc<RefCell<f64>>,
}

impl mbs::Efforts for ReadsCharts {
    fn efforts(&mut self, e: &mut mbs::Effort) -> Result<(), String> {
        use mbs::Model;
        let joint = &Brick::default().info().rotation_joints[0];
        let r = mbs::charts::joint_rotation(&e.chart(0), joint, e.q).to_rotation_matrix();
        let pose = e.frame(0).pose.rotation;
        let mut worst = self.worst.borrow_mut();
        for i in 0..3 {
            for k in 0..3 {
                *worst = worst.max((r[(i, k)] - pose[i][k]).abs());
            }
        }
        Ok(())
    }
}

#[test]
fn efforts_read_a_rotation_in_the_charts_they_are_handed() {
    let worst = Rc::new(RefCell::new(0.0));
    let model = mbs::WithEfforts::new(
        Brick::default(),
        ReadsCharts {
            worst: worst.clone(),
        },
    );
    let (_, st) = mbs::simulate(model, Scheme::Dopri5, Options::adaptive(2.0, 1e-10)).unwrap();
    let worst = *worst.borrow();
    println!(
        "{} re-centrings: the rotation read in the charts within {worst:.1e} of the frame's pose",
        st.chart_switches
    );
    assert!(st.chart_switches >= 1);
    assert!(worst < 1e-12, "{worst:e}");
    quoted::says(
        "README.md",
        &[format!(
            "and its rotation so read by efforts within {worst:.1e} of its frame's pose"
        )],
    );
}

#[test]
fn a_row_at_a_sample_time_holds_the_new_inputs() {
    // x'' = u, u = 1 − x sampled every 0.1 s: every row's qdd is the input of the latest
    // sample at or before its time, as at the start (inputs hold from their sample on)
    for (scheme, output) in [
        (Scheme::Dopri5, Output::Steps),
        (Scheme::Dopri5, Output::Every { dt: 0.05 }),
        (Scheme::Rk4, Output::Every { dt: 0.05 }),
        (Scheme::Radau5, Output::Steps),
    ] {
        let samples = Rc::new(RefCell::new(Vec::new()));
        let record = samples.clone();
        let controller = move |t: f64, s: &State, u: &mut [f64]| {
            u[0] = 1.0 - s.q[0];
            record.borrow_mut().push((t, u[0]));
        };
        let o = if scheme.is_adaptive() {
            Options::adaptive(1.0, 1e-8)
        } else {
            Options::fixed(1.0, 1e-2)
        };
        let o = Options {
            output: output.clone(),
            ..o
        };
        let inputs = Inputs::new().controller(0.1, controller);
        let (tr, _) = simulate_with(Pushed::default(), scheme, o, inputs).unwrap();
        let samples = samples.borrow();
        for i in 0..tr.len() {
            let t = tr.t[i];
            let held = samples.iter().rev().find(|(ts, _)| *ts <= t).unwrap().1;
            let qdd = tr.qdd(i)[0];
            assert!(
                (qdd - held).abs() < 1e-12,
                "{} {output:?}: qdd {qdd} at t = {t}, the input held there {held}",
                scheme.name()
            );
        }
    }
}

#[test]
fn a_controller_period_below_the_resolution_of_time_is_refused() {
    // at t = 1e6 a period of 1e-11 s does not move t: the run took steps of zero length
    let o = Options {
        t0: 1e6,
        ..Options::fixed(1e6 + 1e-3, 1e-4)
    };
    let inputs = Inputs::new().controller(1e-11, |_: f64, _: &State, u: &mut [f64]| u[0] = 1.0);
    let e = simulate_with(Pushed::default(), Scheme::Rk4, o, inputs).unwrap_err();
    assert!(
        matches!(
            e.kind,
            mbs::Failure::InvalidOption {
                name: "controller period",
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("resolution of time"), "{e}");
}

mbs::multibody! {
    /// A unit mass on a spring of 10 N/m, pushed by u[0], released 0.1 m out.
    model SprungBlock {
        dof x = 0.1; input push;
        body block { mass = 1.0; }
        TOG[block] = Tdisp(x, 0, 0);
        generalized_force(x, -10 * x + u[0]);
    }
}

#[test]
fn a_controller_sees_the_start_s_accelerations() {
    // at t0 the state handed to a controller has the spring's −1 m/s² (it had qdd = 0), as
    // a later sample sees the accelerations under the inputs held before it
    let seen = Rc::new(RefCell::new(Vec::new()));
    let record = seen.clone();
    let controller = move |t: f64, s: &State, u: &mut [f64]| {
        record.borrow_mut().push((t, s.q[0], s.qdd[0], u[0]));
        u[0] = 0.5;
    };
    let inputs = Inputs::new().controller(0.1, controller);
    simulate_with(
        SprungBlock::default(),
        Scheme::Rk4,
        Options::fixed(0.3, 1e-3),
        inputs,
    )
    .unwrap();
    let seen = seen.borrow();
    for &(t, x, qdd, held) in seen.iter() {
        assert!(
            (qdd - (-10.0 * x + held)).abs() < 1e-12,
            "at t = {t}: qdd {qdd}, x {x}, held u {held}"
        );
    }
    assert_eq!(seen[0].2, -1.0);
}

/// A run records the inputs in force at every output (a time function plus a sampled
/// controller), and inverse dynamics along it reads them: the motion needed no effort beyond
/// them; under inputs held at zero it needed exactly them as τ, and a motion that records none
/// must be given its inputs.
#[test]
fn a_run_records_its_inputs_and_inverse_dynamics_reads_them() {
    use mbs::Model;
    use mbs::analysis::{inverse_dynamics_actuated_of, inverse_dynamics_of};
    let period = 0.01;
    let wave = |t: f64| 0.05 * (7.0 * t).sin();
    // the largest |τ| beyond the recorded inputs over the schemes
    let mut beyond = 0.0f64;
    for scheme in [Scheme::Dopri5, Scheme::Radau5] {
        // the PI controller's outputs, as it wrote them
        let held = Rc::new(RefCell::new(Vec::new()));
        let record = held.clone();
        let mut pi = pi(period, Rc::new(RefCell::new(Vec::new())));
        let controller = move |t: f64, s: &State, u: &mut [f64]| {
            pi(t, s, u);
            record.borrow_mut().push((t, u[0]));
        };
        let inputs = Inputs::new()
            .function(move |t, u| u[0] = wave(t))
            .controller(period, controller);
        let o = Options {
            output: Output::Steps,
            ..Options::adaptive(0.5, 1e-8)
        };
        let (tr, _) = simulate_with(Rotor::default(), scheme, o, inputs).unwrap();
        assert_eq!(tr.input_names, Rotor::default().info().inputs);
        assert_eq!(tr.u_data.len(), tr.len());
        let samples = held.borrow();
        let mut largest = 0.0f64;
        for i in 0..tr.len() {
            let t = tr.t[i];
            let h = samples.iter().rev().find(|(ts, _)| *ts <= t).unwrap().1;
            let u = tr.u(i)[0];
            assert!((u - (h + wave(t))).abs() < 1e-15, "u = {u} at t = {t}");
            largest = largest.max(u.abs());
        }
        let model = Rotor::default();
        let along = inverse_dynamics_of(&model, &tr, &[]).unwrap();
        let unforced = inverse_dynamics_of(&model, &tr, &[0.0]).unwrap();
        let actuated = inverse_dynamics_actuated_of(&model, &tr, &[], &[0]).unwrap();
        let mut worst = [0.0f64; 3];
        for i in 0..tr.len() {
            worst[0] = worst[0].max(along.at(i)[0].abs());
            worst[1] = worst[1].max((unforced.at(i)[0] - tr.u(i)[0]).abs());
            worst[2] = worst[2].max((actuated.tau[i] - along.at(i)[0]).abs());
        }
        println!(
            "{}: {} outputs, |u| up to {largest:.3} N m; |τ| beyond the recorded inputs {:.1e}, τ − u under u = 0 {:.1e}",
            scheme.name(),
            tr.len(),
            worst[0],
            worst[1]
        );
        assert!(worst[0] < 1e-12 * largest, "{}: {worst:?}", scheme.name());
        assert!(worst[1] < 1e-12 * largest, "{}: {worst:?}", scheme.name());
        assert!(worst[2] < 1e-12 * largest, "{}: {worst:?}", scheme.name());
        beyond = beyond.max(worst[0]);
        // the columns of the CSV
        let mut csv = Vec::new();
        tr.write_csv(&mut csv).unwrap();
        let header = String::from_utf8(csv).unwrap();
        let header = header.lines().next().unwrap();
        assert!(
            header.split(',').any(|c| c == tr.input_names[0]),
            "{header}"
        );
    }
    quoted::says(
        "README.md",
        &[format!(
            "on a rotor under a PI controller and a time function, {beyond:.1e} N·m at most, where \
             inputs held at zero give τ = u"
        )],
    );
    // a measured motion records no inputs: they must be given
    let measured = mbs::Trajectory {
        dof_names: vec!["phi".into()],
        t: vec![0.0],
        q_data: vec![0.0],
        qd_data: vec![0.0],
        qdd_data: vec![0.0],
        ..Default::default()
    };
    let e = inverse_dynamics_of(&Rotor::default(), &measured, &[]).unwrap_err();
    assert!(e.to_string().contains("u"), "{e}");
    assert!(inverse_dynamics_of(&Rotor::default(), &measured, &[0.3]).is_ok());
}

/// A sample that fails (its controller writes a non-finite input) ends the run with the
/// accepted state's row as the step made it: its qdd and its recorded input those of the
/// sample before, not the failed one's.
#[test]
fn a_failed_sample_leaves_the_row_and_the_inputs_of_the_step() {
    let controller = move |t: f64, s: &State, u: &mut [f64]| {
        u[0] = if t < 0.25 { 1.0 - s.q[0] } else { f64::NAN };
    };
    let o = Options {
        output: Output::Steps,
        ..Options::adaptive(1.0, 1e-8)
    };
    let inputs = Inputs::new().controller(0.1, controller);
    let e = simulate_with(Pushed::default(), Scheme::Dopri5, o, inputs).unwrap_err();
    let tr = &e.trajectory;
    let last = tr.len() - 1;
    assert!(
        (tr.t[last] - 0.3).abs() < 1e-12,
        "{e}: ends at {}",
        tr.t[last]
    );
    let (u, qdd) = (tr.u(last)[0], tr.qdd(last)[0]);
    assert!(u.is_finite() && (u - qdd).abs() < 1e-12, "u {u}, qdd {qdd}");
}
