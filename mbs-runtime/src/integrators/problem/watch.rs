//! Singular configurations and singular matrices: the pivots of M (Cholesky, or the generated
//! forward dynamics) watched against their start values, and the failures that name the
//! coordinates involved.

use super::Problem;
use crate::erased::ErasedModel;
use crate::error::Failure;
use crate::linalg::{Singular, cholesky, cholesky_solve};
use crate::options::IterationMatrix;

impl Problem {
    /// The failure for a singular matrix whose pivot column `s.column` names a coordinate,
    /// or, past the coordinates (index-3 matrices), the multiplier of a constraint.
    pub(crate) fn singular(&self, matrix: &'static str, s: Singular) -> Failure {
        let coordinate = if s.column < self.n {
            self.label(s.column)
        } else {
            let k = s.column - self.n;
            let name = self
                .loops
                .closed()
                .map_or_else(|| format!("#{k}"), |c| c.name(k));
            format!("λ of constraint `{name}`")
        };
        Failure::SingularMatrix {
            matrix,
            rcond: s.rcond,
            coordinates: vec![coordinate],
            cause: String::new(),
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
            cause: String::new(),
        }
    }

    /// Watches for singular configurations from now on, with the pivots of the solve of
    /// M qdd = h at the start (t, q) as the reference: those of the generated forward
    /// dynamics when they solved it, and the Cholesky factor of M (the last one made, in
    /// `chol`), which an open-loop model solved by forward dynamics factorises here only
    /// when `implicit` (its schemes watch M through their iteration matrices).
    pub fn watch_from_start(
        &mut self,
        tolerance: f64,
        t: f64,
        q: &[f64],
        implicit: bool,
    ) -> Result<(), Failure> {
        let n = self.n;
        let by_forward = self.forward && self.loops.closed().is_none();
        if by_forward {
            self.start_forward.copy_from_slice(&self.pivots);
            if implicit && tolerance > 0.0 {
                self.model.mass_matrix(t, q, &mut self.chol);
                self.stats.mass_matrix += 1;
                self.check("M", &self.chol)?;
                self.stats.condition_checks += 1;
                cholesky(&mut self.chol, n).map_err(|s| self.singular_mass(&self.chol, s))?;
            } else {
                // no M at the start: a singular configuration is then described with the
                // diagonal of M where it is found (`start_diagonal` stays 0)
                self.singularity_tol = tolerance;
                return Ok(());
            }
        }
        for j in 0..n {
            self.start_pivots[j] = self.chol[j + n * j] * self.chol[j + n * j];
            self.start_diagonal[j] = (0..=j).map(|k| self.chol[j + n * k].powi(2)).sum();
        }
        self.singularity_tol = tolerance;
        // closed loops: the index-1 solve at the start made S and evaluated B
        if tolerance > 0.0
            && let super::Loops::Closed(c) = &mut self.loops
        {
            c.watch_from_start(tolerance);
        }
        Ok(())
    }

    /// Whether singular configurations are watched (after the start, with a tolerance).
    pub(super) fn watching(&self) -> bool {
        self.singularity_tol > 0.0
    }

    /// Watches the accepted state (t, q) of a scheme that solves for accelerations by Newton
    /// when its iteration matrices do not evaluate M (forward differences of τ on a model
    /// without an index-1 form): one evaluation and one Cholesky factorisation of M per
    /// accepted step. Other iteration matrices watch their own M (`iteration_block`), and
    /// index-1 forms watch every evaluation of f.
    pub fn watch_accepted(&mut self, t: f64, q: &[f64]) -> Result<(), Failure> {
        if !self.watching() || self.iteration != IterationMatrix::FiniteDifferences || self.ode() {
            return Ok(());
        }
        self.model.mass_matrix(t, q, &mut self.mchk);
        self.stats.mass_matrix += 1;
        Failure::non_finite("M", &self.mchk, |i| self.label(i % self.n))?;
        self.watch_mchk(t, q)
    }

    /// M (in `mchk`) factorised only to watch its conditioning.
    pub(super) fn watch_mchk(&mut self, t: f64, q: &[f64]) -> Result<(), Failure> {
        self.stats.condition_checks += 1;
        cholesky(&mut self.mchk, self.n).map_err(|s| self.singular_mass(&self.mchk, s))?;
        let (ratio, j) = worst_pivot(&self.mchk, self.n, &self.start_pivots);
        self.judge(ratio, j, t, q)
    }

    /// A singular configuration when the Cholesky pivot of coordinate j fell below
    /// `singularity_tol` times its start value (`ratio`, the smallest over j).
    pub(super) fn judge(&mut self, ratio: f64, j: usize, t: f64, q: &[f64]) -> Result<(), Failure> {
        if ratio < self.singularity_tol {
            return Err(self.singular_configuration(t, q, ratio, j));
        }
        Ok(())
    }

    /// What a singular configuration at (t, q) is (a failure path: allocates, evaluates M
    /// 2n + 1 more times): the coordinates of the near-null vector of M scaled by its start
    /// diagonal (inverse iteration), and the coordinate with the largest |∂ log det M/∂q_j|
    /// (central differences), the one whose value makes M singular.
    pub(super) fn singular_configuration(
        &mut self,
        t: f64,
        q: &[f64],
        ratio: f64,
        pivot: usize,
    ) -> Failure {
        let n = self.n;
        let mut l = vec![0.0; n * n];
        let log_det = |model: &dyn ErasedModel, q: &[f64], l: &mut [f64]| -> Option<f64> {
            model.mass_matrix(t, q, l);
            cholesky(l, n).ok()?;
            Some((0..n).map(|i| (l[i + n * i] * l[i + n * i]).ln()).sum())
        };
        self.model.mass_matrix(t, q, &mut l);
        // the diagonal of M at the start, or here when the start did not evaluate M
        let d: Vec<f64> = if self.start_diagonal.iter().all(|x| *x > 0.0) {
            self.start_diagonal.iter().map(|x| x.sqrt()).collect()
        } else {
            (0..n).map(|j| l[j + n * j].abs().sqrt()).collect()
        };
        let factored = cholesky(&mut l, n).is_ok();
        self.stats.mass_matrix += 1;
        self.stats.factorizations += 1;
        // inverse iteration on S = D₀^-1/2 M D₀^-1/2: x ← D₀^1/2 M⁻¹ D₀^1/2 x
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
            let up = log_det(self.model.erased(), &qp, &mut l);
            qp[j] = q[j] - dj;
            let down = log_det(self.model.erased(), &qp, &mut l);
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
}

/// The Cholesky pivot L_jj² of a factor of M that fell most relative to its start value,
/// min_j L_jj²/L_jj²(start), and its j. L_jj² is the inertia of coordinate j that the
/// coordinates before it cannot produce: it falls when coordinate j starts to move the bodies
/// as a combination of the others does (Euler angles at gimbal lock, aligned joint axes), or
/// stops moving mass; each pivot is compared with its own start value, so units do not mix.
pub(super) fn worst_pivot(l: &[f64], n: usize, start: &[f64]) -> (f64, usize) {
    worst_pivot_of((0..n).map(|j| l[j + n * j] * l[j + n * j]), start)
}

/// The same test on pivots given one per coordinate, such as those of the generated forward
/// dynamics (articulated bodies or LᵀDL, eliminated from the last coordinate: another order,
/// the same product det M).
pub(super) fn worst_pivot_of(pivots: impl Iterator<Item = f64>, start: &[f64]) -> (f64, usize) {
    let mut worst = (f64::INFINITY, 0);
    for (j, (p, s)) in pivots.zip(start).enumerate() {
        let ratio = p / s;
        if ratio < worst.0 {
            worst = (ratio, j);
        }
    }
    worst
}
