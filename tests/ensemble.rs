//! An ensemble (`mbs::simulate_ensemble`): many members of one model run four at a time on
//! the lanes of its batch functions. Each member's run is the one `simulate_with` makes of it
//! (its steps, rejections and outputs; its states to the rounding of the batch functions); a
//! member that fails keeps its trajectory and its own failure while the others finish; the
//! lanes did the stages' evaluations (work counters); what an ensemble cannot run is refused
//! up front.

#![allow(unused_macros)]

use mbs::{
    Failure, Inputs, Integrator, Member, Model, Options, Output, Scheme, SimError, Simulation,
    Stats, StepControl, Trajectory, simulate_ensemble, simulate_ensemble_each, simulate_with,
};

include!("../benches/scaling/shapes.rs");

chain!(Chain8, 8, batch);

mbs::multibody! {
    /// A pendulum driven by a torque input, with a light spring to a wall.
    model Driven {
        param l = 0.8; param m = 1.2; param g = 9.81; param k = 3.0;
        dof a = 0.4;
        input torque;
        body bob { mass = m; inertia = (0.005, 0.005, 0.01); }
        TOG[bob] = Trotz(a) * Tdisp(l, 0, 0);
        gravity(0, -g, 0);
        generalized_force(a, torque - k * a);
        option batch;
    }
}

#[macro_use]
#[path = "common/delegating.rs"]
mod delegating;

#[path = "common/free_box.rs"]
mod free_box;
use free_box::Mixed;

#[path = "common/quoted.rs"]
mod quoted;

/// Starts spread about the model's declared one, deterministic.
fn starts(n: usize, count: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
    (0..count)
        .map(|k| {
            let q = (0..n)
                .map(|i| 0.3 + 0.2 * ((i * 3 + k * 7) as f64).sin())
                .collect();
            let qd = (0..n)
                .map(|i| 0.8 * ((i * 5 + k * 11) as f64).cos())
                .collect();
            (q, qd)
        })
        .collect()
}

fn options(t_end: f64, rtol: f64) -> Options {
    Options {
        output: Output::Every { dt: 0.1 },
        ..Options::adaptive(t_end, rtol)
    }
}

/// The ensemble's run of a member against the member run alone: the same outputs at the
/// same times, the same steps, its states within `tol` relative to their largest entry.
fn same_run(ens: &(Trajectory, Stats), alone: &(Trajectory, Stats), tol: f64, what: &str) -> f64 {
    let ((te, se), (ta, sa)) = (ens, alone);
    assert_eq!(te.len(), ta.len(), "{what}: outputs");
    assert_eq!(te.t, ta.t, "{what}: output times");
    assert_eq!(
        (se.steps, se.rejected_error),
        (sa.steps, sa.rejected_error),
        "{what}: steps and rejections"
    );
    let mut worst = 0.0f64;
    for i in 0..te.len() {
        for (a, b) in [(te.q(i), ta.q(i)), (te.qd(i), ta.qd(i))] {
            let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            for (x, y) in a.iter().zip(b) {
                worst = worst.max((x - y).abs() / scale);
            }
        }
    }
    assert!(
        worst <= tol,
        "{what}: differs by {worst:.2e} from the run alone"
    );
    worst
}

#[test]
fn members_run_as_they_would_alone_four_at_a_time() {
    let model = Chain8::default();
    let fixed = Options {
        step: StepControl::Fixed { h: 2e-3 },
        ..options(1.5, 1e-8)
    };
    for (scheme, opts) in [
        (Scheme::Dopri5, options(1.5, 1e-8)),
        (Scheme::Rk4, fixed.clone()),
        (Scheme::Dopri5, fixed),
    ] {
        // six members: the lanes take the fifth and sixth as the first runs end
        let members: Vec<Member> = starts(8, 6)
            .into_iter()
            .map(|(q, qd)| Member::at(q, qd))
            .collect();
        let report = simulate_ensemble(&model, scheme, &opts, members).unwrap();
        let mut worst = 0.0f64;
        let mut lane_stages = 0;
        // evaluations each run makes alone: its start (qdd₀, and the first step's trial when
        // adaptive) and the stability watch's (fixed steps)
        let mut alone_only = 0;
        for (k, (q, qd)) in starts(8, 6).into_iter().enumerate() {
            let o = Options {
                q0: Some(q),
                qd0: Some(qd),
                ..opts.clone()
            };
            let alone = simulate_with(model.clone(), scheme, o, Inputs::default()).unwrap();
            let ens = report.runs[k].as_ref().unwrap();
            let what = format!("{} member {k}", scheme.name());
            worst = worst.max(same_run(ens, &alone, 1e-9, &what));
            let s = &ens.1;
            assert_eq!(s.dynamics, 0, "{what}: no dense evaluation");
            assert_eq!(
                s.forward_dynamics, alone.1.forward_dynamics,
                "{what}: evaluations"
            );
            let stages = if scheme == Scheme::Rk4 { 4 } else { 6 };
            let on_lanes = stages * (s.steps + s.rejected_error);
            alone_only += s.forward_dynamics - on_lanes;
            lane_stages += on_lanes;
        }
        if mbs::lanes::simd_available() {
            assert_eq!(report.lane_evaluations, lane_stages, "{}", scheme.name());
            // four lanes busy but for the last members' tails
            assert!(
                report.occupancy() > 0.7,
                "occupancy {:.2} ({} batch calls)",
                report.occupancy(),
                report.batch_evaluations
            );
        }
        println!(
            "{}, 6 members of an 8-bar chain: {} batch calls for {} stages ({} evaluations alone), occupancy {:.2}, worst difference from the runs alone {worst:.1e}",
            scheme.name(),
            report.batch_evaluations,
            lane_stages,
            alone_only,
            report.occupancy()
        );
    }
}

/// A member's steps on lanes within 1 % of its steps alone (where contacts' kinks may take a
/// step the other way).
fn nearly_the_steps_alone(on_lanes: &Stats, alone: &Stats, k: usize) {
    let steps = (on_lanes.steps as f64 - alone.steps as f64).abs() / alone.steps as f64;
    assert!(
        steps < 0.01,
        "member {k}: {} steps, {} alone",
        on_lanes.steps,
        alone.steps
    );
}

/// Members that bring their own model (`simulate_ensemble_each`): each lane computes with its
/// member's parameters, and each member's run is the one its model makes alone.
#[test]
fn members_with_their_own_parameters_run_as_they_would_alone() {
    let chain = |k: usize| {
        let mut model = Chain8::default();
        let mut p = model.params().clone();
        p.l *= 1.0 + 0.15 * k as f64;
        p.m *= 1.0 + 0.4 * k as f64;
        p.g -= 0.5 * k as f64;
        model.set_params(p).unwrap();
        model
    };
    let opts = options(1.5, 1e-8);
    // seven members, from one start: only their parameters differ
    let members = (0..7).map(|k| (chain(k), Member::default()));
    let report = simulate_ensemble_each(Scheme::Dopri5, &opts, members).unwrap();
    let mut worst = 0.0f64;
    for k in 0..7 {
        let alone = simulate_with(chain(k), Scheme::Dopri5, opts.clone(), Inputs::default());
        let ens = report.runs[k].as_ref().unwrap();
        worst = worst.max(same_run(ens, &alone.unwrap(), 1e-9, &format!("member {k}")));
        assert_eq!(ens.1.dynamics, 0, "member {k}: no dense evaluation");
        // the model back, with its parameters
        let back = report.models[k].as_ref().unwrap();
        assert_eq!(back.params(), chain(k).params());
    }
    // the members differ from one another: a lane that read another member's parameters
    // would not have matched its run alone
    let end = |k: usize| {
        let t = &report.runs[k].as_ref().unwrap().0;
        t.q(t.len() - 1).to_vec()
    };
    assert!(
        (end(0)[7] - end(6)[7]).abs() > 0.1,
        "{:?} {:?}",
        end(0),
        end(6)
    );
    if mbs::lanes::simd_available() {
        assert!(
            report.occupancy() > 0.7,
            "occupancy {:.2}",
            report.occupancy()
        );
    }
    println!(
        "7 members of an 8-bar chain with their own lengths, masses and gravity: {} batch calls, occupancy {:.2}, worst difference from the runs alone {worst:.1e}",
        report.batch_evaluations,
        report.occupancy()
    );
}

/// A free body whose members tumble through the gimbal lock of their first charts: each run
/// re-centres its own joint's chart when its run alone does (the lanes read each member's
/// chart), and ends where its run alone ends, its model's chart the one it ends with alone.
#[test]
fn a_free_body_re_centres_each_member_s_chart_on_its_own() {
    let model = Mixed::default();
    let opts = options(0.6, 1e-7);
    let starts: Vec<(Vec<f64>, Vec<f64>)> = (0..6)
        .map(|k| {
            let mut q0 = vec![0.0; 7];
            let mut qd0 = vec![0.0; 7];
            model.initial_state(&mut q0, &mut qd0);
            // pitch rates from 0 to 6 rad/s: the fast ones pass b = π/2
            q0[4] = 0.9 + 0.05 * k as f64;
            qd0[4] = 1.2 * k as f64;
            qd0[5] += 0.2 * k as f64;
            (q0, qd0)
        })
        .collect();
    let members: Vec<Member> = starts
        .iter()
        .map(|(q, qd)| Member::at(q.clone(), qd.clone()))
        .collect();
    let report = simulate_ensemble(&model, Scheme::Dopri5, &opts, members).unwrap();
    let (mut switched, mut worst) = (0, 0.0f64);
    // the fewest and the most re-centrings of a run alone
    let (mut fewest, mut most) = (usize::MAX, 0);
    for (k, (q0, qd0)) in starts.into_iter().enumerate() {
        let o = Options {
            q0: Some(q0),
            qd0: Some(qd0),
            ..opts.clone()
        };
        let mut sim = Simulation::new(model.clone(), Scheme::Dopri5, o).unwrap();
        sim.integrate_to(opts.t_end).unwrap();
        let (alone_model, ta, sa) = sim.finish_with_model();
        let (te, se) = report.runs[k].as_ref().unwrap();
        println!(
            "member {k}: {} steps and {} chart switches on lanes, {} and {} alone",
            se.steps, se.chart_switches, sa.steps, sa.chart_switches
        );
        assert_eq!(
            se.chart_switches, sa.chart_switches,
            "member {k}: chart switches"
        );
        switched += usize::from(se.chart_switches > 0);
        fewest = fewest.min(sa.chart_switches);
        most = most.max(sa.chart_switches);
        nearly_the_steps_alone(se, &sa, k);
        // the same pose: the charts each run ends with, the angles measured from them
        let back = report.models[k].as_ref().unwrap();
        let (ce, ca) = (back.chart(0), alone_model.chart(0));
        for (re, ra) in ce.iter().flatten().zip(ca.iter().flatten()) {
            worst = worst.max((re - ra).abs());
        }
        let (qe, qa) = (te.q(te.len() - 1), ta.q(ta.len() - 1));
        for (x, y) in qe.iter().zip(qa) {
            worst = worst.max((x - y).abs());
        }
    }
    assert!(switched >= 2, "{switched} members re-centred their charts");
    assert!(
        worst < 1e-4,
        "final poses differ by {worst:e} from the runs alone"
    );
    println!(
        "a free body tumbling, 6 members, {switched} of them re-centring: final charts and coordinates within {worst:.1e} of the runs alone"
    );
    // the runs alone's counts (those on lanes depend on the processor's vector units)
    quoted::says(
        "docs/ensembles.md",
        &[format!(
            "six members of the free body tumbling at pitch rates up to 6 rad/s re-centred \
             {fewest}–{most} times each, exactly as often as alone"
        )],
    );
}

#[test]
fn a_member_that_fails_keeps_its_trajectory_and_the_others_finish() {
    let model = Driven::default();
    let opts = options(2.0, 1e-7);
    let torque = |k: usize| move |t: f64, u: &mut [f64]| u[0] = 0.5 * k as f64 * (3.0 * t).sin();
    let member = |k: usize| Member::at(vec![0.1 * k as f64], vec![0.0]);
    let mut members: Vec<Member> = (0..5)
        .map(|k| member(k).with_inputs(Inputs::new().function(torque(k))))
        .collect();
    // member 2's input is not finite from t = 0.75 on
    members[2] = member(2).with_inputs(
        Inputs::new()
            .function(|t: f64, u: &mut [f64]| u[0] = if t < 0.75 { 0.3 } else { f64::NAN }),
    );
    // member 4's start has two coordinates for one
    members[4].q0 = Some(vec![0.1, 0.2]);
    let report = simulate_ensemble(&model, Scheme::Dopri5, &opts, members).unwrap();
    assert_eq!(report.runs.len(), 5);
    for k in [0, 1, 3] {
        let o = Options {
            q0: Some(vec![0.1 * k as f64]),
            qd0: Some(vec![0.0]),
            ..opts.clone()
        };
        let alone = simulate_with(
            model.clone(),
            Scheme::Dopri5,
            o,
            Inputs::new().function(torque(k)),
        )
        .unwrap();
        same_run(
            report.runs[k].as_ref().unwrap(),
            &alone,
            1e-9,
            &format!("member {k}"),
        );
    }
    let SimError {
        kind,
        t,
        trajectory,
        ..
    } = report.runs[2].as_ref().unwrap_err();
    assert!(
        matches!(
            kind,
            Failure::NonFinite {
                quantity: "input",
                ..
            }
        ),
        "member 2: {kind}"
    );
    assert!(*t < 0.75 && *t > 0.6, "member 2 failed at t = {t}");
    // its outputs up to the failure: 0, 0.1, …, 0.7
    assert_eq!(
        trajectory.len(),
        8,
        "member 2's outputs: {:?}",
        trajectory.t
    );
    let e4 = report.runs[4].as_ref().unwrap_err();
    assert!(
        matches!(e4.kind, Failure::InvalidOption { name: "q0", .. }),
        "member 4: {}",
        e4.kind
    );
}

#[test]
fn what_an_ensemble_cannot_run_is_refused_up_front() {
    let members = || vec![Member::default(), Member::default()];
    fn refused<M: std::fmt::Debug>(
        r: Result<mbs::EnsembleReport<M>, SimError>,
    ) -> (&'static str, &'static str) {
        match r {
            Err(SimError {
                kind: Failure::InvalidOption { name, reason, .. },
                ..
            }) => (name, reason),
            other => panic!("not refused: {other:?}"),
        }
    }
    let model = Driven::default();
    let opts = options(1.0, 1e-6);
    let (name, reason) = refused(simulate_ensemble(&model, Scheme::Radau5, &opts, members()));
    assert_eq!(name, "scheme");
    assert!(reason.contains("DOPRI5, RK4"), "{reason}");
    let (name, _) = refused(simulate_ensemble(
        &model,
        Scheme::Bdf(Default::default()),
        &opts,
        members(),
    ));
    assert_eq!(name, "scheme");
    let fourbar = mbs_models::fourbar::FourBar::default();
    let (name, reason) = refused(simulate_ensemble(
        &fourbar,
        Scheme::Dopri5,
        &opts,
        members(),
    ));
    assert_eq!(name, "model");
    assert!(reason.contains("closed loop"), "{reason}");
    // a model without `option batch;` runs its lanes one by one: the same runs
    let report = simulate_ensemble(
        &mbs_models::dpend::DoublePendulum::default(),
        Scheme::Dopri5,
        &opts,
        members(),
    )
    .unwrap();
    assert_eq!(report.batch_evaluations, 0);
    assert!(report.runs.iter().all(|r| r.is_ok()));
    let _ = <Driven as Model>::NQ;
}

/// A free body's members run on lanes when its charts stay the model's (`chart_switch` 0):
/// each member the run it makes alone.
#[test]
fn a_free_body_runs_on_lanes_with_its_charts_held() {
    let model = Mixed::default();
    let opts = Options {
        chart_switch: 0.0,
        ..options(0.6, 1e-7)
    };
    let members: Vec<Member> = starts(7, 5)
        .into_iter()
        .map(|(q, qd)| {
            let mut q0 = vec![0.0; 7];
            let mut qd0 = vec![0.0; 7];
            model.initial_state(&mut q0, &mut qd0);
            for i in 3..7 {
                q0[i] += 0.1 * (q[i] - 0.3);
                qd0[i] += 0.3 * qd[i];
            }
            Member::at(q0, qd0)
        })
        .collect();
    let starts: Vec<(Vec<f64>, Vec<f64>)> = members
        .iter()
        .map(|m| (m.q0.clone().unwrap(), m.qd0.clone().unwrap()))
        .collect();
    let report = simulate_ensemble(&model, Scheme::Dopri5, &opts, members).unwrap();
    let mut worst = 0.0f64;
    // the largest error of the runs on lanes, and of the runs alone
    let mut worst_errors = [0.0f64; 2];
    for (k, (q0, qd0)) in starts.into_iter().enumerate() {
        let o = Options {
            q0: Some(q0),
            qd0: Some(qd0),
            ..opts.clone()
        };
        let alone =
            simulate_with(model.clone(), Scheme::Dopri5, o.clone(), Inputs::default()).unwrap();
        let (te, se) = report.runs[k].as_ref().unwrap();
        let (ta, sa) = &alone;
        // the contacts' kinks make the runs alone and on lanes, which differ in the last
        // bits of sin and cos, take some steps differently: the same motion to the tolerance
        assert_eq!(te.t, ta.t, "member {k}: output times");
        nearly_the_steps_alone(se, sa, k);
        for i in 0..te.len() {
            for (x, y) in te.q(i).iter().zip(ta.q(i)) {
                worst = worst.max((x - y).abs());
            }
        }
        // both against the member run alone at rtol 1e-10: the runs on lanes as accurate as
        // the runs alone
        let tight = Options {
            step: StepControl::Adaptive {
                rtol: 1e-10,
                atol: 1e-12,
                h0: None,
            },
            ..o.clone()
        };
        let (tr, _) =
            simulate_with(model.clone(), Scheme::Dopri5, tight, Inputs::default()).unwrap();
        let error = |t: &mbs::Trajectory| {
            (0..t.len())
                .flat_map(|i| t.q(i).iter().zip(tr.q(i)).map(|(x, y)| (x - y).abs()))
                .fold(0.0f64, f64::max)
        };
        let (on_lanes, by_itself) = (error(te), error(ta));
        println!(
            "member {k}: {} steps on lanes, {} alone; error {on_lanes:.1e} on lanes, {by_itself:.1e} alone",
            se.steps, sa.steps
        );
        worst_errors[0] = worst_errors[0].max(on_lanes);
        worst_errors[1] = worst_errors[1].max(by_itself);
        assert_eq!(se.chart_switches, 0);
    }
    assert!(
        worst < 1e-5,
        "positions differ by {worst:e} from the runs alone"
    );
    // as accurate on lanes as alone: the errors are the tolerance's, whichever way a kink's
    // step went
    let [on_lanes, by_itself] = worst_errors;
    assert!(
        on_lanes <= 2.0 * by_itself,
        "largest error {on_lanes:e} on lanes, {by_itself:e} alone"
    );
    // the runs alone's error (that on lanes depends on the processor's vector units)
    quoted::says(
        "docs/ensembles.md",
        &[format!(
            "on lanes and {by_itself:.1e} alone. A member that fails"
        )],
    );
    if mbs::lanes::simd_available() {
        assert!(report.batch_evaluations > 0);
    }
    println!(
        "a free body on two corners of the ground, 5 members: positions within {worst:.1e} of the runs alone"
    );
}

/// The 8-bar chain as a hand-written batch model whose user code fails at every evaluation
/// past t = 0.6 s (a failure it records, as `WithEfforts` does, for `take_failure`): in a batch
/// call, on the model that made the call.
#[derive(Clone, Default)]
struct FailsLate(Chain8, std::cell::Cell<Option<f64>>);

impl FailsLate {
    const AFTER: f64 = 0.6;
    fn record(&self, t: f64) {
        if t > Self::AFTER && self.1.get().is_none() {
            self.1.set(Some(t));
        }
    }
}

delegating_model!(FailsLate => Chain8 {
    const FORWARD_DYNAMICS_GENERATED: bool = true;
    const BATCH_GENERATED: bool = true;
    fn dynamics(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], m: &mut [f64], h: &mut [f64]) {
        self.record(t);
        self.0.dynamics(t, q, qd, u, m, h)
    }
    fn forward_dynamics(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        qdd: &mut [f64],
        pivots: &mut [f64],
    ) {
        self.record(t);
        self.0.forward_dynamics(t, q, qd, u, qdd, pivots)
    }
    fn forward_dynamics_x4(
        &self,
        t: mbs::F64x4,
        q: &[mbs::F64x4],
        qd: &[mbs::F64x4],
        u: &[mbs::F64x4],
        qdd: &mut [mbs::F64x4],
        pivots: &mut [mbs::F64x4],
    ) {
        // any lane past the time: the failure is this model's
        (0..mbs::LANES).for_each(|k| self.record(t.lane(k)));
        self.0.forward_dynamics_x4(t, q, qd, u, qdd, pivots)
    }
    fn forward_dynamics_lanes(
        each: [&Self; mbs::LANES],
        t: mbs::F64x4,
        q: &[mbs::F64x4],
        qd: &[mbs::F64x4],
        u: &[mbs::F64x4],
        qdd: &mut [mbs::F64x4],
        pivots: &mut [mbs::F64x4],
    ) {
        (0..mbs::LANES).for_each(|k| each[k].record(t.lane(k)));
        Chain8::forward_dynamics_lanes(each.map(|m| &m.0), t, q, qd, u, qdd, pivots)
    }
    fn take_failure(&self) -> Option<Failure> {
        self.1.take().map(|t| Failure::EffortRejected {
            t,
            message: "past t = 0.6 s".into(),
        })
    }
});

/// A failure of user code recorded in a batch call is its own lane's, whichever model made
/// the call: every member of identical models (one model evaluates the four lanes) fails at
/// the evaluation where it fails alone, none runs past it.
#[test]
fn a_failure_of_user_code_in_a_shared_batch_call_is_each_lane_s_own() {
    let model = FailsLate::default();
    let opts = options(1.0, 1e-8);
    let starts = starts(8, 6);
    let members: Vec<Member> = starts
        .iter()
        .map(|(q, qd)| Member::at(q.clone(), qd.clone()))
        .collect();
    let report = simulate_ensemble(&model, Scheme::Dopri5, &opts, members).unwrap();
    for (k, (q, qd)) in starts.into_iter().enumerate() {
        let o = Options {
            q0: Some(q),
            qd0: Some(qd),
            ..opts.clone()
        };
        let alone = simulate_with(model.clone(), Scheme::Dopri5, o, Inputs::default()).unwrap_err();
        let Err(e) = &report.runs[k] else {
            panic!(
                "member {k} ran past t = 0.6 s, where alone it failed at {}",
                alone.t
            )
        };
        assert!(
            matches!(e.kind, Failure::EffortRejected { .. }),
            "member {k}: {}",
            e.kind
        );
        println!(
            "member {k}: failed at {} after {} steps, alone at {} after {}",
            e.t, e.stats.steps, alone.t, alone.stats.steps
        );
        // where alone it fails, to the rounding of the batch functions (the steps that close
        // in on the wall of rejected states, 0–5 more or fewer than alone, follow the last
        // bits), never past it
        assert!(
            e.t <= FailsLate::AFTER,
            "member {k} ran past t = 0.6 s: {}",
            e.t
        );
        assert!(
            (e.t - alone.t).abs() < 1e-9,
            "member {k}: {} against {}",
            e.t,
            alone.t
        );
    }
}
