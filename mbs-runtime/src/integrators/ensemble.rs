//! Many runs of one model at once: an ensemble of members (starts, inputs, and each its own
//! model: its parameters and its charts) integrated by one explicit scheme, four members at
//! a time on the lanes of the model's batch functions ([`crate::lanes`], `option batch;`).
//!
//! Each lane is a whole run of its own, the driver's (`driver::Run`): its own step size, error
//! test, rejections, outputs, failure and work counters, exactly those of
//! [`super::simulate_with`] on that member. Only the evaluations are shared: the scheme's
//! step is taken apart at its stages ([`super::stepper::Staged`]), every lane computes its
//! stage point, one call of the batch forward dynamics evaluates the four (each lane with its
//! run's model, [`Model::forward_dynamics_lanes`]; [`Model::forward_dynamics_x4`] of one of
//! them when the four have the same parameters and charts), and each lane
//! checks its own result as its run would ([`super::problem::Problem::accept_forward`]: a
//! value that does not stand is computed again by the lane's dense path, which names the
//! failure). A lane whose run ends, by reaching t_end or by failing, takes the next member
//! at once, so the lanes stay busy while members need different numbers of steps.
//!
//! What an ensemble runs: DOPRI5 (adaptive or fixed steps), RK4 and explicit Euler, on models
//! without constraints. A rotation joint's chart is its run's model's own, re-centred when
//! that run's joint nears gimbal lock, as alone. A model without
//! `option batch;`, or a processor without AVX2, evaluates the lanes one by one: the same
//! results, without the gain.

use super::driver::{Planned, Run};
use super::inputs::Inputs;
use super::sim_error::SimError;
use super::stepper::{Staged, Step, Stepper};
use crate::error::Failure;
use crate::lanes::{F64x4, LANES, pack, simd_available, unpack};
use crate::model::Model;
use crate::options::{Options, Scheme};
use crate::stats::Stats;
use crate::trajectory::Trajectory;

/// One run of an ensemble: its start (the model's declared one where `None`) and its inputs
/// (a function of time; sampled controllers are refused: their instants would stop the lanes
/// at different times).
#[derive(Default)]
pub struct Member {
    pub q0: Option<Vec<f64>>,
    pub qd0: Option<Vec<f64>>,
    pub inputs: Inputs,
}

impl Member {
    /// A member starting at (q0, qd0), without inputs.
    pub fn at(q0: Vec<f64>, qd0: Vec<f64>) -> Member {
        Member {
            q0: Some(q0),
            qd0: Some(qd0),
            inputs: Inputs::default(),
        }
    }

    /// The same member with inputs u(t).
    pub fn with_inputs(mut self, inputs: Inputs) -> Member {
        self.inputs = inputs;
        self
    }
}

/// What an ensemble gave: each member's run, in the order of the members (the trajectory and
/// work counters, or the failure with the trajectory up to it), and the shared work.
#[derive(Debug)]
pub struct EnsembleReport<M> {
    pub runs: Vec<Result<(Trajectory, Stats), SimError>>,
    /// each member's model as its run left it (its charts re-centred), for a run that reached
    /// its end; `None` for a run that failed
    pub models: Vec<Option<M>>,
    /// calls of the batch forward dynamics (four lanes each)
    pub batch_evaluations: usize,
    /// the lanes those calls evaluated for a run (the others were idle: fewer than four runs
    /// left)
    pub lane_evaluations: usize,
}

impl<M> EnsembleReport<M> {
    /// The share of the batch calls' lanes that evaluated a run (1 when all four always did).
    pub fn occupancy(&self) -> f64 {
        if self.batch_evaluations == 0 {
            return 0.0;
        }
        self.lane_evaluations as f64 / (LANES * self.batch_evaluations) as f64
    }
}

/// Runs every member of an ensemble of `model` with `scheme` and `options` (its `q0` and
/// `qd0` are each member's, where given), four at a time. Each member's run is the one
/// [`super::simulate_with`] makes of it, but for the rounding of the batch functions (they
/// agree with the one-state functions to about 1e-15 relative); a member that fails keeps its
/// trajectory up to the failure and does not stop the others.
///
/// Refused with an `InvalidOption` at t₀ (before any run): a scheme other than DOPRI5, RK4
/// and explicit Euler, and a model with constraints. A member whose start is refused (its
/// q0's length, a non-finite value, controllers) has that failure as its run.
pub fn simulate_ensemble<M: Model + Clone + 'static>(
    model: &M,
    scheme: Scheme,
    options: &Options,
    members: Vec<Member>,
) -> Result<EnsembleReport<M>, SimError> {
    supported::<M>(&scheme).map_err(|e| super::driver::refused(model, e, options.t0))?;
    let members = members.into_iter().map(|m| (model.clone(), m));
    simulate_ensemble_each(scheme, options, members)
}

/// [`simulate_ensemble`] of models made by `make`, one per member, for a model that is not
/// `Clone`.
pub fn simulate_ensemble_of<M: Model + 'static>(
    make: impl Fn() -> M,
    scheme: Scheme,
    options: &Options,
    members: Vec<Member>,
) -> Result<EnsembleReport<M>, SimError> {
    let model = make();
    supported::<M>(&scheme).map_err(|e| super::driver::refused(&model, e, options.t0))?;
    let members = members.into_iter().map(|m| (make(), m));
    simulate_ensemble_each(scheme, options, members)
}

/// [`simulate_ensemble`] of members that each bring their model: models of one type with
/// their own parameters (a Monte-Carlo study of a mass, a stiffness) and charts, each lane of
/// the batch functions reading its member's ([`Model::forward_dynamics_lanes`]). The members
/// are taken from `members` as lanes free up, so a long list of them is never all in memory
/// at once. Refused as [`simulate_ensemble`], checked on the first member's model (nothing
/// is checked when there are none).
pub fn simulate_ensemble_each<M: Model + 'static>(
    scheme: Scheme,
    options: &Options,
    members: impl IntoIterator<Item = (M, Member)>,
) -> Result<EnsembleReport<M>, SimError> {
    let mut members = members.into_iter().peekable();
    let stages = match members.peek() {
        Some((model, _)) => {
            supported::<M>(&scheme).map_err(|e| super::driver::refused(model, e, options.t0))?
        }
        None => 0,
    };
    let t_end = options.t_end;
    let start = |model: M, m: Member| -> Result<Run, SimError> {
        if !m.inputs.controllers.is_empty() {
            let e = Failure::InvalidOption {
                name: "inputs",
                value: format!("{} controllers", m.inputs.controllers.len()),
                reason: "an ensemble's members take inputs as functions of time: run a member with sampled controllers by `simulate_with`",
            };
            return Err(super::driver::refused(&model, e, options.t0));
        }
        let options = Options {
            q0: m.q0.or_else(|| options.q0.clone()),
            qd0: m.qd0.or_else(|| options.qd0.clone()),
            ..options.clone()
        };
        Run::new(model, scheme, options, m.inputs)
    };
    let joints = members
        .peek()
        .map_or(0, |(m, _)| m.info().rotation_joints.len());
    let mut lanes = Lanes::new(M::NQ, M::NU, joints);
    let batched = M::BATCH_GENERATED && M::FORWARD_DYNAMICS_GENERATED && simd_available();
    // each member's run and model, filled in as they end (a member taken from the list is
    // given its places)
    let mut runs: Vec<Option<Result<(Trajectory, Stats), SimError>>> = Vec::new();
    let mut models: Vec<Option<M>> = Vec::new();
    let mut queue = members.enumerate();
    let mut active: [Option<(usize, Run)>; LANES] = Default::default();
    let mut report = EnsembleReport {
        runs: Vec::new(),
        models: Vec::new(),
        batch_evaluations: 0,
        lane_evaluations: 0,
    };
    loop {
        // every lane's next attempt, a lane whose run ended taking the next member
        let mut plans: [Option<Planned>; LANES] = [None; LANES];
        for (slot, plan) in active.iter_mut().zip(plans.iter_mut()) {
            *plan = loop {
                if slot.is_none() {
                    let Some((i, (model, m))) = queue.next() else {
                        break None;
                    };
                    runs.push(None);
                    models.push(None);
                    match start(model, m) {
                        Ok(run) => *slot = Some((i, run)),
                        Err(e) => {
                            runs[i] = Some(Err(e));
                            continue;
                        }
                    }
                }
                let (i, run) = slot.as_mut().expect("filled above");
                if run.cur.t >= t_end {
                    let (i, run) = slot.take().expect("filled above");
                    let (model, traj, stats) = run.finish();
                    runs[i] = Some(Ok((traj, stats)));
                    models[i] = model.into_any().downcast().ok().map(|m| *m);
                    continue;
                }
                match run.plan(t_end) {
                    Ok(p) => break Some(p),
                    Err(e) => {
                        runs[*i] = Some(Err(e));
                        *slot = None;
                    }
                }
            };
        }
        if plans.iter().all(Option::is_none) {
            break;
        }
        let mut failed: [Option<Failure>; LANES] = Default::default();
        for ((slot, plan), failed) in active.iter_mut().zip(&plans).zip(failed.iter_mut()) {
            if let (Some((_, run)), Some(p)) = (slot, plan) {
                let Run {
                    problem,
                    stepper,
                    ctl,
                    cur,
                    ..
                } = run;
                *failed = staged(stepper).begin(problem, cur, p.h, ctl).err();
            }
        }
        for s in 1..=stages {
            let live: [bool; LANES] =
                std::array::from_fn(|k| plans[k].is_some() && failed[k].is_none());
            if !live.iter().any(|&l| l) {
                break;
            }
            for k in 0..LANES {
                if let (true, Some((_, run)), Some(p)) = (live[k], &mut active[k], plans[k]) {
                    if let Err(e) = lanes.point(k, run, p.h, s) {
                        failed[k] = Some(e);
                    }
                }
            }
            let live: [bool; LANES] =
                std::array::from_fn(|k| plans[k].is_some() && failed[k].is_none());
            let mut alone = [!batched; LANES];
            if batched && live.iter().any(|&l| l) {
                let first = live.iter().position(|&l| l).expect("a live lane");
                // an idle lane repeats a live one
                let each: [&M; LANES] = std::array::from_fn(|k| {
                    let (_, run) = active[if live[k] { k } else { first }]
                        .as_ref()
                        .expect("a live lane runs");
                    model_of(run)
                });
                let one = lanes.evaluate(each, &live);
                report.batch_evaluations += 1;
                report.lane_evaluations += live.iter().filter(|&&l| l).count();
                // a failure of user code in a lane's model: that lane evaluates alone, so
                // that its run reports it; every lane when one model evaluated them all
                let failed = one.then(|| each[0].take_failure().is_some());
                for (k, alone) in alone.iter_mut().enumerate() {
                    *alone = live[k] && failed.unwrap_or_else(|| each[k].take_failure().is_some());
                }
            }
            for k in 0..LANES {
                if let (true, Some((_, run))) = (live[k], &mut active[k]) {
                    if let Err(e) = lanes.accept(k, run, s, alone[k]) {
                        failed[k] = Some(e);
                    }
                }
            }
        }
        for k in 0..LANES {
            let (Some((i, run)), Some(plan)) = (&mut active[k], plans[k]) else {
                continue;
            };
            let Run {
                problem,
                stepper,
                ctl,
                cur,
                next,
                ..
            } = run;
            let st = staged(stepper);
            let result = match failed[k].take() {
                Some(e) => st.stage_failed(e, ctl, plan.h),
                None => st.complete(Step(problem, cur, plan.h, ctl, next)),
            };
            if let Err(e) = run.conclude(plan, result) {
                runs[*i] = Some(Err(e));
                active[k] = None;
            }
        }
    }
    report.runs = runs
        .into_iter()
        .map(|r| r.expect("every member ran"))
        .collect();
    report.models = models;
    Ok(report)
}

/// A lane's model by its type (every run of an ensemble is of its model type).
fn model_of<M: Model + 'static>(run: &Run) -> &M {
    run.problem
        .model
        .as_any()
        .downcast_ref()
        .expect("an ensemble's runs are of its model type")
}

/// A run's scheme as explicit stages (checked by [`supported`]).
fn staged(stepper: &mut Box<dyn Stepper>) -> &mut dyn Staged {
    stepper.staged().expect("checked by `supported`")
}

/// Whether an ensemble runs `scheme` on models of type `M` ([`simulate_ensemble`] refuses
/// the others with this failure).
pub fn ensemble_supported<M: Model>(scheme: &Scheme) -> Result<(), Failure> {
    supported::<M>(scheme).map(|_| ())
}

/// What an ensemble runs: an explicit staged scheme, on a model without constraints; the
/// scheme's evaluations per step.
fn supported<M: Model>(scheme: &Scheme) -> Result<usize, Failure> {
    let refuse = |name, value: String, reason| {
        Err(Failure::InvalidOption {
            name,
            value,
            reason,
        })
    };
    let Some(stages) = super::dispatch::stepper_for(scheme, M::NQ)
        .staged()
        .map(|s| s.stages())
    else {
        return refuse(
            "scheme",
            scheme.name().to_string(),
            "an ensemble runs explicit schemes (DOPRI5, RK4, explicit Euler), whose stages it evaluates together: run other schemes one member at a time with `simulate`",
        );
    };
    if M::NC > 0 {
        return refuse(
            "model",
            format!("{} constraints", M::NC),
            "an ensemble runs open loops: run a closed loop's members with `simulate`",
        );
    }
    Ok(stages)
}

/// The four lanes' arguments and results of the batch forward dynamics, and one lane's
/// point and accelerations unpacked.
struct Lanes {
    /// the model's rotation joints
    joints: usize,
    t: F64x4,
    q: Vec<F64x4>,
    qd: Vec<F64x4>,
    u: Vec<F64x4>,
    qdd: Vec<F64x4>,
    pivots: Vec<F64x4>,
    /// each lane's stage time, point and inputs as one-state slices
    times: [f64; LANES],
    points: [(Vec<f64>, Vec<f64>); LANES],
    inputs: [Vec<f64>; LANES],
    pivot: Vec<f64>,
}

impl Lanes {
    fn new(n: usize, nu: usize, joints: usize) -> Lanes {
        let z = |len| vec![F64x4::ZERO; len];
        Lanes {
            joints,
            t: F64x4::ZERO,
            q: z(n),
            qd: z(n),
            u: z(nu),
            qdd: z(n),
            pivots: z(n),
            times: [0.0; LANES],
            points: std::array::from_fn(|_| (vec![0.0; n], vec![0.0; n])),
            inputs: std::array::from_fn(|_| vec![0.0; nu]),
            pivot: vec![0.0; n],
        }
    }

    /// Lane `k`'s stage `s` of a step of size h: its time, point and inputs.
    fn point(&mut self, k: usize, run: &mut Run, h: f64, s: usize) -> Result<(), Failure> {
        let t0 = run.cur.t;
        let (c, q, qd) = staged(&mut run.stepper).point(&run.problem, &run.cur, h, s)?;
        let (pq, pv) = &mut self.points[k];
        pq.copy_from_slice(q);
        pv.copy_from_slice(qd);
        self.times[k] = t0 + c * h;
        let u = run.problem.inputs(self.times[k])?;
        self.inputs[k].copy_from_slice(u);
        Ok(())
    }

    /// The batch forward dynamics at the live lanes' points, each lane with its model (an
    /// idle lane repeats a live one): [`Model::forward_dynamics_x4`] of the first when the
    /// four have the same parameters and charts (its code then knows them equal in every
    /// lane), else [`Model::forward_dynamics_lanes`]. Whether one model evaluated them.
    fn evaluate<M: Model>(&mut self, each: [&M; LANES], live: &[bool; LANES]) -> bool {
        let first = live.iter().position(|&l| l).expect("a live lane");
        let lane = |k: usize| if live[k] { k } else { first };
        let points = &self.points;
        pack(std::array::from_fn(|k| &points[lane(k)].0[..]), &mut self.q);
        pack(
            std::array::from_fn(|k| &points[lane(k)].1[..]),
            &mut self.qd,
        );
        let inputs = &self.inputs;
        pack(std::array::from_fn(|k| &inputs[lane(k)][..]), &mut self.u);
        self.t = F64x4::from(std::array::from_fn(|k| self.times[lane(k)]));
        let (q, qd, u) = (&self.q, &self.qd, &self.u);
        let (qdd, pivots) = (&mut self.qdd, &mut self.pivots);
        let one = each[1..].iter().all(|m| same(each[0], m, self.joints));
        if one {
            each[0].forward_dynamics_x4(self.t, q, qd, u, qdd, pivots);
        } else {
            M::forward_dynamics_lanes(each, self.t, q, qd, u, qdd, pivots);
        }
        one
    }

    /// Lane `k`'s accelerations of stage `s` into its scheme, judged by its run; computed by
    /// the run alone when `alone`.
    fn accept(&mut self, k: usize, run: &mut Run, s: usize, alone: bool) -> Result<(), Failure> {
        let t = self.times[k];
        let (q, qd) = &self.points[k];
        let Run {
            problem, stepper, ..
        } = run;
        let a = staged(stepper).accel_mut(s);
        if alone {
            return problem.accel(t, q, qd, a);
        }
        unpack(&self.qdd, k, a);
        unpack(&self.pivots, k, &mut self.pivot);
        problem.accept_forward(t, q, qd, a, &self.pivot)
    }
}

/// Whether two models of one type have the same parameters and charts (`joints` rotation
/// joints), so that one model's batch function computes the other's lanes too.
fn same<M: Model>(a: &M, b: &M, joints: usize) -> bool {
    std::ptr::eq(a, b)
        || (a.params() == b.params() && (0..joints).all(|j| a.chart(j) == b.chart(j)))
}
