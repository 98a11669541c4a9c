//! Iteration matrices M + γ'·C_t + β'·K_t and the tangents C_t, K_t: generated, by finite
//! differences of τ, or M alone.

use super::super::at::{At, Weights};
use super::Problem;
use crate::erased::ErasedModel;
use crate::error::Failure;
use crate::linalg::Lu;
use crate::model::DifferenceBuffers;
use crate::options::IterationMatrix;

impl Problem {
    /// Fills and factorises the iteration matrix M + γ'·C_t + β'·K_t at (t, q, qd, qdd): the
    /// derivative of τ(q̂ + β'a, v̂ + γ'a, a) with respect to a.
    pub fn iteration_matrix(
        &mut self,
        at: At,
        qdd: &[f64],
        w: Weights,
        lu: &mut Lu<f64>,
    ) -> Result<(), Failure> {
        if self.ode() {
            return self.ode_iteration_matrix(at, qdd, w, lu);
        }
        self.iteration_block(at, qdd, w, lu.matrix_mut())?;
        self.stats.factorizations += 1;
        lu.factor()
            .map_err(|s| self.singular("the iteration matrix M + γ'C + β'K", s))
    }

    /// M + γ'·C_t + β'·K_t of the model's τ at (t, q, qd, qdd) into `a` (n × n, column-major),
    /// unfactorised, as `self.iteration` says: exact (M and the generated tangents), mass
    /// only, or forward differences of τ along (β', γ', 1)·e_j (n + 1 evaluations).
    pub fn iteration_block(
        &mut self,
        at: At,
        qdd: &[f64],
        w: Weights,
        a: &mut [f64],
    ) -> Result<(), Failure> {
        let (At { t, q, qd }, Weights { beta, gamma }) = (at, w);
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
                let (model, u, work) = self.differencing();
                let evaluations =
                    model.differenced_iteration_matrix(t, [q, qd, qdd], u, [beta, gamma], a, work);
                self.stats.inverse_dynamics += evaluations;
            }
        }
        if let Some(f) = self.model.take_failure() {
            return Err(f);
        }
        Failure::non_finite("iteration matrix", a, |i| self.label(i % n))?;
        if self.iteration != IterationMatrix::FiniteDifferences && self.watching() {
            self.mchk.copy_from_slice(&self.m);
            self.watch_mchk(t, q)?;
        }
        Ok(())
    }

    /// The model, its inputs at the time `inputs_at` set, and the buffers its differences use.
    fn differencing(&mut self) -> (&dyn ErasedModel, &[f64], DifferenceBuffers<'_>) {
        let work = DifferenceBuffers {
            tau0: &mut self.tau0,
            tau1: &mut self.tau1,
            qp: &mut self.qp,
            vp: &mut self.vp,
            ap: &mut self.ap,
        };
        (self.model.erased(), &self.u, work)
    }

    /// M, C_t and K_t (n × n, column-major) the last iteration matrix was made of, when it was
    /// made of them (exact tangents, tree models): what a scheme may read, at no evaluation,
    /// right after a fresh matrix to learn about the stiffness (BDF's spectrum estimate).
    pub fn last_tangents(&self) -> Option<(&[f64], &[f64], &[f64])> {
        let exact = matches!(
            self.iteration,
            IterationMatrix::Exact | IterationMatrix::Auto
        );
        (exact && !self.ode()).then_some((&self.m[..], &self.c[..], &self.k[..]))
    }

    /// Whether the iteration matrices are built by differences (of τ, or of the ODE of a
    /// closed loop's index-1 form): 2n + 1 evaluations each.
    pub fn matrices_by_differences(&self) -> bool {
        self.ode() || self.iteration == IterationMatrix::FiniteDifferences
    }

    /// The pieces of the iteration matrix, unfactorised, for schemes that combine them with
    /// several (or complex) coefficients: M, C_t = ∂τ/∂qd and K_t = ∂τ/∂q at
    /// (t, q, qd, qdd), n × n column-major each, as `self.iteration` says: exact (M and the
    /// generated tangents: one evaluation of each), finite differences (M exact, C_t and K_t
    /// by forward differences of τ: 2n + 1 evaluations of τ), or mass only (C_t = K_t = 0).
    pub fn tangent_matrices(
        &mut self,
        at: At,
        qdd: &[f64],
        m: &mut [f64],
        c: &mut [f64],
        k: &mut [f64],
    ) -> Result<(), Failure> {
        let At { t, q, qd } = at;
        self.inputs_at(t)?;
        if self.ode() {
            return self.ode_tangent_matrices(at, m, c, k);
        }
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
                let (model, u, work) = self.differencing();
                let evaluations = model.differenced_tangents(t, [q, qd, qdd], u, [k, c], work);
                self.stats.inverse_dynamics += evaluations;
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
}

/// What to do about a [`crate::error::ModelError`], in a few words.
pub(crate) fn model_error_reason(e: &crate::error::ModelError) -> &'static str {
    match e {
        crate::error::ModelError::TangentsNotGenerated { .. } => {
            "the model has no tangents: add `option tangents;` to its multibody! block"
        }
        crate::error::ModelError::NoSensitiveParameters { .. } => {
            "the model has no sensitive parameters: mark them, `param k = 1e4 sensitive;`"
        }
    }
}
