//! Integration of `M(q,t) qdd = h(q, qd, t)` with the scheme the user picks. One driver
//! ([`Simulation`], the [`Integrator`] trait) runs every scheme: it validates options, starts
//! consistently (qdd(0) from M qdd = h), chooses steps, samples outputs, and turns every
//! failure into a typed [`SimError`] that keeps the trajectory computed so far. Schemes live
//! one per file and implement the internal `Stepper` trait.
//!
//! | scheme | file | order | steps |
//! |---|---|---|---|
//! | explicit Euler, RK4 | `explicit.rs` | 1, 4 | fixed (with a stability check) |
//! | Dormand–Prince 5(4) | `dopri5.rs` | 5 | adaptive or fixed, dense output |
//! | Newmark, HHT-α, generalized-α | `newmark.rs` | 2 | fixed or adaptive |
//! | implicit midpoint | `midpoint.rs` | 2 | fixed |
//! | BDF 1–5 | `bdf.rs` | 1–5 | adaptive, variable order |
//! | Radau IIA 3, 5 | `radau/` | 3, 5 | adaptive or fixed |

mod bdf;
pub(crate) mod constrained;
mod dopri5;
mod explicit;
mod midpoint;
mod newmark;
pub(crate) mod newton;
pub(crate) mod problem;
mod radau;

pub use constrained::{Assembly, assemble};
pub use newmark::index3_iteration_matrix;

use crate::error::{Failure, SimError};
use crate::model::{Model, Pose};
use crate::options::{ConstraintMethod, Options, Output, Scheme, StepControl};
use crate::stats::Stats;
use crate::trajectory::{Observer, Trajectory};
use constrained::{Constrained, Mode};
use newton::NewtonTol;
use problem::Problem;

/// A state of the motion.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub t: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    /// accelerations consistent with M qdd = h (or the scheme's own at this step)
    pub qdd: Vec<f64>,
    /// Lagrange multipliers of the constraints, one per named constraint (empty without)
    pub lambda: Vec<f64>,
}

impl State {
    pub(crate) fn zeros(n: usize, nc: usize) -> State {
        State {
            t: 0.0,
            q: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            lambda: vec![0.0; nc],
        }
    }

    pub(crate) fn copy_from(&mut self, o: &State) {
        self.t = o.t;
        self.q.copy_from_slice(&o.q);
        self.qd.copy_from_slice(&o.qd);
        self.qdd.copy_from_slice(&o.qdd);
        self.lambda.copy_from_slice(&o.lambda);
    }
}

/// One integrator interface for every scheme.
pub trait Integrator {
    /// Advances by one accepted step (retrying rejected attempts); records outputs it passes.
    fn step(&mut self) -> Result<(), SimError>;
    /// Advances until `t` (≤ t_end), recording outputs on the way.
    fn integrate_to(&mut self, t: f64) -> Result<(), SimError>;
    /// The current state.
    fn state(&self) -> &State;
    /// Work so far.
    fn stats(&self) -> &Stats;
    /// Outputs so far.
    fn trajectory(&self) -> &Trajectory;
}

/// What one attempted step gave.
pub(crate) enum Attempt {
    /// `next` holds the state at t + h
    Accepted { h_next: f64 },
    /// the local error test failed
    RejectedError { h_next: f64 },
    /// Newton did not converge (or an evaluation failed inside the step)
    RejectedNewton {
        h_next: f64,
        iterations: usize,
        correction: f64,
        cause: Option<Failure>,
    },
}

/// Step control and Newton settings handed to the schemes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Control {
    /// (rtol, atol) when adaptive
    pub adaptive: Option<(f64, f64)>,
    pub newton: NewtonTol,
    /// explicit fixed-step schemes check h·ρ against their stability region
    pub stability_check: bool,
}

impl Control {
    /// Weighted RMS norm of an error vector e against the state scales y0, y1:
    /// sqrt(mean (e_i / (atol + rtol·max(|y0_i|, |y1_i|)))²).
    pub fn error_norm(&self, e: &[f64], y0: &[f64], y1: &[f64]) -> f64 {
        let (rtol, atol) = self.adaptive.unwrap_or((1.0, 1.0));
        let mut s = 0.0;
        for i in 0..e.len() {
            let w = atol + rtol * y0[i].abs().max(y1[i].abs());
            s += (e[i] / w) * (e[i] / w);
        }
        (s / e.len().max(1) as f64).sqrt()
    }
}

/// Next step from an error norm (≤ 1 accepted) of a method whose error estimate is of order
/// `order` (local error ∝ h^(order+1)): h·min(fmax, max(0.2, 0.9·err^(−1/(order+1)))).
pub(crate) fn next_step(h: f64, err: f64, order: usize, fmax: f64) -> f64 {
    let fac = if err == 0.0 {
        fmax
    } else {
        (0.9 * err.powf(-1.0 / (order as f64 + 1.0))).clamp(0.2, fmax)
    };
    h * fac
}

/// A scheme, as the driver sees it.
pub(crate) trait Stepper<M: Model> {
    /// Called once with the consistent initial state.
    fn start(&mut self, _p: &mut Problem<M>, _s: &State, _ctl: &Control) -> Result<(), Failure> {
        Ok(())
    }
    /// Attempts a step of size `h` from `cur`; on acceptance fills `next`.
    fn attempt(
        &mut self,
        p: &mut Problem<M>,
        cur: &State,
        h: f64,
        ctl: &Control,
        next: &mut State,
    ) -> Result<Attempt, Failure>;
    /// Called once the driver has accepted the step from `prev` to `cur`.
    fn accepted(&mut self, _p: &mut Problem<M>, _prev: &State, _cur: &State) {}
    /// Dense output on [prev.t, cur.t]: by default the quintic Hermite interpolant of
    /// (q, qd, qdd) at both ends, accurate beyond every scheme's order here.
    fn interpolate(&self, prev: &State, cur: &State, t: f64, out: &mut State) {
        hermite5(prev, cur, t, out);
    }
}

/// Quintic Hermite interpolation of q between two states (qd and qdd from its derivatives).
pub(crate) fn hermite5(s0: &State, s1: &State, t: f64, out: &mut State) {
    let h = s1.t - s0.t;
    out.t = t;
    if h == 0.0 {
        out.copy_from(s1);
        return;
    }
    let s = (t - s0.t) / h;
    let (s2, s3, s4, s5) = (s * s, s * s * s, s * s * s * s, s * s * s * s * s);
    // basis and its first and second derivatives in s
    let b = [
        1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5,
        s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5,
        0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5,
        0.5 * s3 - s4 + 0.5 * s5,
        -4.0 * s3 + 7.0 * s4 - 3.0 * s5,
        10.0 * s3 - 15.0 * s4 + 6.0 * s5,
    ];
    let d = [
        -30.0 * s2 + 60.0 * s3 - 30.0 * s4,
        1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4,
        s - 4.5 * s2 + 6.0 * s3 - 2.5 * s4,
        1.5 * s2 - 4.0 * s3 + 2.5 * s4,
        -12.0 * s2 + 28.0 * s3 - 15.0 * s4,
        30.0 * s2 - 60.0 * s3 + 30.0 * s4,
    ];
    let dd = [
        -60.0 * s + 180.0 * s2 - 120.0 * s3,
        -36.0 * s + 96.0 * s2 - 60.0 * s3,
        1.0 - 9.0 * s + 18.0 * s2 - 10.0 * s3,
        3.0 * s - 12.0 * s2 + 10.0 * s3,
        -24.0 * s + 84.0 * s2 - 60.0 * s3,
        60.0 * s - 180.0 * s2 + 120.0 * s3,
    ];
    for i in 0..s0.q.len() {
        let c = [
            s0.q[i],
            h * s0.qd[i],
            h * h * s0.qdd[i],
            h * h * s1.qdd[i],
            h * s1.qd[i],
            s1.q[i],
        ];
        let dot = |w: &[f64; 6]| w.iter().zip(&c).map(|(a, b)| a * b).sum::<f64>();
        out.q[i] = dot(&b);
        out.qd[i] = dot(&d) / h;
        out.qdd[i] = dot(&dd) / (h * h);
    }
    lerp_lambda(s0, s1, t, out);
}

/// λ between two states: linear (the states carry no derivative of λ).
pub(crate) fn lerp_lambda(s0: &State, s1: &State, t: f64, out: &mut State) {
    let h = s1.t - s0.t;
    let s = if h == 0.0 { 1.0 } else { (t - s0.t) / h };
    for i in 0..s0.lambda.len() {
        out.lambda[i] = (1.0 - s) * s0.lambda[i] + s * s1.lambda[i];
    }
}

/// u(t), written into its argument.
pub(crate) type InputFn = Box<dyn FnMut(f64, &mut [f64])>;

/// A controller sampled every period: it reads the state at the sample instant and writes
/// the inputs it drives into `u`, held until its next sample (zero-order hold).
pub trait Controller {
    fn sample(&mut self, t: f64, state: &State, u: &mut [f64]);
}

impl<F: FnMut(f64, &State, &mut [f64])> Controller for F {
    fn sample(&mut self, t: f64, state: &State, u: &mut [f64]) {
        self(t, state, u)
    }
}

/// What drives a model's inputs u: a function of time and sampled controllers. At every
/// evaluation u = (the function's value) + (the outputs the controllers hold, zero until
/// they write them). The integrators stop exactly at every sample instant t₀ + k·T, call the
/// controllers there, and restart from that state (a held output jumps: multistep histories
/// and predictors do not survive it).
#[derive(Default)]
pub struct Inputs {
    function: Option<InputFn>,
    controllers: Vec<(f64, Box<dyn Controller>)>,
}

impl Inputs {
    pub fn new() -> Inputs {
        Inputs::default()
    }

    /// u(t) (it adds to the controllers' outputs).
    pub fn function(mut self, f: impl FnMut(f64, &mut [f64]) + 'static) -> Inputs {
        self.function = Some(Box::new(f));
        self
    }

    /// A controller sampled every `period` seconds from t₀.
    pub fn controller(mut self, period: f64, c: impl Controller + 'static) -> Inputs {
        self.controllers.push((period, Box::new(c)));
        self
    }
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
    let t_end = sim.options.t_end;
    sim.integrate_to(t_end)?;
    Ok(sim.finish())
}

/// A running simulation: the model, the scheme, the state, the outputs and the work done.
pub struct Simulation<M: Model> {
    problem: Problem<M>,
    stepper: Box<dyn Stepper<M>>,
    scheme: Scheme,
    options: Options,
    ctl: Control,
    cur: State,
    next: State,
    prev: State,
    scratch: State,
    h: f64,
    attempts: usize,
    /// why the last attempt was rejected, when an evaluation failed (reported if h collapses)
    last_cause: Option<Failure>,
    traj: Trajectory,
    /// pending output times (for `Output::Every` and `Times`), next one first
    out_times: Vec<f64>,
    out_next: usize,
    poses: Vec<Pose>,
    observers: Vec<Box<dyn Observer>>,
    assembly: Option<Assembly>,
    /// sampled controllers: period, samples taken, the controller
    controllers: Vec<(f64, u64, Box<dyn Controller>)>,
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
        let n = M::NQ;
        let info = model.info();
        let dof_names: Vec<String> = info.dofs.iter().map(|s| s.to_string()).collect();
        let frame_names: Vec<String> = info.frames.iter().map(|s| s.to_string()).collect();
        let constraint_names: Vec<String> =
            info.constraints.iter().map(|s| s.to_string()).collect();
        let new_traj = || {
            Trajectory::new(
                dof_names.clone(),
                frame_names.clone(),
                constraint_names.clone(),
            )
        };
        let early = |kind: Failure, stats: Stats| SimError {
            kind,
            t: options.t0,
            h: 0.0,
            stats: Box::new(stats),
            trajectory: Box::new(new_traj()),
        };
        if let Err(e) = options.validate(&scheme, n, info.has_tangents) {
            return Err(early(e, Stats::default()));
        }
        if let Err(e) = crate::model::Parameters::validate(model.params()) {
            return Err(early(Failure::InvalidParameters(e), Stats::default()));
        }
        let driven = inputs.function.is_some() || !inputs.controllers.is_empty();
        if driven && M::NU == 0 {
            return Err(early(
                Failure::InvalidOption {
                    name: "inputs",
                    value: format!("{} controllers", inputs.controllers.len()),
                    reason: "the model has no inputs u: use `u[k]` in its forces, torques or generalised forces",
                },
                Stats::default(),
            ));
        }
        if let Some((p, _)) = inputs
            .controllers
            .iter()
            .find(|(p, _)| !(*p > 0.0) || !p.is_finite())
        {
            return Err(early(
                Failure::InvalidOption {
                    name: "controller period",
                    value: p.to_string(),
                    reason: "must be > 0 and finite",
                },
                Stats::default(),
            ));
        }
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
        let mut cur = State::zeros(n, M::NC);
        cur.t = options.t0;
        problem.model.initial_state(&mut cur.q, &mut cur.qd);
        if let Some(q0) = &options.q0 {
            cur.q.copy_from_slice(q0);
        }
        if let Some(qd0) = &options.qd0 {
            cur.qd.copy_from_slice(qd0);
        }
        let start = problem
            .check("q0", &cur.q)
            .and_then(|_| problem.check("qd0", &cur.qd));
        if let Err(e) = start {
            return Err(early(e, problem.stats.clone()));
        }
        let mut assembly = None;
        if M::NC > 0 {
            // consistent start: assembly, velocities, then qdd₀ and λ₀ of the index-1 form
            let oc = &options.constraints;
            let adaptive = matches!(options.step, StepControl::Adaptive { .. });
            let start = constraint_mode(oc.method, &scheme, adaptive).and_then(|mode| {
                let a = assemble(&problem.model, cur.t, &mut cur.q, &mut cur.qd, oc)?;
                let mut c = Constrained::new(&problem.model, mode, oc);
                if mode == Mode::Partitioning {
                    c.eval_b(&problem.model, &mut problem.stats, cur.t, &cur.q);
                    let marks = problem.model.info().independent;
                    let marked = marks.iter().any(|&m| m);
                    c.choose_partition(marked.then_some(marks), &mut problem.stats);
                }
                problem.con = Some(c);
                Ok(a)
            });
            match start {
                Ok(a) => assembly = Some(a),
                Err(e) => return Err(early(e, problem.stats.clone())),
            }
        }
        // the controllers' first sample, on the consistent positions and velocities
        for (_, count, c) in controllers.iter_mut() {
            c.sample(cur.t, &cur, &mut problem.held);
            *count = 1;
            problem.stats.samples += 1;
        }
        problem.inputs_changed();
        let start = problem.accel(cur.t, &cur.q.clone(), &cur.qd.clone(), &mut cur.qdd);
        if let Err(e) = start {
            return Err(early(e, problem.stats.clone()));
        }
        // singular configurations are judged against the factor of M at the start
        problem.watch_from_start(options.singularity_tol);
        if let Some(c) = &problem.con {
            cur.lambda.copy_from_slice(&c.lambda);
        }
        let newton = NewtonTol {
            atol: options.newton.atol,
            rtol: options.newton.rtol,
            kappa: 1.0,
            max_iterations: options.newton.max_iterations,
            reuse: options.newton.reuse,
        };
        let (adaptive, newton) = match options.step {
            StepControl::Fixed { .. } => (None, newton),
            StepControl::Adaptive { rtol, atol, .. } => (
                Some((rtol, atol)),
                NewtonTol {
                    atol,
                    rtol,
                    kappa: options.newton.tolerance_factor,
                    ..newton
                },
            ),
        };
        let ctl = Control {
            adaptive,
            newton,
            stability_check: options.stability_check,
        };
        let mut stepper = stepper_for::<M>(&scheme, n);
        if let Err(e) = stepper.start(&mut problem, &cur, &ctl) {
            return Err(early(e, problem.stats.clone()));
        }
        let h = match options.step {
            StepControl::Fixed { h } => h,
            StepControl::Adaptive { h0: Some(h0), .. } => h0,
            StepControl::Adaptive { rtol, atol, .. } => {
                initial_step(&mut problem, &cur, rtol, atol, scheme.order(), &options)
            }
        };
        let out_times: Vec<f64> = match &options.output {
            Output::Times(ts) => ts.clone(),
            Output::Every { dt } => {
                let k = ((options.t_end - options.t0) / dt + 1e-9).floor() as usize;
                (0..=k).map(|i| options.t0 + i as f64 * dt).collect()
            }
            Output::Steps | Output::Last => Vec::new(),
        };
        let mut traj = new_traj();
        let expected = match &options.output {
            Output::Steps => 1024,
            Output::Last => 1,
            _ => out_times.len(),
        };
        traj.reserve(expected, options.energy, options.frames);
        let nf = M::NFRAMES;
        let mut sim = Simulation {
            problem,
            stepper,
            scheme,
            ctl,
            next: cur.clone(),
            prev: cur.clone(),
            scratch: cur.clone(),
            cur,
            h: h.min(options.h_max),
            attempts: 0,
            last_cause: None,
            traj,
            out_times,
            out_next: 0,
            poses: vec![Pose::default(); nf],
            observers: Vec::new(),
            options,
            assembly,
            controllers,
        };
        // outputs at t0
        match sim.options.output {
            Output::Steps => sim.record_cur(),
            Output::Last => {}
            _ => {
                while sim.out_next < sim.out_times.len() && sim.out_times[sim.out_next] <= sim.cur.t
                {
                    sim.out_next += 1;
                    sim.record_cur();
                }
            }
        }
        Ok(sim)
    }

    /// Adds an observer that sees every output as it is recorded.
    pub fn observe(&mut self, o: impl Observer + 'static) {
        self.observers.push(Box::new(o));
    }

    /// The scheme.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.problem.model
    }

    /// How the start was made consistent (constrained models only): residuals before and
    /// after, iterations, the largest change.
    pub fn assembly(&self) -> Option<&Assembly> {
        self.assembly.as_ref()
    }

    /// The independent coordinates of coordinate partitioning, as they are now (empty for
    /// other methods).
    pub fn independent_coordinates(&self) -> Vec<String> {
        match &self.problem.con {
            Some(c) if c.mode == Mode::Partitioning => c.independent_labels(),
            _ => Vec::new(),
        }
    }

    /// The step the next attempt will use.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// Hands the outputs recorded since the last call to `sink`, then forgets them: a long run
    /// written to disk as it goes keeps flat memory (a later failure's trajectory holds only
    /// the outputs recorded after this call).
    pub fn drain_outputs<R>(&mut self, sink: impl FnOnce(&Trajectory) -> R) -> R {
        let r = sink(&self.traj);
        self.traj.clear_outputs();
        r
    }

    /// Trajectory and work counters (records the final state for `Output::Last`).
    pub fn finish(mut self) -> (Trajectory, Stats) {
        if self.options.output == Output::Last && self.traj.is_empty() {
            self.record_cur();
        }
        self.problem.stats.user_efforts = self.problem.model.user_evaluations();
        (self.traj, self.problem.stats)
    }

    fn record(&mut self, s: &State) {
        self.traj.push(s.t, &s.q, &s.qd, &s.qdd, &s.lambda);
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

    fn fail(&self, kind: Failure, h: f64) -> SimError {
        let mut stats = self.problem.stats.clone();
        stats.user_efforts = self.problem.model.user_evaluations();
        SimError {
            kind,
            t: self.cur.t,
            h,
            stats: Box::new(stats),
            trajectory: Box::new(self.traj.clone()),
        }
    }

    /// Outputs in (prev.t, cur.t] after an accepted step.
    fn outputs_after_step(&mut self) {
        match self.options.output {
            Output::Steps => self.record_cur(),
            Output::Last => {}
            _ => {
                while self.out_next < self.out_times.len()
                    && self.out_times[self.out_next] <= self.cur.t
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
        for (p, k, c) in self.controllers.iter_mut() {
            let due = t0 + *k as f64 * *p;
            if due <= t + 1e-12 * t.abs().max(1.0) {
                c.sample(t, &self.cur, &mut self.problem.held);
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
        if let Some(c) = &self.problem.con {
            self.cur.lambda.copy_from_slice(&c.lambda);
        }
        self.stepper.start(&mut self.problem, &self.cur, &self.ctl)
    }

    fn step_until(&mut self, t_stop: f64) -> Result<(), SimError> {
        let h_min = self.options.h_min();
        let fixed = matches!(self.options.step, StepControl::Fixed { .. });
        // controllers are sampled exactly at their instants
        let t_stop = t_stop.min(self.next_sample());
        loop {
            if self.attempts >= self.options.max_steps {
                return Err(self.fail(
                    Failure::TooMuchWork {
                        max_steps: self.options.max_steps,
                    },
                    self.h,
                ));
            }
            let remaining = t_stop - self.cur.t;
            let mut h = self.h.min(self.options.h_max);
            let t_next = if fixed {
                // fixed steps stay on the grid t0 + k h, whatever the rounding of sums
                let k = ((self.cur.t - self.options.t0) / h + 1e-9).floor();
                self.options.t0 + (k + 1.0) * h
            } else {
                self.cur.t + h
            };
            // land on t_stop exactly, without leaving a sliver of a step behind
            let last = t_next >= t_stop - 1e-9 * h
                || (!fixed && h > 0.5 * remaining && remaining - h < 0.1 * h);
            if last {
                h = remaining;
            } else if fixed {
                h = t_next - self.cur.t;
            }
            if h < h_min && !last {
                // the cause of the rejections that shrank the step, when there is one
                let kind = self
                    .last_cause
                    .take()
                    .unwrap_or(Failure::StepTooSmall { h_min });
                return Err(self.fail(kind, h));
            }
            self.attempts += 1;
            let result =
                self.stepper
                    .attempt(&mut self.problem, &self.cur, h, &self.ctl, &mut self.next);
            match result {
                Err(kind) => return Err(self.fail(kind, h)),
                Ok(Attempt::Accepted { h_next }) => {
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
                    self.prev.copy_from(&self.cur);
                    std::mem::swap(&mut self.cur, &mut self.next);
                    self.stepper
                        .accepted(&mut self.problem, &self.prev, &self.cur);
                    self.outputs_after_step();
                    if self.cur.t == t_stop && !self.controllers.is_empty() {
                        if let Err(kind) = self.sample() {
                            return Err(self.fail(kind, h));
                        }
                    }
                    if !fixed {
                        // a shortened last step says nothing about the next one
                        self.h = if last {
                            self.h.max(h_next.min(self.h * 5.0))
                        } else {
                            h_next
                        };
                    }
                    return Ok(());
                }
                Ok(Attempt::RejectedError { h_next }) => {
                    // only adaptive schemes test errors
                    self.problem.stats.rejected_error += 1;
                    self.h = h_next;
                }
                Ok(Attempt::RejectedNewton {
                    h_next,
                    iterations,
                    correction,
                    cause,
                }) => {
                    self.problem.stats.rejected_newton += 1;
                    // a user effort's own error does not go away with a smaller step (a
                    // singular configuration met by a trial iterate may: the step shrinks,
                    // and the failure is reported if it collapses)
                    let fatal = matches!(
                        cause,
                        Some(Failure::UserEffort { .. })
                            | Some(Failure::NonFinite {
                                quantity: "user effort",
                                ..
                            })
                    );
                    if fixed || h <= h_min || fatal {
                        let kind = cause.unwrap_or(Failure::NewtonDiverged {
                            iterations,
                            correction,
                        });
                        return Err(self.fail(kind, h));
                    }
                    self.last_cause = cause;
                    self.h = h_next.max(h_min);
                }
            }
        }
    }

    fn check_next(&self) -> Result<(), Failure> {
        self.problem.check("q", &self.next.q)?;
        self.problem.check("qd", &self.next.qd)?;
        self.problem.check("qdd", &self.next.qdd)?;
        match self.next.lambda.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(i) => Err(Failure::NonFinite {
                quantity: "λ",
                coordinate: format!(
                    "of constraint `{}`",
                    self.problem.model.info().constraints[i]
                ),
            }),
        }
    }
}

impl<M: Model + 'static> Integrator for Simulation<M> {
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

    fn state(&self) -> &State {
        &self.cur
    }

    fn stats(&self) -> &Stats {
        &self.problem.stats
    }

    fn trajectory(&self) -> &Trajectory {
        &self.traj
    }
}

/// First step of adaptive schemes (Hairer, Nørsett & Wanner, II.4): from the sizes of y, f
/// and of f's change over a trial Euler step.
fn initial_step<M: Model>(
    p: &mut Problem<M>,
    s: &State,
    rtol: f64,
    atol: f64,
    order: usize,
    o: &Options,
) -> f64 {
    let n = s.q.len();
    let w = |y: f64| atol + rtol * y.abs();
    let norm = |a: &[f64], b: &[f64], ya: &[f64], yb: &[f64]| {
        let ss: f64 = (0..n)
            .map(|i| (a[i] / w(ya[i])).powi(2) + (b[i] / w(yb[i])).powi(2))
            .sum();
        (ss / (2 * n).max(1) as f64).sqrt()
    };
    let d0 = norm(&s.q, &s.qd, &s.q, &s.qd);
    let d1 = norm(&s.qd, &s.qdd, &s.q, &s.qd);
    let mut h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    h0 = h0.min(o.t_end - o.t0).min(o.h_max);
    let q1: Vec<f64> = (0..n).map(|i| s.q[i] + h0 * s.qd[i]).collect();
    let v1: Vec<f64> = (0..n).map(|i| s.qd[i] + h0 * s.qdd[i]).collect();
    let mut a1 = vec![0.0; n];
    if p.accel(s.t + h0, &q1, &v1, &mut a1).is_err() {
        return h0;
    }
    let dv: Vec<f64> = (0..n).map(|i| (v1[i] - s.qd[i]) / h0).collect();
    let da: Vec<f64> = (0..n).map(|i| (a1[i] - s.qdd[i]) / h0).collect();
    let d2 = norm(&dv, &da, &s.q, &s.qd);
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / (order as f64 + 1.0))
    };
    (100.0 * h0)
        .min(h1)
        .min(o.t_end - o.t0)
        .min(o.h_max)
        .max(o.h_min())
}

/// The constraint method a scheme runs: `Auto` resolved, unsupported pairs refused.
fn constraint_mode(
    method: ConstraintMethod,
    scheme: &Scheme,
    adaptive: bool,
) -> Result<Mode, Failure> {
    // without numerical damping, index 3 and step control do not go together
    let no_damping = scheme.spectral_radius_at_infinity() == Some(1.0);
    let undamped = adaptive && no_damping;
    Ok(match method {
        // the damped members of the Newmark family by default, Radau only on request; the
        // undamped ones (trapezoidal Newmark, ρ∞ = 1) diverge at index 3 on fast loops even
        // at fixed steps (slider-crank at h ≥ 1 ms: `examples/work_precision.rs`)
        ConstraintMethod::Auto if scheme.spectral_radius_at_infinity().is_some() && !no_damping => {
            Mode::Index3
        }
        ConstraintMethod::Auto | ConstraintMethod::Projection => Mode::Projection,
        ConstraintMethod::Index3 if !scheme.solves_index3() => {
            return Err(Failure::ConstraintsUnsupported {
                scheme: scheme.name(),
                method: "index 3",
                supported: INDEX3_SCHEMES,
            });
        }
        ConstraintMethod::Index3 if undamped => {
            return Err(Failure::ConstraintsUnsupported {
                scheme: scheme.name(),
                method: "index 3 with adaptive steps",
                supported: "without numerical damping (ρ∞ = 1) the multipliers λ and the accelerations oscillate from step to step at index 3 (Cardona & Géradin 1989), which defeats the error estimate: use gen-alpha with ρ∞ < 1 or hht, fixed steps, or Projection",
            });
        }
        ConstraintMethod::Index3 => Mode::Index3,
        ConstraintMethod::Baumgarte { alpha, beta } => Mode::Baumgarte { alpha, beta },
        ConstraintMethod::Partitioning => Mode::Partitioning,
    })
}

/// The schemes that solve the index-3 equations, for messages.
const INDEX3_SCHEMES: &str = "index-3 constraints are solved by gen-alpha, hht, newmark, radau3 and radau5; every scheme takes them with Projection, Baumgarte or Partitioning";

fn stepper_for<M: Model>(scheme: &Scheme, n: usize) -> Box<dyn Stepper<M>> {
    match *scheme {
        Scheme::ExplicitEuler => Box::new(explicit::Explicit::euler(n)),
        Scheme::Rk4 => Box::new(explicit::Explicit::rk4(n)),
        Scheme::Dopri5 => Box::new(dopri5::Dopri5::new(n)),
        Scheme::Newmark(p) => Box::new(newmark::AlphaFamily::newmark(n, p)),
        Scheme::Hht(p) => Box::new(newmark::AlphaFamily::hht(n, p)),
        Scheme::GenAlpha(p) => Box::new(newmark::AlphaFamily::gen_alpha(n, p)),
        Scheme::ImplicitMidpoint => Box::new(midpoint::Midpoint::new(n)),
        Scheme::Bdf(p) => Box::new(bdf::Bdf::new(n, p.max_order)),
        Scheme::Radau3 => Box::new(radau::Radau::radau3(n)),
        Scheme::Radau5 => Box::new(radau::Radau::radau5(n)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quintic_hermite_reproduces_quintics() {
        let f = |t: f64| {
            (
                1.0 - 2.0 * t + 0.5 * t * t - t.powi(3) + 0.25 * t.powi(4) - 0.1 * t.powi(5),
                -2.0 + t - 3.0 * t * t + t.powi(3) - 0.5 * t.powi(4),
                1.0 - 6.0 * t + 3.0 * t * t - 2.0 * t.powi(3),
            )
        };
        let st = |t: f64| {
            let (q, v, a) = f(t);
            State {
                t,
                q: vec![q],
                qd: vec![v],
                qdd: vec![a],
                lambda: vec![],
            }
        };
        let (s0, s1) = (st(0.3), st(1.1));
        let mut out = State::zeros(1, 0);
        for t in [0.3, 0.5, 0.77, 1.1] {
            hermite5(&s0, &s1, t, &mut out);
            let (q, v, a) = f(t);
            assert!(
                (out.q[0] - q).abs() < 1e-13
                    && (out.qd[0] - v).abs() < 1e-12
                    && (out.qdd[0] - a).abs() < 1e-11
            );
        }
    }
}
