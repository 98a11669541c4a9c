//! Efforts written in Rust and extra first-order states ([`mbs::WithEfforts`]): the same
//! force through the hook and in the DSL gives the same motion; extra states follow their
//! exact solution with every scheme; the wrapper's tangents match differences of its τ; a
//! failing user effort stops every scheme with its typed error and a trajectory free of NaN (and
//! an analysis with it; one before a run does not stop the run); a rejected trial state is
//! retried with a smaller step.

use mbs::{Effort, Efforts, Failure, Model, Options, Output, Scheme, Stats, WithEfforts, simulate};

#[path = "common/quoted.rs"]
mod quoted;

mbs::multibody! {
    /// A double pendulum with a damper between the bars and a horizontal push at the tip,
    /// both in the DSL (scene `Full`) or left out (scene `Bare`) for the hook to add.
    model Dp {
        param c = 0.3; param push = 2.0;
        dof q[0] = 0.6; dof q[1] = -0.3, qd = 1.0;
        option tangents;
        body bar1 { mass = 1.0; inertia = (1.0 / 12.0, 0, 1.0 / 12.0); }
        body bar2 { mass = 1.0; inertia = (1.0 / 12.0, 0, 1.0 / 12.0); }
        point tip on bar2 at (0, -0.5, 0);
        TOG[bar1] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -0.5, 0) * Trotz(q[1]) * Tdisp(0, -0.5, 0);
        gravity(0, -9.81, 0);
        effect extra {
            torque(bar2, relative_to = bar1, axis = z, -c * qd[1]);
            force(tip, (push * cos(t), 0, 0));
        }
        scene Bare = []; scene Full = [extra];
    }
}

/// The DSL's `extra` effect written in Rust.
#[derive(Clone)]
struct Extra {
    bar1: usize,
    bar2: usize,
    tip: usize,
    c: f64,
    push: f64,
}

impl Extra {
    fn new(info: &mbs::ModelInfo) -> Extra {
        Extra {
            bar1: info.frame_index("bar1").expect("bar1"),
            bar2: info.frame_index("bar2").expect("bar2"),
            tip: info.point_index("tip").expect("tip"),
            c: 0.3,
            push: 2.0,
        }
    }
}

impl Efforts for Extra {
    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        // the damper's torque on bar2 about z, the reaction on bar1
        let tau = -self.c * e.qd[1];
        e.torque_on_frame(self.bar2, [0.0, 0.0, tau]);
        e.torque_on_frame(self.bar1, [0.0, 0.0, -tau]);
        e.force_at_point(self.tip, [self.push * e.t.cos(), 0.0, 0.0]);
        Ok(())
    }
}

fn hooked() -> WithEfforts<DpBare, Extra> {
    let bare = DpBare::default();
    let extra = Extra::new(bare.info());
    WithEfforts::new(bare, extra)
}

#[test]
fn hook_and_dsl_give_the_same_motion() {
    // fixed steps for the implicit schemes, with Newton to a tight tolerance: the two models
    // have the same equations but not the same iteration matrices (generated tangents against
    // differences of the hook), so Newton stops at different points within its tolerance, and
    // an adaptive scheme's discrete choices (BDF's order) can then differ: 1e-7 apart
    let newton = mbs::NewtonOptions {
        tolerance_factor: 1e-5,
        atol: 1e-14,
        rtol: 1e-14,
        max_iterations: 12,
        ..Default::default()
    };
    for (scheme, step) in [
        (Scheme::Dopri5, Options::adaptive(3.0, 1e-8).step),
        (Scheme::Rk4, Options::fixed(3.0, 1e-3).step),
        (
            Scheme::from_name("gen-alpha").unwrap(),
            Options::fixed(3.0, 1e-3).step,
        ),
        (Scheme::Radau5, Options::fixed(3.0, 1e-2).step),
        (
            Scheme::from_name("bdf").unwrap(),
            Options::fixed(3.0, 1e-3).step,
        ),
    ] {
        let o = || Options {
            t_end: 3.0,
            step,
            output: Output::Every { dt: 0.05 },
            newton,
            ..Options::default()
        };
        let (a, sa) = simulate(DpFull::default(), scheme, o()).unwrap();
        let (b, sb) = simulate(hooked(), scheme, o()).unwrap();
        let d = (0..a.len())
            .flat_map(|i| (0..2).map(move |k| (i, k)))
            .map(|(i, k)| {
                (a.q(i)[k] - b.q(i)[k])
                    .abs()
                    .max((a.qd(i)[k] - b.qd(i)[k]).abs())
            })
            .fold(0.0, f64::max);
        println!(
            "{:>10}: max |Δ| {d:.1e}; DSL {} steps, hook {} steps, {} user evaluations",
            scheme.name(),
            sa.steps,
            sb.steps,
            sb.user_efforts
        );
        assert_eq!(a.len(), b.len());
        assert!(d < 1e-10, "{}: {d:e}", scheme.name());
        assert!(sb.user_efforts > 0 && sa.user_efforts == 0);
    }
}

/// τ of the wrapper at a state, for differences.
fn tau<M: Model>(m: &M, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let mut t = vec![0.0; M::NQ];
    m.inverse_dynamics(0.7, q, qd, qdd, &[], &mut t);
    t
}

#[test]
fn tangents_of_the_hooked_model_match_differences() {
    let worst = tangents_gap(&hooked(), &[0.3, -0.8], &[1.1, -0.6], &[0.2, 0.5]);
    println!("tangents vs central differences: {worst:.1e}");
    assert!(worst < 1e-6);
}

/// The largest gap between a model's tangents at (q, qd, qdd) and central differences of
/// its τ.
fn tangents_gap<M: Model>(m: &M, q: &[f64], qd: &[f64], qdd: &[f64]) -> f64 {
    let n = M::NQ;
    let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
    m.tangents(0.7, q, qd, qdd, &[], &mut k, &mut c).unwrap();
    let eps = 1e-6;
    let mut worst = 0.0f64;
    for j in 0..n {
        for (which, exact) in [(0, &k), (1, &c)] {
            let (mut a, mut b) = ((q.to_vec(), qd.to_vec()), (q.to_vec(), qd.to_vec()));
            if which == 0 {
                a.0[j] += eps;
                b.0[j] -= eps;
            } else {
                a.1[j] += eps;
                b.1[j] -= eps;
            }
            let (ta, tb) = (tau(m, &a.0, &a.1, qdd), tau(m, &b.0, &b.1, qdd));
            for i in 0..n {
                let cd = (ta[i] - tb[i]) / (2.0 * eps);
                worst = worst.max((exact[i + n * j] - cd).abs());
            }
        }
    }
    worst
}

/// The five buffers of three numbers the differences use.
fn buffers(w: &mut [[f64; 3]; 5]) -> mbs::DifferenceBuffers<'_> {
    let [tau0, tau1, qp, vp, ap] = w;
    mbs::DifferenceBuffers {
        tau0,
        tau1,
        qp,
        vp,
        ap,
    }
}

/// The push at the tip through a first-order lag, ẋ = (push·cos t − x)/T, and the damper
/// between the bars: efforts that read q, qd and an extra state.
struct Lagged(Extra);

impl Efforts for Lagged {
    const NX: usize = 1;
    const STATE_NAMES: &'static [&'static str] = &["push"];
    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        let Extra {
            bar1, bar2, tip, c, ..
        } = self.0;
        let tau = -c * e.qd[1] * e.q[0].cos();
        e.torque_on_frame(bar2, [0.0, 0.0, tau]);
        e.torque_on_frame(bar1, [0.0, 0.0, -tau]);
        e.force_at_point(tip, [e.x[0], 0.0, 0.0]);
        Ok(())
    }
    fn state_derivatives(&mut self, e: &Effort, xd: &mut [f64]) -> Result<(), String> {
        xd[0] = (self.0.push * e.t.cos() - e.x[0] * (1.0 + e.q[1] * e.q[1])) / 0.2;
        Ok(())
    }
}

/// With extra states, the wrapper's differenced tangents are the default's differences of
/// its τ to the bit, with fewer evaluations: none for the states' integrals (nothing reads
/// them) and the user part alone for the states; its tangents (the wrapped model's exact
/// ones, the user part differenced) match central differences.
#[test]
fn the_wrappers_differences_skip_what_no_state_reads() {
    let bare = DpBare::default();
    let extra = Lagged(Extra::new(bare.info()));
    let m = WithEfforts::new(bare, extra);
    let (q, qd, qdd) = ([0.3, -0.8, 0.0], [1.1, -0.6, 0.4], [0.2, 0.5, -0.3]);
    let mut work = [[0.0; 3]; 5];
    let state = [&q[..], &qd[..], &qdd[..]];
    let (mut k0, mut c0, mut k1, mut c1) = ([0.0; 9], [0.0; 9], [0.0; 9], [0.0; 9]);
    let before = m.user_evaluations();
    let all =
        mbs::differenced_tangents(&m, 0.7, state, &[], [&mut k0, &mut c0], buffers(&mut work));
    let middle = m.user_evaluations();
    let wrapped = m.differenced_tangents(0.7, state, &[], [&mut k1, &mut c1], buffers(&mut work));
    let after = m.user_evaluations();
    let bits = |x: &[f64; 9]| x.map(f64::to_bits);
    assert_eq!(bits(&k0), bits(&k1));
    assert_eq!(bits(&c0), bits(&c1));
    // 2·3 + 1 evaluations of τ and of the user part; 2·2 + 1 of the wrapped model and
    // 2·2 + 1 + 1 of the user part
    assert_eq!((all, middle - before), (7, 7));
    assert_eq!((wrapped, after - middle), (5, 6));
    // the extra state drives the tip and its own rate, and its integral nothing
    assert!(c1[2 * 3] != 0.0 && c1[2 * 3 + 2] != 0.0 && k1[6..] == [0.0; 3]);
    // the iteration matrix M + γ'C + β'K alike: 3 + 1 evaluations of τ and of the user part
    // by default; 2 + 1 of the wrapped model's and 3 + 1 of the user part's
    let (mut a0, mut a1) = ([0.0; 9], [0.0; 9]);
    let w = [0.25 * 0.01, 0.5 * 0.1];
    let all =
        mbs::differenced_iteration_matrix(&m, 0.7, state, &[], w, &mut a0, buffers(&mut work));
    let middle = m.user_evaluations();
    let wrapped = m.differenced_iteration_matrix(0.7, state, &[], w, &mut a1, buffers(&mut work));
    let last = m.user_evaluations();
    assert_eq!(a0.map(f64::to_bits), a1.map(f64::to_bits));
    assert_eq!((all, middle - after), (4, 4));
    assert_eq!((wrapped, last - middle), (3, 4));

    let worst = tangents_gap(&m, &q, &qd, &qdd);
    println!("tangents with an extra state vs central differences: {worst:.1e}");
    assert!(worst < 1e-6);
}

/// A unit mass pushed by a force x that decays by ẋ = −x/T: y(t) = x₀T²(e^(−t/T) − 1 + t/T).
struct Decaying {
    body: usize,
}

impl Efforts for Decaying {
    const NX: usize = 1;
    const STATE_NAMES: &'static [&'static str] = &["force"];
    fn initial_states(&self, x: &mut [f64]) {
        x[0] = 2.0;
    }
    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        let at = e.frame(self.body).pose.position;
        e.force_on_frame(self.body, at, [e.x[0], 0.0, 0.0]);
        Ok(())
    }
    fn state_derivatives(&mut self, e: &Effort, xd: &mut [f64]) -> Result<(), String> {
        xd[0] = -e.x[0] / 0.5;
        Ok(())
    }
}

mbs::multibody! {
    model Slider {
        dof y = 0.0;
        body block { mass = 1.0; }
        TOG[block] = Tdisp(y, 0, 0);
    }
}

#[test]
fn extra_states_follow_their_exact_solution() {
    let exact = |t: f64| {
        let (x0, tt) = (2.0, 0.5);
        x0 * tt * tt * ((-t / tt).exp() - 1.0 + t / tt)
    };
    let model = || {
        let s = Slider::default();
        let body = s.info().frame_index("block").unwrap();
        WithEfforts::new(s, Decaying { body })
    };
    assert_eq!(model().info().dofs, ["y", "x:force"]);
    for (scheme, o, tol) in [
        (Scheme::Dopri5, Options::adaptive(2.0, 1e-10), 1e-8),
        (Scheme::Radau5, Options::adaptive(2.0, 1e-10), 1e-8),
        (
            Scheme::from_name("gen-alpha").unwrap(),
            Options::fixed(2.0, 1e-3),
            1e-5,
        ),
        (
            Scheme::from_name("newmark").unwrap(),
            Options::fixed(2.0, 1e-3),
            1e-6,
        ),
        (Scheme::Rk4, Options::fixed(2.0, 1e-2), 1e-8),
    ] {
        let (tr, st): (_, Stats) = simulate(model(), scheme, o).unwrap();
        let k = tr.len() - 1;
        let (y, x) = (tr.q(k)[0], tr.qd(k)[1]);
        let (ey, ex) = (
            (y - exact(2.0)).abs(),
            (x - 2.0 * (-2.0f64 / 0.5).exp()).abs(),
        );
        println!(
            "{:>10}: |Δy| {ey:.1e}, |Δx| {ex:.1e}, {} steps",
            scheme.name(),
            st.steps
        );
        assert!(ey < tol && ex < tol, "{}", scheme.name());
    }
}

/// A push that turns into NaN, or into an error, from t = 0.5 on.
struct Breaks {
    tip: usize,
    nan: bool,
}

impl Efforts for Breaks {
    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        if e.t >= 0.5 {
            if self.nan {
                e.force_at_point(self.tip, [f64::NAN, 0.0, 0.0]);
            } else {
                return Err("sensor lost at t ≥ 0.5".into());
            }
        }
        Ok(())
    }
}

#[test]
fn failing_user_efforts_stop_every_scheme_with_a_typed_error() {
    for nan in [true, false] {
        for scheme in Scheme::all() {
            let bare = DpBare::default();
            let tip = bare.info().point_index("tip").unwrap();
            let model = WithEfforts::new(bare, Breaks { tip, nan });
            let o = if scheme.is_adaptive() {
                Options::adaptive(1.0, 1e-6)
            } else {
                Options::fixed(1.0, 1e-3)
            };
            let e = simulate(model, scheme, o).expect_err("fails after 0.5");
            let tr = &e.trajectory;
            let clean = tr.q_data.iter().chain(&tr.qd_data).all(|x| x.is_finite());
            let ok = match &e.kind {
                Failure::NonFinite { quantity, .. } => nan && *quantity == "user effort",
                Failure::UserEffort { t, message } => {
                    !nan && *t >= 0.5 && message.contains("sensor")
                }
                _ => false,
            };
            assert!(ok, "{} (nan {nan}): {e}", scheme.name());
            assert!(clean, "{}: NaN in the trajectory", scheme.name());
            // stopped within one step of 0.5
            assert!(
                e.t <= 0.5 && e.t >= 0.5 - 0.05,
                "{}: stopped at {}",
                scheme.name(),
                e.t
            );
            assert!(tr.t.last().is_some_and(|&t| t <= 0.5));
        }
    }
}

/// A guard on the first bar's angle a little above the largest the motion reaches: the
/// trial states of large steps can overshoot it where the motion never goes.
#[derive(Clone)]
struct Guard {
    limit: f64,
    reject: bool,
}

impl Efforts for Guard {
    const FRAMES: bool = false;
    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        if e.q[0].abs() > self.limit {
            let m = format!("|q[0]| = {:.6} beyond {:.6}", e.q[0].abs(), self.limit);
            return Err(if self.reject { e.reject(m) } else { m });
        }
        Ok(())
    }
}

#[test]
fn rejected_trial_states_are_retried_smaller() {
    // the largest |q[0]| of the motion, sampled finely at tight tolerances
    let t_end = 3.0;
    let fine = Options {
        output: Output::Every { dt: 1e-3 },
        ..Options::adaptive(t_end, 1e-12)
    };
    let (tr, _) = simulate(DpBare::default(), Scheme::Dopri5, fine).unwrap();
    let reach = (0..tr.len()).map(|i| tr.q(i)[0].abs()).fold(0.0, f64::max);
    let guarded = |limit, reject| WithEfforts::new(DpBare::default(), Guard { limit, reject });
    // a guard 1e-6 above it: large steps' trial states overshoot it; a plain Err stops the
    // run there, a rejection retries the step smaller and the run goes on
    let limit = reach + 1e-6;
    // the earliest and latest stops of the plain Err, the fewest and most steps retried
    let (mut stops, mut retried) = ((f64::INFINITY, 0.0f64), (usize::MAX, 0));
    for (scheme, rtol) in [
        (Scheme::Dopri5, 1e-2),
        (Scheme::Dopri5, 1e-3),
        (Scheme::Radau5, 1e-3),
    ] {
        let name = format!("{} at rtol {rtol:e}", scheme.name());
        let hard = simulate(
            guarded(limit, false),
            scheme,
            Options::adaptive(t_end, rtol),
        )
        .expect_err("a trial state overshoots");
        assert!(
            matches!(hard.kind, Failure::UserEffort { .. }),
            "{name}: {hard}"
        );
        let (tr, stats) = simulate(guarded(limit, true), scheme, Options::adaptive(t_end, rtol))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        println!(
            "{name}: the Err guard stops at t = {:.4}; the rejecting guard runs to {t_end} s in {} steps, {} retried smaller",
            hard.t, stats.steps, stats.rejected_effort
        );
        assert!(stats.rejected_effort >= 1, "{name}");
        assert_eq!(tr.t.last(), Some(&t_end), "{name}");
        assert!((0..tr.len()).all(|i| tr.q(i)[0].abs() <= limit), "{name}");
        stops = (stops.0.min(hard.t), stops.1.max(hard.t));
        retried = (
            retried.0.min(stats.rejected_effort),
            retried.1.max(stats.rejected_effort),
        );
    }
    quoted::says(
        "README.md",
        &[format!(
            "stops DOPRI5 (rtol 1e-2, 1e-3) and Radau5 (rtol 1e-3) at t ≈ {:.1}–{:.1} s as a plain \
             `Err`; as a rejection they run to the end, retrying {}–{} steps",
            stops.0, stops.1, retried.0, retried.1
        )],
    );
    // a guard the motion itself crosses: the run stops with the typed failure where smaller
    // steps cannot avoid it, the trajectory until then kept
    let e = simulate(
        guarded(reach - 0.005, true),
        Scheme::Dopri5,
        Options::adaptive(t_end, 1e-6),
    )
    .expect_err("the motion crosses the guard");
    println!(
        "crossed, adaptive: {e}; {} retried smaller",
        e.stats.rejected_effort
    );
    assert!(matches!(e.kind, Failure::EffortRejected { .. }), "{e}");
    assert!(e.h < 1e-9 && e.t > 0.5 && e.t < t_end, "{e} (h {})", e.h);
    assert_eq!(e.trajectory.t.last(), Some(&e.t));
    // ... and at a fixed step at once
    let e = simulate(
        guarded(reach - 0.005, true),
        Scheme::Rk4,
        Options::fixed(t_end, 1e-3),
    )
    .expect_err("the motion crosses the guard");
    assert!(matches!(e.kind, Failure::EffortRejected { .. }), "{e}");
    assert_eq!(e.stats.rejected_effort, 0);
}

#[test]
fn a_user_failure_before_a_run_is_not_the_run_s() {
    // the caller evaluates the model where its efforts fail (as a statics' trial state
    // may), then runs it from a start where they do not: the run is not stopped at t0 by
    // the earlier failure
    let model = WithEfforts::new(
        DpBare::default(),
        Guard {
            limit: 1.0,
            reject: false,
        },
    );
    let (mut m, mut h) = ([0.0; 4], [0.0; 2]);
    model.dynamics(0.0, &[1.5, 0.0], &[0.0; 2], &[], &mut m, &mut h);
    let (tr, _) = simulate(model, Scheme::Dopri5, Options::adaptive(0.3, 1e-6))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(tr.t.last(), Some(&0.3));
}

#[test]
fn an_analysis_reports_the_user_s_failure() {
    // statics at a state where the efforts fail: the user's message, not a NaN it caused
    let model = WithEfforts::new(
        DpBare::default(),
        Guard {
            limit: 0.1,
            reject: false,
        },
    );
    let e = mbs::static_equilibrium(&model, &mbs::StaticsOptions::default())
        .expect_err("the efforts fail at the start");
    assert!(
        matches!(&e, mbs::AnalysisError::Failure(Failure::UserEffort { message, .. }) if message.contains("beyond")),
        "{e}"
    );
}

#[test]
fn a_linearisation_with_efforts_in_rust_is_not_called_exact() {
    // the wrapped model's tangents are generated, the efforts written in Rust differenced
    fn exact<M: Model + Clone>(model: &M) -> bool {
        let how = mbs::IterationMatrix::Auto;
        let lin = mbs::linearize(model, 0.0, &[0.2, 0.1], &[0.0; 2], &[], how);
        lin.unwrap().exact
    }
    let bare = DpBare::default();
    let extra = Extra::new(bare.info());
    assert!(exact(&DpFull::default()));
    assert!(!exact(&WithEfforts::new(bare, extra)));
}

mbs::multibody! {
    /// The DC motor's arm held by a torsion spring of 2 N·m/rad: one static equilibrium per
    /// voltage.
    model SprungArm {
        param l = 0.4; param m = 1.0; param ks = 2.0;
        dof theta = 0.0;
        input voltage;
        option tangents;
        body bar { mass = m; inertia = (0, m * l * l / 12, m * l * l / 12); }
        TOG[bar] = Trotz(theta) * Tdisp(l / 2, 0, 0);
        generalized_force(theta, -ks * theta - 0.01 * qd[0]);
    }
}

/// The equilibrium of `model` (an arm on the DC motor) at 1 V under either stiffness: its q
/// (the current last) and its one stiffness eigenvalue, the current settled.
fn motor_statics<M: mbs::Model + Clone + 'static>(model: M, q: &[f64], eigenvalue: f64) {
    use mbs_models::dc_motor::Motor;
    for how in [
        mbs::IterationMatrix::Auto,
        mbs::IterationMatrix::FiniteDifferences,
    ] {
        let model = WithEfforts::new(model.clone(), Motor::default());
        let options = mbs::StaticsOptions {
            u: Some(vec![1.0]),
            stiffness: how,
            ..Default::default()
        };
        let eq = mbs::static_equilibrium(&model, &options).unwrap_or_else(|e| panic!("{e}"));
        println!("{how:?}: {eq}");
        for (k, (&got, &want)) in eq.q.iter().zip(q).enumerate() {
            assert!((got - want).abs() < 1e-9, "{how:?}: q[{k}] = {got}");
        }
        assert_eq!(eq.stability, mbs::Stability::Stable, "{how:?}");
        assert_eq!(eq.stiffness_eigenvalues.len(), 1, "{how:?}");
        let e = eq.stiffness_eigenvalues[0];
        assert!((e - eigenvalue).abs() < 1e-6, "{how:?}: {e}");
    }
}

#[test]
fn statics_solves_for_the_extra_states() {
    // at 1 V the current settles at V/R = 1 A (no back-emf at rest), and the spring holds the
    // motor's torque N k i = 0.5 N·m at θ = 0.25 rad; its stiffness, the current settled
    motor_statics(SprungArm::default(), &[0.25, 1.0], 2.0);
}

/// The poles of `model` (an arm of inertia `j` on the DC motor, held by a spring of 2 N·m/rad)
/// linearised at its equilibrium at 1 V: those of the arm (J θ̈ = −ks θ − c θ̇ + N k i) and the
/// circuit (L i̇ = V − R i − k N θ̇); the current's integral, read by nothing, is no pole.
fn motor_poles<M: mbs::Model + Clone + 'static>(model: M, j: f64) {
    use mbs_models::dc_motor::Motor;
    let model = WithEfforts::new(model, Motor::default());
    let options = mbs::StaticsOptions {
        u: Some(vec![1.0]),
        ..Default::default()
    };
    let eq = mbs::static_equilibrium(&model, &options).unwrap();
    let n = eq.q.len();
    let mut qd = vec![0.0; n];
    qd[n - 1] = eq.q[n - 1];
    let lin = mbs::linearize(&model, 0.0, &eq.q, &qd, &[1.0], mbs::IterationMatrix::Auto).unwrap();
    assert_eq!(lin.first_order.len(), 1);
    let modes = mbs::modes(&lin, None).unwrap();
    println!("{modes}");
    let motor = Motor::default();
    let (ks, c, nk) = (2.0, 0.01, motor.gear * motor.k);
    let a = nalgebra::Matrix3::new(
        0.0,
        1.0,
        0.0, //
        -ks / j,
        -c / j,
        nk / j, //
        0.0,
        -nk / motor.l,
        -motor.r / motor.l,
    );
    let mut expected: Vec<(f64, f64)> = a
        .complex_eigenvalues()
        .iter()
        .filter(|l| l.im >= 0.0)
        .map(|l| (l.re, l.im))
        .collect();
    let mut got: Vec<(f64, f64)> = modes.modes.iter().map(|m| (m.re, m.im)).collect();
    let by_re = |a: &(f64, f64), b: &(f64, f64)| a.0.total_cmp(&b.0);
    expected.sort_by(by_re);
    got.sort_by(by_re);
    assert_eq!(got.len(), expected.len(), "{got:?} against {expected:?}");
    for (g, e) in got.iter().zip(&expected) {
        let size = e.0.hypot(e.1);
        assert!(
            (g.0 - e.0).hypot(g.1 - e.1) < 1e-6 * size,
            "{got:?} against {expected:?}"
        );
    }
}

#[test]
fn an_extra_state_adds_its_own_pole_and_no_zero_one() {
    motor_poles(SprungArm::default(), 0.4f64.powi(2) / 3.0);
}

#[test]
fn an_extra_state_of_a_closed_loop_adds_its_own_pole_and_no_zero_one() {
    // the arm and the disk turn together: J = m l²/3 + 1e-4
    motor_poles(SprungArmGeared::default(), 0.4f64.powi(2) / 3.0 + 1e-4);
}

mbs::multibody! {
    /// The sprung arm in two coordinates tied by a constraint: the motor turns `theta`, the
    /// spring (2 N·m/rad) holds `psi`, a light disk's angle, and `gear: psi − theta = 0`.
    model SprungArmGeared {
        param l = 0.4; param m = 1.0; param ks = 2.0;
        dof theta = 0.0; dof psi = 0.0;
        input voltage;
        option tangents;
        body bar { mass = m; inertia = (0, m * l * l / 12, m * l * l / 12); }
        body disk { mass = 0.1; inertia = (1e-4, 1e-4, 1e-4); }
        TOG[bar] = Trotz(theta) * Tdisp(l / 2, 0, 0);
        TOG[disk] = Trotz(psi);
        generalized_force(psi, -ks * psi - 0.01 * qd[1]);
        constraint gear = psi - theta;
    }
}

#[test]
fn constrained_statics_judges_stability_with_the_extra_states_settled() {
    // the same equilibrium through the constraint: θ = ψ = 0.25 rad, i = 1 A; on the
    // constraint manifold, N = (1, 1)/√2 over (θ, ψ), the spring's stiffness is 2 / 2 = 1
    // (with the current among the reduced coordinates: two eigenvalues, 0.99997 and 1000)
    motor_statics(SprungArmGeared::default(), &[0.25, 0.25, 1.0], 1.0);
}
