//! The model as the schemes see it: evaluations counted, results checked (a non-finite value
//! is named by its coordinate), forward dynamics by Cholesky, residuals τ, and iteration
//! matrices M + γ'·C_t + β'·K_t, all on buffers allocated once.

use crate::error::Failure;
use crate::linalg::{Lu, Singular, cholesky, cholesky_solve};
use crate::model::Model;
use crate::options::IterationMatrix;
use crate::stats::Stats;

pub(crate) struct Problem<M: Model> {
    pub model: M,
    pub n: usize,
    /// inputs u (zero until input functions exist)
    pub u: Vec<f64>,
    pub stats: Stats,
    /// how iteration matrices are built (never `Auto` here)
    pub iteration: IterationMatrix,
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
            stats: Stats::default(),
            iteration,
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
        }
    }

    /// Name of coordinate `i` for messages: `q[3]` or `q[3] (knee)`.
    pub fn label(&self, i: usize) -> String {
        self.labels[i].clone()
    }

    /// The first non-finite entry of `v`, as a failure naming its coordinate.
    pub fn check(&self, quantity: &'static str, v: &[f64]) -> Result<(), Failure> {
        match v.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(i) => Err(Failure::NonFinite {
                quantity,
                coordinate: self.label(i % self.n),
            }),
        }
    }

    pub(crate) fn singular(&self, matrix: &'static str, s: Singular) -> Failure {
        Failure::SingularMatrix {
            matrix,
            rcond: s.rcond,
            coordinates: vec![self.label(s.column)],
        }
    }

    /// qdd from M qdd = h at (t, q, qd).
    pub fn accel(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &mut [f64]) -> Result<(), Failure> {
        self.model
            .dynamics(t, q, qd, &self.u, &mut self.m, &mut self.h);
        self.stats.dynamics += 1;
        self.check("h", &self.h)?;
        self.check("M", &self.m)?;
        self.chol.copy_from_slice(&self.m);
        self.stats.factorizations += 1;
        cholesky(&mut self.chol, self.n).map_err(|s| self.singular("the mass matrix M", s))?;
        qdd.copy_from_slice(&self.h);
        cholesky_solve(&self.chol, self.n, qdd);
        self.stats.solves += 1;
        self.check("qdd", qdd)
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
        self.model.inverse_dynamics(t, q, qd, qdd, &self.u, r);
        self.stats.inverse_dynamics += 1;
        self.check("τ", r)
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
                let a = lu.matrix_mut();
                for i in 0..n * n {
                    a[i] = self.m[i] + gamma * self.c[i] + beta * self.k[i];
                }
            }
            IterationMatrix::MassOnly => {
                self.model.mass_matrix(t, q, &mut self.m);
                self.stats.mass_matrix += 1;
                lu.matrix_mut().copy_from_slice(&self.m);
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
                    let a = lu.matrix_mut();
                    for i in 0..n {
                        a[i + n * j] = (self.tau1[i] - self.tau0[i]) / eps;
                    }
                }
            }
        }
        if let Some(i) = lu.matrix_mut().iter().position(|x| !x.is_finite()) {
            return Err(Failure::NonFinite {
                quantity: "iteration matrix",
                coordinate: self.label(i % n),
            });
        }
        self.stats.factorizations += 1;
        lu.factor()
            .map_err(|s| self.singular("the iteration matrix M + γ'C + β'K", s))
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
        self.check("K_t", k)
    }

    /// Evaluations for one output: energy, and poses when asked for.
    pub fn energy(&mut self, t: f64, q: &[f64], qd: &[f64]) -> crate::model::Energy {
        self.stats.energy += 1;
        self.model.energy(t, q, qd)
    }
}

fn model_error_reason(e: &crate::error::ModelError) -> &'static str {
    match e {
        crate::error::ModelError::TangentsNotGenerated { .. } => {
            "the model has no tangents: add `option tangents;` to its multibody! block"
        }
    }
}
