//! The driver every scheme runs under: `Simulation` validates the options, starts from a
//! consistent state, proposes steps, lands on stop and sample times, records outputs and
//! turns failures into `SimError`s.

use super::constrained::{Assembly, Constrained, Mode, assemble_erased};
use super::dispatch::{constraint_mode, stepper_for};
use super::inputs::{Controller, Inputs};
use super::newton::NewtonTol;
use super::problem::{Loops, Problem};
use super::sim_error::SimError;
use super::step_control::{Largest, StepBounds, Tolerances, component_name, initial_step};
use super::stepper::{Attempt, Control, Step, Stepper};
use super::{Integrator, State};
use crate::charts::{self, Recentring};
use crate::erased::{ErasedModel, OwnedModel};
use crate::error::{Failure, FlooredTolerance, HeldMost, OutOfSteps};
use crate::model::{Model, Pose};
use crate::options::{Options, Output, Scheme, StepControl};
use crate::stats::Stats;
use crate::trajectory::{Observer, Trajectory};
use std::marker::PhantomData;

/// Below this order of the error in h, observed over rejections from about one t, the forces
/// are taken not to be smooth there: a step across a jump Δa in the acceleration errs by
/// about h·Δa (order 1), a step across a law that switches with the state by a size that
/// does not fall with h (order 0), where a smooth motion gives the schemes' orders of 2 to 6
/// (and a motion that runs away an error that grows as h shrinks: below −0.5, not taken).
const JUMP_ORDER: f64 = 1.5;

/// Whether two times are about one: within a millionth of their size (or of 1 s).
fn near(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * a.abs().max(b.abs()).max(1.0)
}

/// Runs `scheme` on `model` with `options` to the end; on failure, the error keeps the
/// trajectory up to the failure.
pub fn simulate<M: Model + 'static>(
    model: M,
    scheme: Scheme,
    options: Options,
) -> Result<(Trajectory, Stats), SimError> {
    simulate_with(model, scheme, options, Inputs::default())
}

/// [`simulate`] with inputs driven by time functions and sampled controllers.
pub fn simulate_with<M: Model + 'static>(
    model: M,
    scheme: Scheme,
    options: Options,
    inputs: Inputs,
) -> Result<(Trajectory, Stats), SimError> {
    let mut sim = Simulation::with_inputs(model, scheme, options, inputs)?;
    let t_end = sim.run.options.t_end;
    sim.integrate_to(t_end)?;
    Ok(sim.finish())
}

/// A running simulation: the model, the scheme, the state, the outputs and the work done.
pub struct Simulation<M: Model> {
    run: Run,
    model: PhantomData<fn() -> M>,
}

/// A simulation with its model's type erased: all of its work, compiled once whatever the
/// model (`crate::erased`).
pub(super) struct Run {
    pub(super) problem: Problem,
    pub(super) stepper: Box<dyn Stepper>,
    scheme: Scheme,
    options: Options,
    pub(super) ctl: Control,
    pub(super) cur: State,
    pub(super) next: State,
    prev: State,
    scratch: State,
    h: f64,
    attempts: usize,
    /// why the last attempt was rejected, when an evaluation failed (reported if h collapses)
    last_cause: Option<Failure>,
    /// the component that weighed most in the last attempt's error test, which rejected the
    /// attempt or accepted it and chose the next step (`Failure::StepTooSmall` names it)
    held_by: Option<Largest>,
    /// the first rejection by the error test of the current run of rejections from about
    /// one t (t moving by less than a millionth of itself): its t, its h and its error norm
    first_rejection: Option<(f64, f64, f64)>,
    /// the order at which the error fell with the step over that run of rejections
    /// (ln(err₁/err₂)/ln(h₁/h₂), h shrunk by 4 at least), and the t it was observed at:
    /// about 1 where the forces jump within the step, about 0 where they switch with the state
    observed_order: Option<(f64, f64)>,
    /// the largest position and velocity of the start, against which a component that held
    /// the step is judged to have run away (`HeldBy::ran_away`)
    start_scale: [f64; 2],
    /// per coordinate (its position and velocity), then per multiplier: the accepted steps
    /// whose error test it held
    held_counts: Vec<u32>,
    traj: Trajectory,
    /// pending output times (for `Output::Every` and `Times`), next one first
    out_times: Vec<f64>,
    out_next: usize,
    poses: Vec<Pose>,
    observers: Vec<Box<dyn Observer>>,
    assembly: Option<Assembly>,
    /// sampled controllers: period, samples taken, the controller
    controllers: Vec<(f64, u64, Box<dyn Controller>)>,
    /// the charts of the rotation joints, handed to the controllers at each sample
    charts: Vec<[[f64; 3]; 3]>,
    /// the controllers' outputs before a sample, restored when it fails
    held_before: Vec<f64>,
    /// rotation joints: the re-centrings of the last accepted step, each joint's chart
    /// number and last recorded quaternion, and a buffer of orientations to record
    moved: Vec<Recentring>,
    chart_numbers: Vec<u32>,
    last_quaternion: Vec<Option<[f64; 4]>>,
    orientations: Vec<f64>,
}

impl<M: Model + 'static> Simulation<M> {
    /// Validates everything, then starts from a consistent state: the given or declared q0,
    /// qd0 and qdd0 from M qdd = h.
    pub fn new(model: M, scheme: Scheme, options: Options) -> Result<Simulation<M>, SimError> {
        Simulation::with_inputs(model, scheme, options, Inputs::default())
    }

    /// [`Simulation::new`] with inputs driven by a time function and sampled controllers
    /// (sampled a first time at t₀, before the start's accelerations).
    pub fn with_inputs(
        model: M,
        scheme: Scheme,
        options: Options,
        inputs: Inputs,
    ) -> Result<Simulation<M>, SimError> {
        if M::SENSITIVITY_BLOCKS > 0 && !inputs.controllers.is_empty() {
            // u(t) alone is free of the parameters; a controller's u is not
            return Err(refused(
                &model,
                Failure::InvalidOption {
                    name: "controllers",
                    value: format!("{} sampled controllers", inputs.controllers.len()),
                    reason: "sensitivities take the inputs as free of the parameters, and a controller's feedback through the state would be left out of dq/dp: write the control law in the model (`generalized_force`), or differentiate whole runs",
                },
                options.t0,
            ));
        }
        let run = Run::new(model, scheme, options, inputs)?;
        Ok(Simulation {
            run,
            model: PhantomData,
        })
    }

    /// Adds an observer that sees every output as it is recorded.
    pub fn observe(&mut self, o: impl Observer + 'static) {
        self.run.observers.push(Box::new(o));
    }

    /// The scheme.
    pub fn scheme(&self) -> Scheme {
        self.run.scheme
    }

    /// The model.
    pub fn model(&self) -> &M {
        let any = self.run.problem.model.as_any();
        any.downcast_ref()
            .expect("the model the simulation was made with")
    }

    /// How the start was made consistent (constrained models only): residuals before and
    /// after, iterations, the largest change.
    pub fn assembly(&self) -> Option<&Assembly> {
        self.run.assembly.as_ref()
    }

    /// The independent coordinates of coordinate partitioning, as they are now (empty for
    /// other methods).
    pub fn independent_coordinates(&self) -> Vec<String> {
        self.run.independent_coordinates()
    }

    /// The step the next attempt will use.
    pub fn h(&self) -> f64 {
        self.run.h
    }

    /// Hands the outputs recorded since the last call to `sink`, then forgets them: a long run
    /// written to disk as it goes keeps flat memory (a later failure's trajectory holds only
    /// the outputs recorded after this call).
    pub fn drain_outputs<R>(&mut self, sink: impl FnOnce(&Trajectory) -> R) -> R {
        let r = sink(&self.run.traj);
        self.run.traj.clear_outputs();
        r
    }

    /// Trajectory and work counters (records the final state for `Output::Last`).
    pub fn finish(self) -> (Trajectory, Stats) {
        let (_, traj, stats) = self.run.finish();
        (traj, stats)
    }

    /// [`Simulation::finish`], handing back the model too (its charts as the run left them),
    /// for quantities computed from the trajectory afterwards (a sweep's metrics).
    pub fn finish_with_model(self) -> (M, Trajectory, Stats) {
        let (model, traj, stats) = self.run.finish();
        let model = model.into_any().downcast::<M>();
        (
            *model.expect("the model the simulation was made with"),
            traj,
            stats,
        )
    }
}

impl Run {
    /// Validates everything, then starts (what [`Simulation::with_inputs`] does).
    pub(super) fn new<M: Model + 'static>(
        model: M,
        scheme: Scheme,
        options: Options,
        inputs: Inputs,
    ) -> Result<Run, SimError> {
        let names = Names::of(&model);
        validate(&model, &scheme, &options, &inputs)
            .map_err(|e| names.failure_at_start(e, options.t0, Stats::default()))?;
        let groups = 1 + M::SENSITIVITY_BLOCKS;
        Run::start(Box::new(model), names, scheme, options, inputs, groups)
    }

    /// From validated options: a consistent start, the scheme started on it, the outputs
    /// at t₀; `groups` those of the error norm (`Tolerances::groups`).
    fn start(
        model: Box<dyn OwnedModel>,
        names: Names,
        scheme: Scheme,
        options: Options,
        inputs: Inputs,
        groups: usize,
    ) -> Result<Run, SimError> {
        let early = |kind: Failure, stats: Stats| names.failure_at_start(kind, options.t0, stats);
        let (n, nc, nframes) = (model.nq(), model.nc(), model.nframes());
        let mut problem = Problem::new(model, options.iteration_matrix);
        problem.input_fn = inputs.function;
        let mut controllers: Vec<(f64, u64, Box<dyn Controller>)> = inputs
            .controllers
            .into_iter()
            .map(|(p, c)| (p, 0, c))
            .collect();
        if let Scheme::Bdf(p) = scheme {
            // the order history is counted per order: sized now, not while stepping
            problem.stats.order_steps = vec![0; p.max_order];
        }
        let mut cur = State::zeros(n, nc);
        let start = initial_state(&mut problem, &options, &mut cur)
            .and_then(|_| consistent_start(&mut problem, &scheme, &options, &mut cur))
            .and_then(|assembly| {
                first_sample(
                    &mut problem,
                    &mut controllers,
                    options.singularity_tol,
                    scheme.is_implicit(),
                    &mut cur,
                )?;
                Ok(assembly)
            });
        let assembly = start.map_err(|e| {
            let e = with_parameters_blamed(e, &mut problem, &options, 0.0);
            early(e, problem.stats.clone())
        })?;
        let ctl = control(&options, groups);
        let mut stepper = stepper_for(&scheme, n);
        if let Err(e) = stepper.start(&mut problem, &cur, &ctl) {
            let e = with_parameters_blamed(e, &mut problem, &options, 0.0);
            return Err(early(e, problem.stats.clone()));
        }
        if let Some(tol) = ctl.adaptive {
            problem.stats.error_test = stepper.error_test(&problem);
            problem.stats.tolerance_floor = stepper.tolerance_floor(tol.rtol);
            problem.stats.floor_from = floor_from(|r| stepper.tolerance_floor(r).is_some());
        }
        let h = match options.step {
            StepControl::Fixed { h } => h,
            StepControl::Adaptive { h0: Some(h0), .. } => h0,
            StepControl::Adaptive { rtol, atol, .. } => initial_step(
                &cur,
                Tolerances {
                    rtol,
                    atol,
                    groups: 1,
                },
                scheme.order(),
                StepBounds::of(&options),
                |t, q, qd, qdd| problem.accel(t, q, qd, qdd).is_ok(),
            ),
        };
        let mut traj = names.trajectory();
        let joints = problem.model.info().rotation_joints;
        traj.charts = (0..joints.len())
            .map(|j| vec![chart_quaternion(&problem.model.chart(j))])
            .collect();
        let expected = match &options.output {
            Output::Steps => 1024,
            Output::Last => 1,
            Output::Times(ts) => ts.len(),
            Output::Every { dt } => every_count(&options, *dt) + 1,
        };
        let bytes = expected.saturating_mul(traj.bytes_per_output(options.energy, options.frames));
        if bytes > MAX_OUTPUT_BYTES
            || traj
                .reserve(expected, options.energy, options.frames)
                .is_err()
        {
            let e = Failure::InvalidOption {
                name: "output",
                value: format!("{expected} outputs of {:.1} GB", bytes as f64 * 1e-9),
                reason: "take more memory than a trajectory may (8 GB): ask fewer (a larger `dt`, `Output::Times`), or `Output::Last` and read the motion with an observer",
            };
            return Err(early(e, problem.stats.clone()));
        }
        let out_times = output_times(&options);
        let held_counts = vec![0; n + cur.lambda.len()];
        let largest = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let start_scale = [largest(&cur.q), largest(&cur.qd)];
        let nu = problem.held.len();
        let mut sim = Run {
            start_scale,
            problem,
            stepper,
            scheme,
            ctl,
            next: cur.clone(),
            prev: cur.clone(),
            scratch: cur.clone(),
            cur,
            h: h.min(options.h_max()),
            attempts: 0,
            last_cause: None,
            held_by: None,
            first_rejection: None,
            observed_order: None,
            held_counts,
            traj,
            out_times,
            out_next: 0,
            poses: vec![Pose::default(); nframes],
            observers: Vec::new(),
            options,
            assembly,
            controllers,
            charts: vec![[[0.0; 3]; 3]; joints.len()],
            held_before: vec![0.0; nu],
            moved: Vec::with_capacity(joints.len()),
            chart_numbers: vec![0; joints.len()],
            last_quaternion: vec![None; joints.len()],
            orientations: Vec::with_capacity(4 * joints.len()),
        };
        sim.outputs_at_start();
        Ok(sim)
    }

    /// Outputs at t₀.
    fn outputs_at_start(&mut self) {
        match self.options.output {
            Output::Steps => self.record_cur(),
            Output::Last => {}
            _ => {
                while self.out_next < self.out_times.len()
                    && self.out_times[self.out_next] <= self.cur.t
                {
                    self.out_next += 1;
                    self.record_cur();
                }
            }
        }
    }

    /// The independent coordinates of coordinate partitioning, as they are now.
    fn independent_coordinates(&self) -> Vec<String> {
        match self.problem.loops.closed() {
            Some(c) if c.mode == Mode::Partitioning => c.independent_labels(),
            _ => Vec::new(),
        }
    }

    /// The model, the trajectory and the work counters (the final state recorded for
    /// `Output::Last`).
    pub(super) fn finish(mut self) -> (Box<dyn OwnedModel>, Trajectory, Stats) {
        if self.options.output == Output::Last && self.traj.is_empty() {
            self.record_cur();
        }
        self.problem.stats.user_efforts = self.problem.model.user_evaluations();
        self.problem.stats.held_most = self.held_most();
        (self.problem.model, self.traj, self.problem.stats)
    }

    fn record(&mut self, s: &State) {
        self.traj.push(s.t, &s.q, &s.qd, &s.qdd, &s.lambda);
        // u in force at the output; a non-finite input is recorded as it is (the evaluation
        // at that time stops the run with it)
        let _ = self.problem.inputs(s.t);
        self.traj.u_data.extend_from_slice(&self.problem.u);
        let model = &self.problem.model;
        let joints = model.info().rotation_joints;
        if !joints.is_empty() {
            self.orientations.clear();
            for (j, joint) in joints.iter().enumerate() {
                let u = charts::joint_rotation(&model.chart(j), joint, &s.q);
                let x = charts::quaternion_near(&u, self.last_quaternion[j]);
                self.last_quaternion[j] = Some(x);
                self.orientations.extend_from_slice(&x);
            }
            self.traj
                .push_joints(&self.orientations, &self.chart_numbers);
        }
        if self.options.energy {
            let e = self.problem.energy(s.t, &s.q, &s.qd);
            self.traj.energy.push(e);
        }
        if self.options.frames {
            self.problem.model.frames(s.t, &s.q, &mut self.poses);
            self.traj.poses.extend_from_slice(&self.poses);
        }
        for o in self.observers.iter_mut() {
            o.observe(s.t, &s.q, &s.qd, &s.qdd);
        }
    }

    fn record_cur(&mut self) {
        let s = std::mem::replace(&mut self.cur, State::zeros(0, 0));
        self.record(&s);
        self.cur = s;
    }

    /// The coordinate (its position or velocity) or multiplier whose error test held the most
    /// accepted steps, and how many.
    fn held_most(&self) -> Option<HeldMost> {
        let of: u32 = self.held_counts.iter().sum();
        let (i, &steps) = self
            .held_counts
            .iter()
            .enumerate()
            .max_by_key(|&(i, c)| (*c, std::cmp::Reverse(i)))?;
        let n = self.problem.n;
        (of > 0).then(|| HeldMost {
            component: if i < n {
                format!("{} (its position or velocity)", self.problem.label(i))
            } else {
                format!("λ[{}]", i - n)
            },
            steps: steps as usize,
            of: of as usize,
        })
    }

    fn fail(&mut self, kind: Failure, h: f64) -> SimError {
        // a first step that is not finite: what the parameters have to do with it
        let kind = if self.problem.stats.steps == 0 && h > 0.0 {
            with_parameters_blamed(kind, &mut self.problem, &self.options, h)
        } else {
            kind
        };
        // `Output::Last` records at the end: a run that fails keeps its last accepted state
        if self.options.output == Output::Last && self.traj.is_empty() {
            self.record_cur();
        }
        let mut stats = self.problem.stats.clone();
        stats.held_most = self.held_most();
        stats.user_efforts = self.problem.model.user_evaluations();
        SimError {
            kind,
            t: self.cur.t,
            h,
            stats: Box::new(stats),
            trajectory: Box::new(self.traj.clone()),
        }
    }

    /// Outputs in (prev.t, cur.t] after an accepted step (at cur.t only `with_cur`).
    fn outputs_after_step(&mut self, with_cur: bool) {
        match self.options.output {
            Output::Steps if with_cur => self.record_cur(),
            Output::Steps | Output::Last => {}
            _ => {
                while self.out_next < self.out_times.len()
                    && (self.out_times[self.out_next] < self.cur.t
                        || with_cur && self.out_times[self.out_next] == self.cur.t)
                {
                    let t = self.out_times[self.out_next];
                    self.out_next += 1;
                    let mut s = std::mem::replace(&mut self.scratch, State::zeros(0, 0));
                    if t == self.cur.t {
                        s.copy_from(&self.cur);
                    } else {
                        self.stepper.interpolate(&self.prev, &self.cur, t, &mut s);
                    }
                    self.record(&s);
                    self.scratch = s;
                }
            }
        }
    }

    /// The outputs at the current state's time, after a sample held them back
    /// (`outputs_after_step` without them).
    fn outputs_at_cur(&mut self) {
        match self.options.output {
            Output::Steps => self.record_cur(),
            Output::Last => {}
            _ => {
                while self.out_next < self.out_times.len()
                    && self.out_times[self.out_next] == self.cur.t
                {
                    self.out_next += 1;
                    let mut s = std::mem::replace(&mut self.scratch, State::zeros(0, 0));
                    s.copy_from(&self.cur);
                    self.record(&s);
                    self.scratch = s;
                }
            }
        }
    }

    /// After an accepted step: re-centres the charts of the rotation joints whose |cos b|
    /// fell below `Options::chart_switch`, maps the state (its accelerations too) and lets
    /// the scheme carry on from it with its step.
    fn recentre(&mut self) -> Result<(), Failure> {
        let threshold = self.options.chart_switch;
        if threshold == 0.0 || self.chart_numbers.is_empty() {
            return Ok(());
        }
        let cur = &mut self.cur;
        let evaluate = charts::recentre_below_erased(
            self.problem.model.erased_mut(),
            threshold,
            [&mut cur.q, &mut cur.qd],
            Some(&mut cur.qdd),
            &mut self.moved,
        );
        if self.moved.is_empty() {
            return Ok(());
        }
        // the state is in the new charts from here on, whatever follows: its rows say so
        for r in &self.moved {
            self.traj.charts[r.joint].push(chart_quaternion(&r.chart));
            self.chart_numbers[r.joint] = (self.traj.charts[r.joint].len() - 1) as u32;
        }
        if evaluate {
            // the model's own coordinates (a wrapper's) need their accelerations anew
            self.problem.chart_changed();
            let (q, qd) = (std::mem::take(&mut cur.q), std::mem::take(&mut cur.qd));
            let r = self.problem.accel(cur.t, &q, &qd, &mut cur.qdd);
            (cur.q, cur.qd) = (q, qd);
            r?;
            if let Some(c) = self.problem.loops.closed() {
                cur.lambda.copy_from_slice(&c.lambda);
            }
        }
        self.problem.stats.chart_switches += self.moved.len();
        self.problem.chart_changed();
        self.stepper.rechart(
            &mut self.problem,
            &self.cur,
            &self.ctl,
            &self.moved,
            evaluate,
        )
    }

    /// The next sample instant of any controller (infinite without).
    fn next_sample(&self) -> f64 {
        let t0 = self.options.t0;
        self.controllers
            .iter()
            .map(|(p, k, _)| t0 + *k as f64 * p)
            .fold(f64::INFINITY, f64::min)
    }

    /// At a sample instant: the due controllers write their outputs, then qdd and λ of the
    /// current state are computed again and the scheme restarts from it.
    fn sample(&mut self) -> Result<(), Failure> {
        let (t0, t) = (self.options.t0, self.cur.t);
        let mut any = false;
        charts::read_charts_erased(self.problem.model.erased(), &mut self.charts);
        for (p, k, c) in self.controllers.iter_mut() {
            let due = t0 + *k as f64 * *p;
            if due <= t + 1e-12 * t.abs().max(1.0) {
                c.sample_in_charts(t, &self.cur, &self.charts, &mut self.problem.held);
                *k += 1;
                self.problem.stats.samples += 1;
                any = true;
            }
        }
        if !any {
            return Ok(());
        }
        self.problem.inputs_changed();
        self.problem
            .accel(t, &self.cur.q, &self.cur.qd, &mut self.cur.qdd)?;
        if let Some(c) = self.problem.loops.closed() {
            self.cur.lambda.copy_from_slice(&c.lambda);
        }
        self.stepper.start(&mut self.problem, &self.cur, &self.ctl)
    }

    fn step_until(&mut self, t_stop: f64) -> Result<(), SimError> {
        // controllers are sampled exactly at their instants
        let t_stop = t_stop.min(self.next_sample());
        loop {
            let plan = self.plan(t_stop)?;
            let step = Step(
                &mut self.problem,
                &self.cur,
                plan.h,
                &self.ctl,
                &mut self.next,
            );
            let result = self.stepper.attempt(step);
            if self.conclude(plan, result)? {
                return Ok(());
            }
        }
    }

    /// The scheme's floor when its local error test held it rather than what rtol asked, with
    /// the loosest rtol that holds it.
    fn floored(&self) -> Option<Box<FlooredTolerance>> {
        let stats = &self.problem.stats;
        Some(Box::new(FlooredTolerance {
            floor: stats.tolerance_floor?,
            from: stats.floor_from?,
        }))
    }

    /// The next attempt towards `t_stop`: its size, landing on t_stop exactly, counted; the
    /// run's failure when it has no steps left or the step fell below h_min.
    pub(super) fn plan(&mut self, t_stop: f64) -> Result<Planned, SimError> {
        // the floor of adaptive steps, at the time this step starts (a fixed step is never
        // judged by it: its size is the user's, checked against the resolution of t up front)
        let h_min = self.options.h_min_at(self.cur.t);
        let fixed = matches!(self.options.step, StepControl::Fixed { .. });
        if self.attempts >= self.options.max_steps {
            let max_steps = self.options.max_steps;
            // a scheme that found the problem stiff says so (DOPRI5's detection)
            let kind = match self.problem.stats.stiff_from {
                Some(t) => Failure::LikelyStiff {
                    scheme: self.scheme.name(),
                    t,
                    max_steps,
                    held_most: self.held_most(),
                },
                None => Failure::TooMuchWork {
                    max_steps,
                    held_most: self.held_most(),
                    cause: OutOfSteps::of(
                        self.scheme.name(),
                        match self.options.step {
                            StepControl::Fixed { h } => {
                                let span = (self.options.t_end - self.options.t0).abs();
                                Some((span / h - 1e-9).ceil().max(1.0) as u64)
                            }
                            _ => None,
                        },
                    ),
                    floored: self.floored(),
                },
            };
            return Err(self.fail(kind, self.h));
        }
        let remaining = t_stop - self.cur.t;
        let h_max = self.options.h_max();
        let mut h = self.h.min(h_max);
        // the rounding of t, in steps, beside a part in 10⁹ of a step
        let slack = grid_slack(self.options.t0, self.cur.t.abs().max(t_stop.abs()), h);
        let t_next = if fixed {
            // fixed steps stay on the grid t0 + k h, whatever the rounding of sums
            let k = ((self.cur.t - self.options.t0) / h + slack).floor();
            self.options.t0 + (k + 1.0) * h
        } else {
            self.cur.t + h
        };
        // land on t_stop exactly, without leaving a sliver of a step behind (nor a step
        // longer than h_max)
        let last = t_next >= t_stop - slack * h
            || (!fixed && h > 0.5 * remaining && remaining - h < 0.1 * h && remaining <= h_max);
        if last {
            h = remaining;
        } else if fixed {
            h = t_next - self.cur.t;
        }
        if h < h_min && !last && !fixed {
            // the cause of the rejections that shrank the step, when there is one
            let held_by = self
                .held_by
                .map(|b| Box::new(b.held_by(|i| self.problem.label(i), self.start_scale)));
            // an order below 1.5 observed close by: forces that jump, or switch with the
            // state, which no step resolves
            let jump = self.observed_order.and_then(|(t, order)| {
                (near(t, self.cur.t) && (-0.5..JUMP_ORDER).contains(&order)).then_some(order)
            });
            let kind = self.last_cause.take().unwrap_or(Failure::StepTooSmall {
                h_min,
                held_by,
                given: self.options.h_min.is_some(),
                jump,
                near_change_point: self.near_change_point(),
            });
            return Err(self.fail(kind, h));
        }
        self.attempts += 1;
        Ok(Planned {
            h,
            last,
            t_next,
            t_stop,
            h_min,
            fixed,
        })
    }

    /// What the attempt `plan` gave: true when accepted (the run moved on, outputs recorded),
    /// false when rejected (the next attempt's size set), the run's failure otherwise.
    pub(super) fn conclude(
        &mut self,
        plan: Planned,
        result: Result<Attempt, Failure>,
    ) -> Result<bool, SimError> {
        let Planned {
            h,
            last,
            t_next,
            t_stop,
            h_min,
            fixed,
        } = plan;
        match result {
            // a trial state the user's efforts rejected: retried smaller while it can be
            Err(kind @ Failure::EffortRejected { .. }) if !fixed && h > h_min => {
                self.problem.stats.rejected_effort += 1;
                self.last_cause = Some(kind);
                self.held_by = None;
                self.h = (0.25 * h).max(h_min);
            }
            Err(kind) => return Err(self.fail(kind, h)),
            Ok(Attempt::Accepted { h_next }) => {
                let test = self.stepper.last_test();
                if test.floored {
                    self.problem.stats.floored_steps += 1;
                }
                if let Some(b) = test.held_by {
                    let n = self.problem.n;
                    // a coordinate's position and velocity together, then the multipliers
                    let i = if b.block < 2 { b.index } else { n + b.index };
                    if let Some(c) = self.held_counts.get_mut(i) {
                        *c += 1;
                    }
                }
                self.next.t = if last {
                    t_stop
                } else if fixed {
                    t_next
                } else {
                    self.cur.t + h
                };
                if let Err(kind) = self
                    .problem
                    .after_step(&mut self.next)
                    .and_then(|_| self.check_next())
                {
                    return Err(self.fail(kind, h));
                }
                self.problem.stats.record_step(h);
                self.problem.stats.user_efforts = self.problem.model.user_evaluations();
                self.last_cause = None;
                // the test that chose the next step: named if that step falls below h_min
                self.held_by = test.held_by;
                self.prev.copy_from(&self.cur);
                std::mem::swap(&mut self.cur, &mut self.next);
                self.stepper
                    .accepted(&mut self.problem, &self.prev, &self.cur);
                // at a sample time the state's row waits for the new inputs: its qdd and λ
                // are those of u_k, as at the start (inputs hold from their sample on)
                let sampling = self.cur.t == t_stop && !self.controllers.is_empty();
                self.outputs_after_step(!sampling);
                if let Err(kind) = self.recentre() {
                    return Err(self.fail(kind, h));
                }
                if sampling {
                    // the accepted state as it was, kept in the attempt's buffer: a sample
                    // that fails leaves the state's row as the step made it
                    self.next.copy_from(&self.cur);
                    self.held_before.clone_from(&self.problem.held);
                    if let Err(kind) = self.sample() {
                        // ... and with the inputs it was made under
                        self.cur.copy_from(&self.next);
                        self.problem.held.clone_from(&self.held_before);
                        self.problem.inputs_changed();
                        self.outputs_at_cur();
                        return Err(self.fail(kind, h));
                    }
                    self.outputs_at_cur();
                }
                if !fixed {
                    // a shortened last step says nothing about the next one
                    self.h = if last {
                        self.h.max(h_next.min(self.h * 5.0))
                    } else {
                        h_next
                    };
                }
                return Ok(true);
            }
            Ok(Attempt::RejectedError { h_next }) => {
                // only adaptive schemes test errors
                self.problem.stats.rejected_error += 1;
                let test = self.stepper.last_test();
                self.held_by = test.held_by;
                // rejections from about one t: the order at which the error fell with h
                let t = self.cur.t;
                match self.first_rejection {
                    Some((t1, h1, e1)) if near(t1, t) => {
                        let e = test.value;
                        if h * 4.0 <= h1 && e1 > 0.0 && e > 0.0 {
                            self.observed_order = Some((t, (e1 / e).ln() / (h1 / h).ln()));
                        }
                    }
                    _ => self.first_rejection = Some((t, h, test.value)),
                }
                self.h = h_next;
            }
            Ok(Attempt::RejectedNewton {
                h_next,
                iterations,
                correction,
                cause,
            }) => {
                self.problem.stats.rejected_newton += 1;
                if matches!(cause, Some(Failure::EffortRejected { .. })) {
                    self.problem.stats.rejected_effort += 1;
                }
                // a user effort's own error does not go away with a smaller step (a
                // singular configuration met by a trial iterate may, and so may a state
                // the efforts rejected: the step shrinks, and the failure is reported if
                // it collapses)
                let fatal = matches!(
                    cause,
                    Some(Failure::UserEffort { .. })
                        | Some(Failure::NonFinite {
                            quantity: "user effort",
                            ..
                        })
                );
                if fixed || h <= h_min || fatal {
                    let largest = self
                        .stepper
                        .newton_largest()
                        .map(|(block, i)| component_name(block, i, |j| self.problem.label(j)));
                    let kind = cause.unwrap_or(Failure::NewtonDiverged {
                        iterations,
                        correction,
                        largest,
                        fixed,
                        near_change_point: self.near_change_point(),
                    });
                    return Err(self.fail(kind, h));
                }
                self.last_cause = cause;
                self.held_by = None;
                self.h = h_next.max(h_min);
            }
        }
        Ok(false)
    }

    /// The closed loops near a change point, for a step that failed at h_min.
    fn near_change_point(&self) -> Option<crate::error::NearChangePoint> {
        self.problem.loops.closed()?.near_change_point()
    }

    fn check_next(&self) -> Result<(), Failure> {
        self.problem.check("q", &self.next.q)?;
        self.problem.check("qd", &self.next.qd)?;
        self.problem.check("qdd", &self.next.qdd)?;
        Failure::non_finite("λ", &self.next.lambda, |i| {
            format!(
                "of constraint `{}`",
                self.problem.model.info().constraints[i]
            )
        })
    }
}

impl Run {
    fn step(&mut self) -> Result<(), SimError> {
        if self.cur.t >= self.options.t_end {
            return Ok(());
        }
        let t_end = self.options.t_end;
        self.step_until(t_end)
    }

    fn integrate_to(&mut self, t: f64) -> Result<(), SimError> {
        let t = t.min(self.options.t_end);
        while self.cur.t < t {
            self.step_until(t)?;
        }
        Ok(())
    }
}

impl<M: Model + 'static> Integrator for Simulation<M> {
    fn step(&mut self) -> Result<(), SimError> {
        self.run.step()
    }

    fn integrate_to(&mut self, t: f64) -> Result<(), SimError> {
        self.run.integrate_to(t)
    }

    fn state(&self) -> &State {
        &self.run.cur
    }

    fn stats(&self) -> &Stats {
        &self.run.problem.stats
    }

    fn trajectory(&self) -> &Trajectory {
        &self.run.traj
    }
}

/// The names a trajectory carries: coordinates, frames, constraints.
/// A request refused before any work: `kind` at t₀, with an empty trajectory of the model's
/// names.
pub(crate) fn refused<M: Model>(model: &M, kind: Failure, t0: f64) -> SimError {
    Names::of(model).failure_at_start(kind, t0, Stats::default())
}

struct Names {
    dofs: Vec<String>,
    frames: Vec<String>,
    constraints: Vec<String>,
    inputs: Vec<String>,
    /// rotation joints, by the frame each moves
    joints: Vec<String>,
}

impl Names {
    fn of<M: Model>(model: &M) -> Names {
        let info = model.info();
        let own = |v: &[&str]| v.iter().map(|s| s.to_string()).collect();
        Names {
            dofs: own(info.dofs),
            frames: own(info.frames),
            constraints: own(info.constraints),
            inputs: own(info.inputs),
            joints: info
                .rotation_joints
                .iter()
                .map(|j| info.frames[j.frame].to_string())
                .collect(),
        }
    }

    fn trajectory(&self) -> Trajectory {
        let mut t = Trajectory::new(
            self.dofs.clone(),
            self.frames.clone(),
            self.constraints.clone(),
        );
        t.joint_names = self.joints.clone();
        t.input_names = self.inputs.clone();
        t
    }

    /// A failure before the first step: at t₀, with an empty trajectory.
    fn failure_at_start(&self, kind: Failure, t0: f64, stats: Stats) -> SimError {
        SimError {
            kind,
            t: t0,
            h: 0.0,
            stats: Box::new(stats),
            trajectory: Box::new(self.trajectory()),
        }
    }
}

/// The options against the scheme and the model, the parameters, and the inputs against the
/// model.
fn validate<M: Model>(
    model: &M,
    scheme: &Scheme,
    options: &Options,
    inputs: &Inputs,
) -> Result<(), Failure> {
    options.validate(scheme, M::NQ, model.info().has_tangents)?;
    crate::model::Parameters::validate(model.params()).map_err(Failure::InvalidParameters)?;
    let driven = inputs.function.is_some() || !inputs.controllers.is_empty();
    if driven && M::NU == 0 {
        return Err(Failure::InvalidOption {
            name: "inputs",
            value: format!("{} controllers", inputs.controllers.len()),
            reason: "the model has no inputs u: use `u[k]` in its forces, torques or generalised forces",
        });
    }
    if let Some((p, _)) = inputs
        .controllers
        .iter()
        .find(|(p, _)| !(*p > 0.0) || !p.is_finite())
    {
        return Err(Failure::InvalidOption {
            name: "controller period",
            value: p.to_string(),
            reason: "must be > 0 and finite",
        });
    }
    let t_far = options.t0.abs().max(options.t_end.abs());
    if let Some((p, _)) =
        (inputs.controllers.iter()).find(|(p, _)| *p < 64.0 * f64::EPSILON * t_far)
    {
        return Err(Failure::InvalidOption {
            name: "controller period",
            value: format!("{p} (with t_end = {})", options.t_end),
            reason: "is below the resolution of time there (64 ε·|t|): samples that close would not move t; take a longer period",
        });
    }
    Ok(())
}

/// t₀ and the given or declared q₀, qd₀ into `cur`, checked finite.
fn initial_state(problem: &mut Problem, options: &Options, cur: &mut State) -> Result<(), Failure> {
    cur.t = options.t0;
    given_or_declared(problem.model.erased(), options, &mut cur.q, &mut cur.qd);
    problem.check("q0", &cur.q)?;
    problem.check("qd0", &cur.qd)?;
    // a rotation joint that starts near gimbal lock starts in a chart centred on it
    if options.chart_switch > 0.0 {
        let mut moved = Vec::new();
        charts::recentre_below_erased(
            problem.model.erased_mut(),
            options.chart_switch,
            [&mut cur.q, &mut cur.qd],
            None,
            &mut moved,
        );
        problem.stats.chart_switches += moved.len();
    }
    Ok(())
}

/// A start, or a first step of size `step` (0 for the start), that is not finite, or a mass
/// matrix singular at the start, with what the parameters have to do with it: those that,
/// set back to their default alone, make it finite (the initial state, or the one the options
/// give, M and h there, and for a step the state a Taylor step of that size reaches,
/// q + h qd + h²/2 qdd, and M and h there) or M regular (its Cholesky factorisation), or that
/// they are all at their defaults, so that it is an expression of the model (or the state
/// given) that is not defined there. Other failures unchanged.
fn with_parameters_blamed(
    e: Failure,
    problem: &mut Problem,
    options: &Options,
    step: f64,
) -> Failure {
    let singular_mass = matches!(
        &e,
        Failure::SingularMatrix { matrix: "the mass matrix M", cause, .. } if cause.is_empty() && step == 0.0
    );
    let non_finite = matches!(
        &e,
        Failure::NonFinite { quantity, cause, .. } if cause.is_empty() && *quantity != "input"
    );
    if !singular_mass && !non_finite {
        return e;
    }
    let n = problem.model.nq();
    let u = problem.held.clone();
    let t0 = options.t0;
    let mut holds = |m: &dyn ErasedModel| {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
        given_or_declared(m, options, &mut q, &mut qd);
        let (mut mass, mut h) = (vec![0.0; n * n], vec![0.0; n]);
        m.dynamics(t0, &q, &qd, &u, &mut mass, &mut h);
        let mut ok = finite(&q) && finite(&qd) && finite(&mass) && finite(&h);
        if ok && singular_mass {
            ok = crate::linalg::cholesky(&mut mass, n).is_ok();
        }
        if ok && step > 0.0 {
            let (mut qdd, mut pivots) = (vec![0.0; n], vec![0.0; n]);
            m.forward_dynamics(t0, &q, &qd, &u, &mut qdd, &mut pivots);
            for i in 0..n {
                q[i] += step * qd[i] + 0.5 * step * step * qdd[i];
                qd[i] += step * qdd[i];
            }
            m.dynamics(t0 + step, &q, &qd, &u, &mut mass, &mut h);
            ok = finite(&qdd) && finite(&q) && finite(&qd) && finite(&mass) && finite(&h);
        }
        // an evaluation that failed in a model's Rust efforts left its failure to be taken
        ok && m.take_failure().is_none()
    };
    let (found, all_default) = problem.model.defaults_for_which(&mut holds);
    let what = match (singular_mass, step > 0.0) {
        (true, _) => "M is regular at the start",
        (false, true) => "a first step of that size is finite",
        (false, false) => "the start is finite",
    };
    let at = if step > 0.0 {
        "a first step of that size"
    } else {
        "the start"
    };
    let text = if !found.is_empty() {
        crate::model::blamed_parameters(&found, what)
    } else if singular_mass {
        // a singular M with the parameters at their defaults is the coordinates' doing:
        // the failure's own text says so
        String::new()
    } else if all_default && (options.q0.is_some() || options.qd0.is_some()) {
        format!(
            "; every parameter is at its default: the start given in Options::q0 or qd0 makes {at} not finite, or an expression of the model is not defined there (a square root of a negative, a division by zero)"
        )
    } else if all_default {
        format!(
            "; every parameter is at its default: an expression of the model is not defined at {at} (a square root of a negative, a division by zero)"
        )
    } else {
        String::new()
    };
    let mut e = e;
    if let Failure::NonFinite { cause, .. } | Failure::SingularMatrix { cause, .. } = &mut e {
        *cause = text;
    }
    e
}

/// The start's q₀ and qd₀: those `options` give, else those `m` declares.
fn given_or_declared(m: &dyn ErasedModel, options: &Options, q: &mut [f64], qd: &mut [f64]) {
    m.initial_state(q, qd);
    if let Some(q0) = &options.q0 {
        q.copy_from_slice(q0);
    }
    if let Some(qd0) = &options.qd0 {
        qd.copy_from_slice(qd0);
    }
}

/// A chart (rows of a rotation matrix) as a quaternion `[x, y, z, w]`, w ≥ 0.
fn chart_quaternion(c: &[[f64; 3]; 3]) -> [f64; 4] {
    let m = nalgebra::Matrix3::from_fn(|r, k| c[r][k]);
    charts::quaternion_near(&charts::rotation_of(&m), None)
}

/// A constrained model: the constraint method, the assembly of q₀ and qd₀, the partition
/// when partitioning; the model's constraints are then set in `problem`.
fn consistent_start(
    problem: &mut Problem,
    scheme: &Scheme,
    options: &Options,
    cur: &mut State,
) -> Result<Option<Assembly>, Failure> {
    if problem.model.nc() == 0 {
        return Ok(None);
    }
    let oc = &options.constraints;
    let adaptive = matches!(options.step, StepControl::Adaptive { .. });
    let mode = constraint_mode(oc.method, scheme, adaptive)?;
    let a = assemble_erased(problem.model.erased(), cur.t, &mut cur.q, &mut cur.qd, oc)?;
    problem
        .model
        .complete_start(cur.t, &mut cur.q, &mut cur.qd)?;
    let mut c = Constrained::new(problem.model.erased(), mode, oc);
    if mode == Mode::Partitioning {
        c.eval_b(problem.model.erased(), &mut problem.stats, cur.t, &cur.q);
        let marks = problem.model.info().independent;
        let marked = marks.iter().any(|&m| m);
        c.choose_partition(marked.then_some(marks), &mut problem.stats);
    }
    problem.loops = Loops::Closed(Box::new(c));
    Ok(Some(a))
}

/// The controllers' first sample on the consistent positions and velocities (with their qdd
/// and λ under no inputs yet, as a later sample sees those under the inputs before it), then
/// qdd₀ (and λ₀) there; singular configurations are judged against the factor of M found now.
fn first_sample(
    problem: &mut Problem,
    controllers: &mut [(f64, u64, Box<dyn Controller>)],
    singularity_tol: f64,
    implicit: bool,
    cur: &mut State,
) -> Result<(), Failure> {
    let mut charts = Vec::new();
    charts::read_charts_erased(problem.model.erased(), &mut charts);
    if !controllers.is_empty() {
        // the controllers see the state as at their later samples: its qdd and λ under the
        // inputs held before them (none yet: u = 0, or the input function alone)
        problem.accel(cur.t, &cur.q.clone(), &cur.qd.clone(), &mut cur.qdd)?;
        if let Some(c) = problem.loops.closed() {
            cur.lambda.copy_from_slice(&c.lambda);
        }
    }
    for (_, count, c) in controllers.iter_mut() {
        c.sample_in_charts(cur.t, cur, &charts, &mut problem.held);
        *count = 1;
        problem.stats.samples += 1;
    }
    problem.inputs_changed();
    problem.accel(cur.t, &cur.q.clone(), &cur.qd.clone(), &mut cur.qdd)?;
    problem.watch_from_start(singularity_tol, cur.t, &cur.q, implicit)?;
    if let Some(c) = problem.loops.closed() {
        cur.lambda.copy_from_slice(&c.lambda);
    }
    Ok(())
}

/// Step control and Newton settings from the options; `groups` those of the error norm (the
/// motion, and each parameter's sensitivities).
fn control(options: &Options, groups: usize) -> Control {
    let newton = NewtonTol {
        atol: options.newton.atol,
        rtol: options.newton.rtol,
        kappa: 1.0,
        max_iterations: options.newton.max_iterations,
        reuse: options.newton.reuse,
        keep_below: options.newton.keep_below,
        follows_motion: true,
    };
    let (adaptive, newton) = match options.step {
        StepControl::Fixed { .. } => (None, newton),
        StepControl::Adaptive { rtol, atol, .. } => (
            Some(Tolerances { rtol, atol, groups }),
            NewtonTol {
                atol,
                rtol,
                kappa: options.newton.tolerance_factor,
                follows_motion: false,
                ..newton
            },
        ),
    };
    Control {
        adaptive,
        newton,
        stability_check: options.stability_check,
    }
}

/// One attempt as [`Run::plan`] made it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Planned {
    /// its size
    pub h: f64,
    /// whether it lands on `t_stop`
    last: bool,
    /// where a fixed step lands on its grid
    t_next: f64,
    t_stop: f64,
    h_min: f64,
    fixed: bool,
}

/// The most memory the outputs asked for may take, 8 GB: beyond it the request is refused
/// before the run rather than ending it without a word when memory runs out.
const MAX_OUTPUT_BYTES: usize = 8_000_000_000;

/// The whole intervals `dt` from t0 to t_end (the outputs of `Output::Every` less one).
fn every_count(options: &Options, dt: f64) -> usize {
    let slack = grid_slack(options.t0, options.t_end.abs(), dt);
    ((options.t_end - options.t0) / dt + slack).floor() as usize
}

/// How far (in steps of `h`) a time of size `t` computed on the grid t0 + k h may fall short
/// of its grid point: a part in 10⁹ of a step, and the rounding of t and t0 in steps. The
/// part in 10⁹ alone was below one rounding of t once t/h passed 10⁷: from t0 = 1000 at
/// h = 1e-5, the step reached t0 + h, counted as t0 + 0.99999999748 h, and planned its next
/// grid point there, a step of zero length, again and again.
fn grid_slack(t0: f64, t: f64, h: f64) -> f64 {
    1e-9 + 8.0 * f64::EPSILON * (t0.abs() + t) / h
}

/// The output instants of `Output::Every` and `Output::Times` (none for the others).
fn output_times(options: &Options) -> Vec<f64> {
    match &options.output {
        Output::Times(ts) => ts.clone(),
        Output::Every { dt } => {
            // the last may round past t_end (0.1 · 3 = 0.30000000000000004 > 0.3): it is
            // t_end's output, which the run reaches exactly
            let k = every_count(options, *dt);
            (0..=k)
                .map(|i| (options.t0 + i as f64 * dt).min(options.t_end))
                .collect()
        }
        Output::Steps | Output::Last => Vec::new(),
    }
}

/// The loosest rtol at which a scheme's local error test holds its floor (`held`), `None`
/// when it holds none from 0.5 down to 1e-16: halving rtol from 0.5 finds the first held,
/// then bisecting (in log rtol) to a part in 10⁶ its edge (the schemes' maps of rtol grow
/// with it; the Newmark family's holds no floor for an rtol below the floor itself).
fn floor_from(held: impl Fn(f64) -> bool) -> Option<f64> {
    let mut hi = 0.5;
    while !held(hi / 2.0) {
        hi /= 2.0;
        if hi < 1e-16 {
            return None;
        }
    }
    let mut lo = hi / 2.0;
    while hi / lo > 1.0 + 1e-6 {
        let mid = (lo * hi).sqrt();
        if held(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(lo)
}
