//! What a constrained model needs after a step and for its error estimates: projection or
//! completion of the accepted state, its multipliers, the drift check, and the part of a
//! vector tangent to the constraints.

use super::super::State;
use super::super::constrained::{Constrained, Mode};
use super::{Loops, Problem};
use crate::error::Failure;
use crate::linalg::cholesky;

impl Problem {
    /// Runs `f` on the constraints of closed loops, lent out of `self.loops` meanwhile
    /// (`open` without loops).
    fn with_closed<R>(&mut self, open: R, f: impl FnOnce(&mut Self, &mut Constrained) -> R) -> R {
        match std::mem::take(&mut self.loops) {
            Loops::Open => open,
            Loops::Closed(mut c) => {
                let r = f(self, &mut c);
                self.loops = Loops::Closed(c);
                r
            }
        }
    }

    /// The part of `e` tangent to the constraints at (t, q) in the metric of M(q): index-3
    /// error estimates leave out the components M⁻¹Bᵀx that only the multipliers move.
    pub fn tangent_part(&mut self, t: f64, q: &[f64], e: &mut [f64]) -> Result<(), Failure> {
        self.with_closed(Ok(()), |p, c| p.closed_tangent_part(c, t, q, e))
    }

    fn closed_tangent_part(
        &mut self,
        c: &mut Constrained,
        t: f64,
        q: &[f64],
        e: &mut [f64],
    ) -> Result<(), Failure> {
        self.model.mass_matrix(t, q, &mut self.chol);
        self.stats.mass_matrix += 1;
        self.stats.factorizations += 1;
        if let Err(s) = cholesky(&mut self.chol, self.n) {
            return Err(self.singular_mass(&self.chol, s));
        }
        c.eval_b(self.model.erased(), &mut self.stats, t, q);
        if c.tangent_part(&mut self.stats, &self.chol, e, &mut self.dx)
            .is_err()
        {
            return Err(c.rank_failure(self.model.erased(), &mut self.stats, t, q));
        }
        Ok(())
    }

    /// Completes an accepted state of a constrained model: projection or completion of the
    /// dependent coordinates (then qdd and λ there), λ of the index-1 form (Baumgarte), a
    /// new partition when the current one is ill-conditioned, and the drift check (index 3,
    /// Baumgarte). `next.lambda` is the scheme's for index 3.
    pub fn after_step(&mut self, next: &mut State) -> Result<(), Failure> {
        self.with_closed(Ok(()), |p, c| p.closed_after_step(c, next))
    }

    fn closed_after_step(&mut self, c: &mut Constrained, next: &mut State) -> Result<(), Failure> {
        let t = next.t;
        match c.mode {
            Mode::Index3 | Mode::Index2 => {
                c.check_drift(self.model.erased(), &mut self.stats, t, &next.q)
            }
            Mode::Baumgarte { .. } => {
                let mut f = std::mem::take(&mut self.fa);
                let r = self.closed_accel(c, t, &next.q, &next.qd, &mut f);
                self.fa = f;
                r?;
                next.lambda.copy_from_slice(&c.lambda);
                c.check_drift(self.model.erased(), &mut self.stats, t, &next.q)
            }
            Mode::Projection => {
                self.model.mass_matrix(t, &next.q, &mut self.chol);
                self.stats.mass_matrix += 1;
                self.stats.factorizations += 1;
                cholesky(&mut self.chol, self.n).map_err(|s| self.singular_mass(&self.chol, s))?;
                c.project(
                    self.model.erased(),
                    &mut self.stats,
                    &self.chol,
                    next,
                    &mut self.dx,
                )?;
                self.closed_accel(c, t, &next.q, &next.qd, &mut next.qdd)?;
                next.lambda.copy_from_slice(&c.lambda);
                Ok(())
            }
            Mode::Partitioning => {
                c.complete(self.model.erased(), &mut self.stats, t, &next.q, &next.qd)?;
                next.q.copy_from_slice(&c.qc);
                next.qd.copy_from_slice(&c.vc);
                self.closed_accel(c, t, &next.q, &next.qd, &mut next.qdd)?;
                next.lambda.copy_from_slice(&c.lambda);
                c.check_partition(&mut self.stats);
                Ok(())
            }
        }
    }
}
