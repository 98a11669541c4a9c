//! Inputs driven by time functions and sampled controllers ([`mbs::Inputs`]): a PI speed
//! controller sampled every 10 ms brings a damped rotor to its set-point, the integrators
//! stop exactly at every sample instant, and a time function drives a mass as the exact
//! solution says.

use mbs::{Inputs, Options, Output, Scheme, State, simulate_with};
use std::cell::RefCell;
use std::rc::Rc;

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
