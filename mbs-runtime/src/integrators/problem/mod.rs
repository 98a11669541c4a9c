//! The model as the schemes see it: evaluations counted, results checked (a non-finite value
//! is named by its coordinate), forward dynamics (generated, or by Cholesky), residuals τ,
//! and iteration matrices M + γ'·C_t + β'·K_t, all on buffers allocated once.
//!
//! A constrained model run by a method other than index 3 is, for the schemes, the ODE
//! qdd = f(t, q, qd) of its index-1 form (projection, Baumgarte, partitioning): `accel` is f,
//! the residual is a − f, and the iteration matrices are those of that ODE (M = I,
//! C_t = −∂f/∂qd, K_t = −∂f/∂q), by forward differences of f whatever `iteration` says (the
//! generated tangents are those of τ, not of f); `MassOnly` keeps I alone.
//!
//! Here: evaluation (inputs, checks, accelerations, residuals); `watch.rs`: singular
//! configurations and matrices; `index1.rs`: the index-1 ODE and its finite-difference
//! matrices; `matrices.rs`: iteration matrices and tangents of τ; `projection.rs`: what
//! follows an accepted step of a constrained model.

mod index1;
mod matrices;
pub(crate) use matrices::model_error_reason;
mod projection;
mod watch;

use super::constrained::Constrained;
use crate::erased::OwnedModel;
use crate::error::Failure;
use crate::linalg::{PIVOT_FLOOR, cholesky, cholesky_solve};
use crate::options::IterationMatrix;
use crate::stats::Stats;
use watch::{worst_pivot, worst_pivot_of};

pub(crate) struct Problem {
    pub model: Box<dyn OwnedModel>,
    pub n: usize,
    /// inputs u at the time of the last evaluation: the time function's value plus the
    /// outputs the sampled controllers hold
    pub u: Vec<f64>,
    /// u(t), when given
    pub input_fn: Option<super::InputFn>,
    /// the outputs of the sampled controllers (held between samples)
    pub held: Vec<f64>,
    u_fn: Vec<f64>,
    /// the time `u` holds the inputs of (NaN: to compute)
    u_t: f64,
    pub stats: Stats,
    /// how iteration matrices are built (never `Auto` here)
    pub iteration: IterationMatrix,
    /// `Options::singularity_tol` (0 until the start is made: no watch before)
    pub singularity_tol: f64,
    /// the Cholesky pivots L_jj² of M and its diagonal at the start
    start_pivots: Vec<f64>,
    start_diagonal: Vec<f64>,
    /// whether M qdd = h is solved by the generated forward dynamics (open loops, a model
    /// that has them), the pivots of its last solve and of the solve at the start
    forward: bool,
    pivots: Vec<f64>,
    start_forward: Vec<f64>,
    /// M factorised only to watch its conditioning (implicit schemes)
    mchk: Vec<f64>,
    labels: Vec<String>,
    m: Vec<f64>,
    chol: Vec<f64>,
    h: Vec<f64>,
    k: Vec<f64>,
    c: Vec<f64>,
    tau0: Vec<f64>,
    tau1: Vec<f64>,
    qp: Vec<f64>,
    vp: Vec<f64>,
    ap: Vec<f64>,
    /// open or closed loops, and how closed ones are treated
    pub loops: Loops,
    /// the point f is evaluated at (completed when partitioning), f, and scratch
    qx: Vec<f64>,
    vx: Vec<f64>,
    fa: Vec<f64>,
    fb: Vec<f64>,
    dx: Vec<f64>,
    /// the last index-1 evaluation: (t, q, qd) → (qdd, λ)
    cache_valid: bool,
    cache_t: f64,
    cache_q: Vec<f64>,
    cache_v: Vec<f64>,
    cache_a: Vec<f64>,
    cache_l: Vec<f64>,
}

/// Whether the model's loops are closed, and when they are, the constraints with what the
/// constrained code needs (the method, B, Φ, λ and their buffers).
#[derive(Default)]
pub(crate) enum Loops {
    /// no constraints
    #[default]
    Open,
    Closed(Box<Constrained>),
}

impl Loops {
    /// The constraints when closed.
    pub fn closed(&self) -> Option<&Constrained> {
        match self {
            Loops::Open => None,
            Loops::Closed(c) => Some(c),
        }
    }

    /// The constraints when closed, to work on.
    pub fn closed_mut(&mut self) -> Option<&mut Constrained> {
        match self {
            Loops::Open => None,
            Loops::Closed(c) => Some(c),
        }
    }
}

impl Problem {
    pub fn new(model: Box<dyn OwnedModel>, iteration: IterationMatrix) -> Problem {
        // a failure of user code in evaluations before the run (an analysis's trial states,
        // the caller's own calls) is not this run's
        let _ = model.take_failure();
        let (n, nu, nc) = (model.nq(), model.nu(), model.nc());
        let forward = model.forward_dynamics_generated();
        let info = model.info();
        let labels = (0..n).map(|i| info.dof_label(i)).collect();
        let iteration = match iteration {
            IterationMatrix::Auto if info.has_tangents => IterationMatrix::Exact,
            IterationMatrix::Auto => IterationMatrix::FiniteDifferences,
            other => other,
        };
        let z = || vec![0.0; n];
        Problem {
            model,
            n,
            u: vec![0.0; nu],
            input_fn: None,
            held: vec![0.0; nu],
            u_fn: vec![0.0; nu],
            u_t: f64::NAN,
            stats: Stats::default(),
            iteration,
            singularity_tol: 0.0,
            start_pivots: z(),
            start_diagonal: z(),
            forward,
            pivots: z(),
            start_forward: z(),
            mchk: vec![0.0; n * n],
            labels,
            m: vec![0.0; n * n],
            chol: vec![0.0; n * n],
            h: z(),
            k: vec![0.0; n * n],
            c: vec![0.0; n * n],
            tau0: z(),
            tau1: z(),
            qp: z(),
            vp: z(),
            ap: z(),
            loops: Loops::Open,
            qx: z(),
            vx: z(),
            fa: z(),
            fb: z(),
            dx: z(),
            cache_valid: false,
            cache_t: f64::NAN,
            cache_q: z(),
            cache_v: z(),
            cache_a: z(),
            cache_l: vec![0.0; nc],
        }
    }

    /// u at time t: the input function (if any) plus the held controller outputs.
    fn inputs_at(&mut self, t: f64) -> Result<(), Failure> {
        if self.u.is_empty() || self.u_t == t {
            return Ok(());
        }
        self.u_t = t;
        self.u.copy_from_slice(&self.held);
        if let Some(f) = self.input_fn.as_mut() {
            self.u_fn.fill(0.0);
            f(t, &mut self.u_fn);
            for (u, x) in self.u.iter_mut().zip(&self.u_fn) {
                *u += x;
            }
        }
        match self.u.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(i) => {
                self.u_t = f64::NAN;
                Err(Failure::NonFinite {
                    quantity: "input",
                    coordinate: format!("u[{i}] at t = {t}"),
                    cause: String::new(),
                })
            }
        }
    }

    /// The held controller outputs changed: u and the cached index-1 solution are stale.
    pub fn inputs_changed(&mut self) {
        self.u_t = f64::NAN;
        self.cache_valid = false;
    }

    /// The chart of a rotation joint moved: the same coordinates now mean another
    /// configuration, so nothing evaluated before is reused.
    pub fn chart_changed(&mut self) {
        self.cache_valid = false;
    }

    /// Name of coordinate `i` for messages: `q[3]` or `q[3] (knee)`.
    pub fn label(&self, i: usize) -> String {
        self.labels[i].clone()
    }

    /// The first non-finite entry of `v`, as a failure naming its coordinate and the vector
    /// in words (`h` is the generalized force, not the step).
    pub fn check(&self, quantity: &'static str, v: &[f64]) -> Result<(), Failure> {
        // user code reports its own failure first (a NaN it caused is only its symptom)
        if let Some(f) = self.model.take_failure() {
            return Err(f);
        }
        Failure::non_finite(quantity_name(quantity), v, |i| self.label(i % self.n))
    }

    /// qdd from M qdd = h at (t, q, qd); for a constrained model, qdd and λ (in the
    /// constraints' `lambda`) of the index-1 equations, after completing the dependent
    /// coordinates when partitioning.
    pub fn accel(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &mut [f64]) -> Result<(), Failure> {
        match std::mem::take(&mut self.loops) {
            Loops::Open => self.plain_accel(t, q, qd, qdd),
            Loops::Closed(mut c) => {
                let r = self.closed_accel(&mut c, t, q, qd, qdd);
                self.loops = Loops::Closed(c);
                r
            }
        }
    }

    /// Checks the M and h just evaluated at (t, q), factorises M into `chol` and watches its
    /// pivots: what every solve of M qdd = h starts with.
    pub(super) fn factorise_mass(&mut self, t: f64, q: &[f64]) -> Result<(), Failure> {
        self.check("h", &self.h)?;
        self.check("M", &self.m)?;
        self.chol.copy_from_slice(&self.m);
        self.stats.factorizations += 1;
        cholesky(&mut self.chol, self.n).map_err(|s| self.singular_mass(&self.chol, s))?;
        if self.watching() {
            let (ratio, j) = worst_pivot(&self.chol, self.n, &self.start_pivots);
            self.judge(ratio, j, t, q)?;
        }
        Ok(())
    }

    /// qdd of an open-loop model: by its generated forward dynamics when it has them, their
    /// pivots watched against those at the start; by M, h and a dense Cholesky factorisation
    /// otherwise, and whenever the forward solve gives a pivot not above `PIVOT_FLOOR` of the
    /// largest (the dense Cholesky's test) or a value that is not finite (a failure path: the dense
    /// path names the coordinate).
    fn plain_accel(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
    ) -> Result<(), Failure> {
        self.inputs_at(t)?;
        if self.forward {
            self.model
                .forward_dynamics(t, q, qd, &self.u, qdd, &mut self.pivots);
            if self.forward_holds(t, q, qdd)? {
                return Ok(());
            }
        }
        self.dense_accel(t, q, qd, qdd)
    }

    /// Counts the forward dynamics just evaluated into `qdd` and `self.pivots` and judges
    /// them: true when they stand (finite, every pivot above `PIVOT_FLOOR` of the largest,
    /// the configuration watched against the start), false when the dense path must decide.
    fn forward_holds(&mut self, t: f64, q: &[f64], qdd: &[f64]) -> Result<bool, Failure> {
        self.stats.forward_dynamics += 1;
        if let Some(f) = self.model.take_failure() {
            return Err(f);
        }
        // the dense Cholesky's test, against the largest pivot
        let scale = self.pivots.iter().fold(0.0f64, |m, p| m.max(*p));
        let positive = self.pivots.iter().all(|p| *p > PIVOT_FLOOR * scale) && scale.is_finite();
        if positive && qdd.iter().all(|a| a.is_finite()) {
            // the watch's ratios p/p₀ only where some pivot is near its tolerance: clear of
            // it by a margin above rounding, p ≥ tol·p₀ says so without a division per pivot
            let tol = self.singularity_tol * (1.0 + 1e-12);
            let clear = (self.pivots.iter().zip(&self.start_forward))
                .fold(true, |ok, (p, p0)| ok & (*p >= tol * p0));
            if self.watching() && !clear {
                let (ratio, j) = worst_pivot_of(self.pivots.iter().copied(), &self.start_forward);
                self.judge(ratio, j, t, q)?;
            }
            return Ok(true);
        }
        Ok(false)
    }

    /// M, h and a dense Cholesky factorisation: qdd of an open-loop model, its failures named.
    fn dense_accel(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
    ) -> Result<(), Failure> {
        self.model
            .dynamics(t, q, qd, &self.u, &mut self.m, &mut self.h);
        self.stats.dynamics += 1;
        self.factorise_mass(t, q)?;
        qdd.copy_from_slice(&self.h);
        cholesky_solve(&self.chol, self.n, qdd);
        self.stats.solves += 1;
        self.check("qdd", qdd)
    }

    /// The inputs u at time t (a function's value and the held outputs), for an evaluation
    /// made outside ([`Problem::accept_forward`]).
    pub fn inputs(&mut self, t: f64) -> Result<&[f64], Failure> {
        self.inputs_at(t)?;
        Ok(&self.u)
    }

    /// What [`Problem::accel`] makes of forward dynamics evaluated outside, at (t, q, qd) with
    /// [`Problem::inputs`] (`qdd` and `pivots` as the model's forward dynamics gave them: an
    /// ensemble's lanes): counted, checked and watched the same way; where they do not
    /// stand, or the model has no generated forward dynamics, `qdd` is computed here by the
    /// dense path, which names the failure. An open-loop model only.
    pub fn accept_forward(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
        pivots: &[f64],
    ) -> Result<(), Failure> {
        self.inputs_at(t)?;
        if self.forward {
            self.pivots.copy_from_slice(pivots);
            if self.forward_holds(t, q, qdd)? {
                return Ok(());
            }
        }
        self.dense_accel(t, q, qd, qdd)
    }

    /// The residual τ(t, q, qd, qdd) = M qdd − h.
    pub fn residual(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        r: &mut [f64],
    ) -> Result<(), Failure> {
        self.inputs_at(t)?;
        if self.ode() {
            // the index-1 ODE: a − f(t, q, qd)
            self.f_into_fa(t, q, qd)?;
            for i in 0..self.n {
                r[i] = qdd[i] - self.fa[i];
            }
            return Ok(());
        }
        self.model.inverse_dynamics(t, q, qd, qdd, &self.u, r);
        self.stats.inverse_dynamics += 1;
        self.check("τ", r)
    }

    /// Evaluations for one output: energy, and poses when asked for.
    pub fn energy(&mut self, t: f64, q: &[f64], qd: &[f64]) -> crate::model::Energy {
        self.stats.energy += 1;
        self.model.energy(t, q, qd)
    }
}

/// The words a message uses for a vector the evaluations check: the symbol alone is
/// ambiguous (`h` is the generalized force in M qdd = h, and the step in every message about
/// steps).
fn quantity_name(symbol: &'static str) -> &'static str {
    match symbol {
        "h" => "generalized force h",
        "M" => "mass matrix M",
        "q" => "position q",
        "qd" => "velocity qd",
        "qdd" => "acceleration qdd",
        "q0" => "initial position q0",
        "qd0" => "initial velocity qd0",
        "τ" => "inverse-dynamics residual τ = M qdd − h",
        "C_t" => "damping tangent C_t",
        "K_t" => "stiffness tangent K_t",
        other => other,
    }
}
