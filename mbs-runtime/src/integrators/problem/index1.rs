//! A constrained model run by projection, Baumgarte or partitioning is, for the schemes, the
//! ODE qdd = f(t, q, qd) of its index-1 form: its accelerations and multipliers, and its
//! iteration matrices by forward differences of f.

use super::super::at::{At, Weights};
use super::super::constrained::{Constrained, Mode};
use super::Problem;
use crate::error::Failure;
use crate::linalg::Lu;
use crate::options::IterationMatrix;

impl Problem {
    /// qdd and λ (into `c.lambda`) of the index-1 equations of the closed loops `c`, after
    /// completing the dependent coordinates when partitioning; the last evaluation is cached.
    pub(super) fn closed_accel(
        &mut self,
        c: &mut Constrained,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &mut [f64],
    ) -> Result<(), Failure> {
        self.inputs_at(t)?;
        if self.cache_valid && self.cache_t == t && self.cache_q == q && self.cache_v == qd {
            qdd.copy_from_slice(&self.cache_a);
            c.lambda.copy_from_slice(&self.cache_l);
            return Ok(());
        }
        if c.mode == Mode::Partitioning {
            c.complete(self.model.erased(), &mut self.stats, t, q, qd)?;
            self.qx.copy_from_slice(&c.qc);
            self.vx.copy_from_slice(&c.vc);
        } else {
            self.qx.copy_from_slice(q);
            self.vx.copy_from_slice(qd);
        }
        self.model
            .dynamics(t, &self.qx, &self.vx, &self.u, &mut self.m, &mut self.h);
        self.stats.dynamics += 1;
        // the completed coordinates are where M is judged (a Vec moved out and back: no copy)
        let qx = std::mem::take(&mut self.qx);
        let factorised = self.factorise_mass(t, &qx);
        self.qx = qx;
        factorised?;
        c.kkt(
            self.model.erased(),
            &mut self.stats,
            &self.chol,
            At::new(t, &self.qx, &self.vx),
            &self.h,
            qdd,
        )?;
        self.check("qdd", qdd)?;
        self.cache_valid = true;
        self.cache_t = t;
        self.cache_q.copy_from_slice(q);
        self.cache_v.copy_from_slice(qd);
        self.cache_a.copy_from_slice(qdd);
        self.cache_l.copy_from_slice(&c.lambda);
        Ok(())
    }

    /// The constrained model is integrated as the ODE of its index-1 form.
    pub(super) fn ode(&self) -> bool {
        self.loops.closed().is_some_and(|c| c.mode.is_ode())
    }

    /// f(t, q, qd) into `self.fa` (the ODE of the index-1 form).
    pub(super) fn f_into_fa(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<(), Failure> {
        let mut f = std::mem::take(&mut self.fa);
        let r = self.accel(t, q, qd, &mut f);
        self.fa = f;
        r
    }

    /// f(t, q, qd) into `self.fb`.
    pub(super) fn f_into_fb(&mut self, t: f64, q: &[f64], qd: &[f64]) -> Result<(), Failure> {
        let mut f = std::mem::take(&mut self.fb);
        let r = self.accel(t, q, qd, &mut f);
        self.fb = f;
        r
    }

    /// Iteration matrix of the index-1 ODE, I + γ'·(−∂f/∂qd) + β'·(−∂f/∂q), by forward
    /// differences of f along (β', γ')·e_j (I alone with `MassOnly`).
    pub(super) fn ode_iteration_matrix(
        &mut self,
        at: At,
        qdd: &[f64],
        w: Weights,
        lu: &mut Lu<f64>,
    ) -> Result<(), Failure> {
        let (At { t, q, qd }, Weights { beta, gamma }) = (at, w);
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
    pub(super) fn ode_tangent_matrices(
        &mut self,
        at: At,
        m: &mut [f64],
        c: &mut [f64],
        k: &mut [f64],
    ) -> Result<(), Failure> {
        let At { t, q, qd } = at;
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
}
