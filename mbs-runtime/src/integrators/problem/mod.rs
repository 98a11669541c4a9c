//! The model as the schemes see it: evaluations counted, results checked (a non-finite value
//! is named by its coordinate), forward dynamics by Cholesky, residuals τ, and iteration
//! matrices M + γ'·C_t + β'·K_t, all on buffers allocated once.
//!
//! A constrained model run by a method other than index 3 is, for the schemes, the ODE
//! qdd = f(t, q, qd) of its index-1 form (projection, Baumgarte, partitioning): `accel` is f,
//! the residual is a − f, and the iteration matrices are those of that ODE (M = I,
//! C_t = −∂f/∂qd, K_t = −∂f/∂q), by forward differences of f whatever `iteration` says (the
//! generated tangents are those of τ, not of f); `MassOnly` keeps I alone.

use super::State;
use super::constrained::{Constrained, Mode};
use crate::error::Failure;
use crate::linalg::{Lu, Singular, cholesky, cholesky_solve};
use crate::model::Model;
use crate::options::IterationMatrix;
use crate::stats::Stats;

pub(crate) struct Problem<M: Model> {
    pub model: M,
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
    /// constraints and how they are treated (None: unconstrained)
    pub con: Option<Constrained>,
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

impl<M: Model> Problem<M> {
    pub fn new(model: M, iteration: IterationMatrix) -> Problem<M> {
        let n = M::NQ;
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
            u: vec![0.0; M::NU],
            input_fn: None,
            held: vec![0.0; M::NU],
            u_fn: vec![0.0; M::NU],
            u_t: f64::NAN,
            stats: Stats::default(),
            iteration,
            singularity_tol: 0.0,
            start_pivots: z(),
            start_diagonal: z(),
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
            con: None,
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
            cache_l: vec![0.0; M::NC],
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
                })
            }
        }
    }

    /// The held controller outputs changed: u and the cached index-1 solution are stale.
    pub fn inputs_changed(&mut self) {
        self.u_t = f64::NAN;
        self.cache_valid = false;
    }

    /// The constrained model is integrated as the ODE of its index-1 form.
    fn ode(&self) -> bool {
        self.con.as_ref().is_some_and(|c| c.mode.is_ode())
    }

    /// Name of coordinate `i` for messages: `q[3]` or `q[3] (knee)`.
    pub fn label(&self, i: usize) -> String {
        self.labels[i].clone()
    }

    /// The first non-finite entry of `v`, as a failure naming its coordinate.
    pub fn check(&self, quantity: &'static str, v: &[f64]) -> Result<(), Failure> {
        // user code reports its own failure first (a NaN it caused is only its symptom)
        if let Some(f) = self.model.take_failure() {
            return Err(f);
        }
        match v.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(i) => Err(Failure::NonFinite {
                quantity,
                coordinate: self.label(i % self.n),
            }),
        }
    }

    /// The failure for a singular matrix whose pivot column `s.column` names a coordinate,
    /// or, past the coordinates (index-3 matrices), the multiplier of a constraint.
    pub(crate) fn singular(&self, matrix: &'static str, s: Singular) -> Failure {
        let coordinate = if s.column < self.n {
            self.label(s.column)
        } else {
            let k = s.column - self.n;
            let name = self
                .con
                .as_ref()
                .map_or_else(|| format!("#{k}"), |c| c.name(k));
            format!("λ of constraint `{name}`")
        };
        Failure::SingularMatrix {
            matrix,
            rcond: s.rcond,
            coordinates: vec![coordinate],
        }
    }

    /// A singular mass matrix (its Cholesky factorisation in `l` stopped at `s.column`),
    /// named by the coordinates that move the bodies alike: the null vector of the leading
    /// block up to the failed pivot.
    pub(crate) fn singular_mass(&self, l: &[f64], s: Singular) -> Failure {
        let (n, j) = (self.n, s.column);
        // x = (−L₁₁⁻ᵀ l_j, 1), with l_j row j of L left of the diagonal: x_{0..=j}ᵀ M x_{0..=j}
        // is the failed pivot
        let mut x = vec![0.0; j + 1];
        x[j] = 1.0;
        for i in (0..j).rev() {
            let mut v = -l[j + n * i];
            for k in i + 1..j {
                v -= l[k + n * i] * x[k];
            }
            x[i] = v / l[i + n * i];
        }
        // weigh each coordinate by its own inertia, √M_ii (M_ii = Σ_k L_ik² above the failure)
        let w: Vec<f64> = (0..=j)
            .map(|i| {
                let mii = if i < j {
                    (0..=i).map(|k| l[i + n * k] * l[i + n * k]).sum::<f64>()
                } else {
                    l[j + n * j].abs()
                };
                x[i].abs() * mii.sqrt()
            })
            .collect();
        let top = w.iter().fold(0.0f64, |m, v| m.max(*v));
        let mut coordinates: Vec<String> = (0..=j)
            .filter(|&i| w[i] >= 0.2 * top && top > 0.0)
            .map(|i| self.label(i))
            .collect();
        if coordinates.is_empty() {
            coordinates.push(self.label(j));
        }
        Failure::SingularMatrix {
            matrix: "the mass matrix M",
            rcond: s.rcond,
            coordinates,
        }
    }

    /// Watches for singular configurations from now on, with the factor of M at the start
    /// (the last one made, in `chol`) as the reference.
    pub fn watch_from_start(&mut self, tolerance: f64) {
        let n = self.n;
        for j in 0..n {
            self.start_pivots[j] = self.chol[j + n * j] * self.chol[j + n * j];
            self.start_diagonal[j] = (0..=j).map(|k| self.chol[j + n * k].powi(2)).sum();
        }
        self.singularity_tol = tolerance;
    }

    /// Whether singular configurations are watched (after the start, with a tolerance).
    fn watching(&self) -> bool {
        self.singularity_tol > 0.0
    }

    /// M (in `mchk`) factorised only to watch its conditioning.
    fn watch_mchk(&mut self, t: f64, q: &[f64]) -> Result<(), Failure> {
        self.stats.condition_checks += 1;
        cholesky(&mut self.mchk, self.n).map_err(|s| self.singular_mass(&self.mchk, s))?;
        let (ratio, j) = worst_pivot(&self.mchk, self.n, &self.start_pivots);
        self.judge(ratio, j, t, q)
    }

    /// A singular configuration when the Cholesky pivot of coordinate j fell below
    /// `singularity_tol` times its start value (`ratio`, the smallest over j).
    fn judge(&mut self, ratio: f64, j: usize, t: f64, q: &[f64]) -> Result<(), Failure> {
        if ratio < self.singularity_tol {
            return Err(self.singular_configuration(t, q, ratio, j));
        }
        Ok(())
    }

    /// What a singular configuration at (t, q) is (a failure path: allocates, evaluates M
    /// 2n + 1 more times): the coordinates of the near-null vector of M scaled by its start
    /// diagonal (inverse iteration), and the coordinate with the largest |∂ log det M/∂q_j|
    /// (central differences), the one whose value makes M singular.
    fn singular_configuration(&mut self, t: f64, q: &[f64], ratio: f64, pivot: usize) -> Failure {
        let n = self.n;
        let mut l = vec![0.0; n * n];
        let log_det = |model: &M, q: &[f64], l: &mut [f64]| -> Option<f64> {
            model.mass_matrix(t, q, l);
            cholesky(l, n).ok()?;
            Some((0..n).map(|i| (l[i + n * i] * l[i + n * i]).ln()).sum())
        };
        self.model.mass_matrix(t, q, &mut l);
        let factored = cholesky(&mut l, n).is_ok();
        self.stats.mass_matrix += 1;
        self.stats.factorizations += 1;
        // inverse iteration on S = D₀^-1/2 M D₀^-1/2: x ← D₀^1/2 M⁻¹ D₀^1/2 x
        let d: Vec<f64> = self.start_diagonal.iter().map(|x| x.sqrt()).collect();
        let mut x = vec![1.0; n];
        if factored {
            for _ in 0..8 {
                for i in 0..n {
                    x[i] *= d[i];
                }
                cholesky_solve(&l, n, &mut x);
                self.stats.solves += 1;
                for i in 0..n {
                    x[i] *= d[i];
                }
                let norm = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                x.iter_mut().for_each(|v| *v /= norm);
            }
        }
        let mut dependent: Vec<String> = (0..n)
            .filter(|&i| factored && x[i].abs() >= 0.2)
            .map(|i| self.label(i))
            .collect();
        if dependent.is_empty() {
            dependent.push(self.label(pivot));
        }
        let mut qp = q.to_vec();
        let mut best = (pivot, 0.0f64);
        for j in 0..n {
            let dj = 1e-6 * q[j].abs().max(1.0);
            qp[j] = q[j] + dj;
            let up = log_det(&self.model, &qp, &mut l);
            qp[j] = q[j] - dj;
            let down = log_det(&self.model, &qp, &mut l);
            qp[j] = q[j];
            self.stats.mass_matrix += 2;
            self.stats.factorizations += 2;
            if let (Some(a), Some(b)) = (up, down) {
                let g = ((a - b) / (2.0 * dj)).abs();
                if g > best.1 {
                    best = (j, g);
                }
            }
        }
        Failure::SingularConfiguration {
            coordinate: self.label(best.0),
            value: q[best.0],
            dependent,
            ratio,
            tolerance: self.singularity_tol,
        }
    }

    /// qdd from M qdd = h at (t, q, qd); for a constrained model, qdd and λ (in
    /// `con.lambda`) of the index-1 equations, after completing the dependent coordinates
    /// when partitioning.
    pub fn accel(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &mut [f64]) -> Result<(), Failure> {
        self.inputs_at(t)?;
        let Some(c) = self.con.as_mut() else {
            return self.plain_accel(t, q, qd, qdd);
        };
        if self.cache_valid && self.cache_t == t && self.cache_q == q && self.cache_v == qd {
            qdd.copy_from_slice(&self.cache_a);
            c.lambda.copy_from_slice(&self.cache_l);
            return Ok(());
        }
        if c.mode == Mode::Partitioning {
            c.complete(&self.model, &mut self.stats, t, q, qd)?;
            self.qx.copy_from_slice(&c.qc);
            self.vx.copy_from_slice(&c.vc);
        } else {
            self.qx.copy_from_slice(q);
            self.vx.copy_from_slice(qd);
        }
        self.model
            .dynamics(t, &self.qx, &self.vx, &self.u, &mut self.m, &mut self.h);
        self.stats.dynamics += 1;
        self.check("h", &self.h)?;
        self.check("M", &self.m)?;
        self.chol.copy_from_slice(&self.m);
        self.stats.factorizations += 1;
        cholesky(&mut self.chol, self.n).map_err(|s| self.singular_mass(&self.chol, s))?;
        if self.watching() {
            let (ratio, j) = worst_pivot(&self.chol, self.n, &self.start_pivots);
            let qx = std::mem::take(&mut self.qx);
            let judged = self.judge(ratio, j, t, &qx);
            self.qx = qx;
            judged?;
        }
        let c = self.con.as_mut().expect("constrained");
        c.kkt(
            &self.model,
            &mut self.stats,
            &self.chol,
            t,
            &self.qx,
            &self.vx,
            &self.h,
            qdd,
        )?;
        self.check("qdd", qdd)?;
        let c = self.con.as_ref().expect("constrained");
        self.cache_valid = true;
        self.cache_t = t;
        self.cache_q.copy_from_slice(q);
        self.cache_v.copy_from_slice(qd);
        self.cache_a.copy_from_slice(qdd);
        self.cache_l.copy_from_slice(&c.lambda);
        Ok(())
    }

    fn plain_accel(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
    ) -> Result<(), Failure> {
        self.model
            .dynamics(t, q, qd, &self.u, &mut self.m, &mut self.h);
        self.stats.dynamics += 1;
        self.check("h", &self.h)?;
        self.check("M", &self.m)?;
        self.chol.copy_from_slice(&self.m);
        self.stats.factorizations += 1;
        cholesky(&mut self.chol, self.n).map_err(|s| self.singular_mass(&self.chol, s))?;
        if self.watching() {
            let (ratio, j) = worst_pivot(&self.chol, self.n, &self.start_pivots);
            self.judge(ratio, j, t, q)?;
        }
        qdd.copy_from_slice(&self.h);
        cholesky_solve(&self.chol, self.n, qdd);
        self.stats.solves += 1;
        self.check("qdd", qdd)
    }

    /// f(t, q, qd) into `self.fa` (the ODE of the index-1 form).
    fn f_into_fa(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<(), Failure> {
        let mut f = std::mem::take(&mut self.fa);
        let r = self.accel(t, q, qd, &mut f);
        self.fa = f;
        r
    }

    /// f(t, q, qd) into `self.fb`.
    fn f_into_fb(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<(), Failure> {
        let mut f = std::mem::take(&mut self.fb);
        let r = self.accel(t, q, qd, &mut f);
        self.fb = f;
        r
    }

    /// The part of `e` tangent to the constraints at (t, q) in the metric of M(q): index-3
    /// error estimates leave out the components M⁻¹Bᵀx that only the multipliers move.
    pub fn tangent_part(&mut self, t: f64, q: &[f64], e: &mut [f64]) -> Result<(), Failure> {
        if self.con.is_none() {
            return Ok(());
        }
        self.model.mass_matrix(t, q, &mut self.chol);
        self.stats.mass_matrix += 1;
        self.stats.factorizations += 1;
        if let Err(s) = cholesky(&mut self.chol, self.n) {
            return Err(self.singular_mass(&self.chol, s));
        }
        let c = self.con.as_mut().expect("constrained");
        c.eval_b(&self.model, &mut self.stats, t, q);
        if c.tangent_part(&mut self.stats, &self.chol, e, &mut self.dx)
            .is_err()
        {
            let c = self.con.as_mut().expect("constrained");
            return Err(c.rank_failure(&self.model, &mut self.stats, t, q));
        }
        Ok(())
    }

    /// Completes an accepted state of a constrained model: projection or completion of the
    /// dependent coordinates (then qdd and λ there), λ of the index-1 form (Baumgarte), a
    /// new partition when the current one is ill-conditioned, and the drift check (index 3,
    /// Baumgarte). `next.lambda` is the scheme's for index 3.
    pub fn after_step(&mut self, next: &mut State) -> Result<(), Failure> {
        let Some(c) = self.con.as_mut() else {
            return Ok(());
        };
        let t = next.t;
        let mode = c.mode;
        match mode {
            Mode::Index3 => c.check_drift(&self.model, &mut self.stats, t, &next.q),
            Mode::Baumgarte { .. } => {
                self.f_into_fa(t, &next.q, &next.qd)?;
                let c = self.con.as_mut().expect("constrained");
                next.lambda.copy_from_slice(&c.lambda);
                c.check_drift(&self.model, &mut self.stats, t, &next.q)
            }
            Mode::Projection => {
                self.model.mass_matrix(t, &next.q, &mut self.chol);
                self.stats.mass_matrix += 1;
                self.stats.factorizations += 1;
                cholesky(&mut self.chol, self.n).map_err(|s| self.singular_mass(&self.chol, s))?;
                let c = self.con.as_mut().expect("constrained");
                c.project(
                    &self.model,
                    &mut self.stats,
                    &self.chol,
                    t,
                    &mut next.q,
                    &mut next.qd,
                    &mut self.dx,
                )?;
                let (q, qd) = (std::mem::take(&mut next.q), std::mem::take(&mut next.qd));
                let r = self.accel(t, &q, &qd, &mut next.qdd);
                (next.q, next.qd) = (q, qd);
                r?;
                next.lambda
                    .copy_from_slice(&self.con.as_ref().expect("constrained").lambda);
                Ok(())
            }
            Mode::Partitioning => {
                c.complete(&self.model, &mut self.stats, t, &next.q, &next.qd)?;
                next.q.copy_from_slice(&c.qc);
                next.qd.copy_from_slice(&c.vc);
                let (q, qd) = (std::mem::take(&mut next.q), std::mem::take(&mut next.qd));
                let r = self.accel(t, &q, &qd, &mut next.qdd);
                (next.q, next.qd) = (q, qd);
                r?;
                let c = self.con.as_mut().expect("constrained");
                next.lambda.copy_from_slice(&c.lambda);
                c.check_partition(&mut self.stats);
                Ok(())
            }
        }
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

    /// Iteration matrix of the index-1 ODE, I + γ'·(−∂f/∂qd) + β'·(−∂f/∂q), by forward
    /// differences of f along (β', γ')·e_j (I alone with `MassOnly`).
    #[allow(clippy::too_many_arguments)]
    fn ode_iteration_matrix(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        beta: f64,
        gamma: f64,
        lu: &mut Lu<f64>,
    ) -> Result<(), Failure> {
        let n = self.n;
        {
            let a = lu.matrix_mut();
            a.fill(0.0);
            for i in 0..n {
                a[i + n * i] = 1.0;
            }
        }
        if self.iteration != IterationMatrix::MassOnly {
            self.f_into_fa(t, q, qd)?;
            let mut qp = std::mem::take(&mut self.qp);
            let mut vp = std::mem::take(&mut self.vp);
            qp.copy_from_slice(q);
            vp.copy_from_slice(qd);
            let mut result = Ok(());
            for j in 0..n {
                let eps = f64::EPSILON.sqrt() * qdd[j].abs().max(1.0);
                qp[j] += beta * eps;
                vp[j] += gamma * eps;
                result = self.f_into_fb(t, &qp, &vp);
                qp[j] = q[j];
                vp[j] = qd[j];
                if result.is_err() {
                    break;
                }
                let a = lu.matrix_mut();
                for i in 0..n {
                    a[i + n * j] -= (self.fb[i] - self.fa[i]) / eps;
                }
            }
            self.qp = qp;
            self.vp = vp;
            result?;
        }
        self.stats.factorizations += 1;
        lu.factor()
            .map_err(|s| self.singular("the iteration matrix I − γ'∂f/∂qd − β'∂f/∂q", s))
    }

    /// M = I, C_t = −∂f/∂qd, K_t = −∂f/∂q of the index-1 ODE, by forward differences of f
    /// (2n evaluations; C_t = K_t = 0 with `MassOnly`).
    #[allow(clippy::too_many_arguments)]
    fn ode_tangent_matrices(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        m: &mut [f64],
        c: &mut [f64],
        k: &mut [f64],
    ) -> Result<(), Failure> {
        let n = self.n;
        m.fill(0.0);
        for i in 0..n {
            m[i + n * i] = 1.0;
        }
        c.fill(0.0);
        k.fill(0.0);
        if self.iteration == IterationMatrix::MassOnly {
            return Ok(());
        }
        self.f_into_fa(t, q, qd)?;
        let mut qp = std::mem::take(&mut self.qp);
        let mut vp = std::mem::take(&mut self.vp);
        qp.copy_from_slice(q);
        vp.copy_from_slice(qd);
        let mut result = Ok(());
        for j in 0..n {
            let eps = (q[j] + f64::EPSILON.sqrt() * q[j].abs().max(1.0)) - q[j];
            qp[j] = q[j] + eps;
            result = self.f_into_fb(t, &qp, qd);
            qp[j] = q[j];
            if result.is_err() {
                break;
            }
            for i in 0..n {
                k[i + n * j] = -(self.fb[i] - self.fa[i]) / eps;
            }
            let eps = (qd[j] + f64::EPSILON.sqrt() * qd[j].abs().max(1.0)) - qd[j];
            vp[j] = qd[j] + eps;
            result = self.f_into_fb(t, q, &vp);
            vp[j] = qd[j];
            if result.is_err() {
                break;
            }
            for i in 0..n {
                c[i + n * j] = -(self.fb[i] - self.fa[i]) / eps;
            }
        }
        self.qp = qp;
        self.vp = vp;
        result
    }

    /// Fills and factorises the iteration matrix M + γ'·C_t + β'·K_t at (t, q, qd, qdd): the
    /// derivative of τ(q̂ + β'a, v̂ + γ'a, a) with respect to a.
    #[allow(clippy::too_many_arguments)]
    pub fn iteration_matrix(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        beta: f64,
        gamma: f64,
        lu: &mut Lu<f64>,
    ) -> Result<(), Failure> {
        if self.ode() {
            return self.ode_iteration_matrix(t, q, qd, qdd, beta, gamma, lu);
        }
        self.iteration_block(t, q, qd, qdd, beta, gamma, lu.matrix_mut())?;
        self.stats.factorizations += 1;
        lu.factor()
            .map_err(|s| self.singular("the iteration matrix M + γ'C + β'K", s))
    }

    /// M + γ'·C_t + β'·K_t of the model's τ at (t, q, qd, qdd) into `a` (n × n, column-major),
    /// unfactorised, as `self.iteration` says: exact (M and the generated tangents), mass
    /// only, or forward differences of τ along (β', γ', 1)·e_j (n + 1 evaluations).
    #[allow(clippy::too_many_arguments)]
    pub fn iteration_block(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        beta: f64,
        gamma: f64,
        a: &mut [f64],
    ) -> Result<(), Failure> {
        self.inputs_at(t)?;
        let n = self.n;
        match self.iteration {
            IterationMatrix::Exact | IterationMatrix::Auto => {
                self.model.mass_matrix(t, q, &mut self.m);
                self.stats.mass_matrix += 1;
                // validated up front against `ModelInfo::has_tangents`
                if let Err(e) =
                    self.model
                        .tangents(t, q, qd, qdd, &self.u, &mut self.k, &mut self.c)
                {
                    return Err(Failure::InvalidOption {
                        name: "iteration_matrix",
                        value: "Exact".into(),
                        reason: model_error_reason(&e),
                    });
                }
                self.stats.tangents += 1;
                for i in 0..n * n {
                    a[i] = self.m[i] + gamma * self.c[i] + beta * self.k[i];
                }
            }
            IterationMatrix::MassOnly => {
                self.model.mass_matrix(t, q, &mut self.m);
                self.stats.mass_matrix += 1;
                a.copy_from_slice(&self.m);
            }
            IterationMatrix::FiniteDifferences => {
                self.model
                    .inverse_dynamics(t, q, qd, qdd, &self.u, &mut self.tau0);
                self.stats.inverse_dynamics += 1;
                self.qp.copy_from_slice(q);
                self.vp.copy_from_slice(qd);
                self.ap.copy_from_slice(qdd);
                for j in 0..n {
                    let eps = f64::EPSILON.sqrt() * qdd[j].abs().max(1.0);
                    self.qp[j] += beta * eps;
                    self.vp[j] += gamma * eps;
                    self.ap[j] += eps;
                    self.model.inverse_dynamics(
                        t,
                        &self.qp,
                        &self.vp,
                        &self.ap,
                        &self.u,
                        &mut self.tau1,
                    );
                    self.stats.inverse_dynamics += 1;
                    self.qp[j] = q[j];
                    self.vp[j] = qd[j];
                    self.ap[j] = qdd[j];
                    for i in 0..n {
                        a[i + n * j] = (self.tau1[i] - self.tau0[i]) / eps;
                    }
                }
            }
        }
        if let Some(f) = self.model.take_failure() {
            return Err(f);
        }
        if let Some(i) = a.iter().position(|x| !x.is_finite()) {
            return Err(Failure::NonFinite {
                quantity: "iteration matrix",
                coordinate: self.label(i % n),
            });
        }
        if self.iteration != IterationMatrix::FiniteDifferences && self.watching() {
            self.mchk.copy_from_slice(&self.m);
            self.watch_mchk(t, q)?;
        }
        Ok(())
    }

    /// The pieces of the iteration matrix, unfactorised, for schemes that combine them with
    /// several (or complex) coefficients: M, C_t = ∂τ/∂qd and K_t = ∂τ/∂q at
    /// (t, q, qd, qdd), n × n column-major each, as `self.iteration` says: exact (M and the
    /// generated tangents: one evaluation of each), finite differences (M exact, C_t and K_t
    /// by forward differences of τ: 2n + 1 evaluations of τ), or mass only (C_t = K_t = 0).
    #[allow(clippy::too_many_arguments)]
    pub fn tangent_matrices(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        m: &mut [f64],
        c: &mut [f64],
        k: &mut [f64],
    ) -> Result<(), Failure> {
        self.inputs_at(t)?;
        if self.ode() {
            return self.ode_tangent_matrices(t, q, qd, m, c, k);
        }
        let n = self.n;
        self.model.mass_matrix(t, q, m);
        self.stats.mass_matrix += 1;
        match self.iteration {
            IterationMatrix::Exact | IterationMatrix::Auto => {
                if let Err(e) = self.model.tangents(t, q, qd, qdd, &self.u, k, c) {
                    return Err(Failure::InvalidOption {
                        name: "iteration_matrix",
                        value: "Exact".into(),
                        reason: model_error_reason(&e),
                    });
                }
                self.stats.tangents += 1;
            }
            IterationMatrix::MassOnly => {
                c.fill(0.0);
                k.fill(0.0);
            }
            IterationMatrix::FiniteDifferences => {
                self.model
                    .inverse_dynamics(t, q, qd, qdd, &self.u, &mut self.tau0);
                self.stats.inverse_dynamics += 1;
                self.qp.copy_from_slice(q);
                self.vp.copy_from_slice(qd);
                for j in 0..n {
                    // the increment actually represented in floating point
                    let eps = (q[j] + f64::EPSILON.sqrt() * q[j].abs().max(1.0)) - q[j];
                    self.qp[j] = q[j] + eps;
                    self.model
                        .inverse_dynamics(t, &self.qp, qd, qdd, &self.u, &mut self.tau1);
                    self.qp[j] = q[j];
                    for i in 0..n {
                        k[i + n * j] = (self.tau1[i] - self.tau0[i]) / eps;
                    }
                    let eps = (qd[j] + f64::EPSILON.sqrt() * qd[j].abs().max(1.0)) - qd[j];
                    self.vp[j] = qd[j] + eps;
                    self.model
                        .inverse_dynamics(t, q, &self.vp, qdd, &self.u, &mut self.tau1);
                    self.vp[j] = qd[j];
                    for i in 0..n {
                        c[i + n * j] = (self.tau1[i] - self.tau0[i]) / eps;
                    }
                }
                self.stats.inverse_dynamics += 2 * n;
            }
        }
        self.check("M", m)?;
        self.check("C_t", c)?;
        self.check("K_t", k)?;
        if self.watching() {
            self.mchk.copy_from_slice(m);
            self.watch_mchk(t, q)?;
        }
        Ok(())
    }

    /// Evaluations for one output: energy, and poses when asked for.
    pub fn energy(&mut self, t: f64, q: &[f64], qd: &[f64]) -> crate::model::Energy {
        self.stats.energy += 1;
        self.model.energy(t, q, qd)
    }
}

/// The Cholesky pivot L_jj² of a factor of M that fell most relative to its start value,
/// min_j L_jj²/L_jj²(start), and its j. L_jj² is the inertia of coordinate j that the
/// coordinates before it cannot produce: it falls when coordinate j starts to move the bodies
/// as a combination of the others does (Euler angles at gimbal lock, aligned joint axes), or
/// stops moving mass; each pivot is compared with its own start value, so units do not mix.
pub(crate) fn worst_pivot(l: &[f64], n: usize, start: &[f64]) -> (f64, usize) {
    let mut worst = (f64::INFINITY, 0);
    for j in 0..n {
        let ratio = l[j + n * j] * l[j + n * j] / start[j];
        if ratio < worst.0 {
            worst = (ratio, j);
        }
    }
    worst
}

fn model_error_reason(e: &crate::error::ModelError) -> &'static str {
    match e {
        crate::error::ModelError::TangentsNotGenerated { .. } => {
            "the model has no tangents: add `option tangents;` to its multibody! block"
        }
    }
}
