//! Simplified Newton on the stage accelerations (RADAU5's iteration and stopping rules): the
//! eigen-block factorisations, start values, stage values and corrections.

use super::super::State;
use super::super::problem::Problem;
use super::super::step_control::Argmax;
use super::index2::border2;
use super::index3::border;
use super::tableau::re;
use super::{
    MATRIX_C, MATRIX_C2, MATRIX_C3, MATRIX_R, MATRIX_R2, MATRIX_R3, NewtonFail, Radau, Tol,
};
use crate::error::Failure;
use crate::linalg::{C64, Singular};

impl Radau {
    /// Factorises the complex block (and the real one when `real`) for step h, unless
    /// factorised for this h already. At index 3 the blocks are bordered by −Bᵀ and B.
    pub(super) fn factor(&mut self, p: &mut Problem, h: f64, real: bool) -> Result<(), Failure> {
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-10 * x.abs().max(y.abs());
        let (n, nc) = (self.n, self.nc);
        let big = n + if self.index2 { 2 * nc } else { nc };
        if !close(self.h_c, h) {
            self.h_c = f64::NAN;
            let lam = self.k.lambda[self.k.complex];
            let g1 = lam * re(h);
            let g2 = lam * lam * re(h * h);
            let a = self.lu_c.matrix_mut();
            for j in 0..n {
                for i in 0..n {
                    let x = i + n * j;
                    a[i + big * j] = C64::new(
                        self.m[x] + g1.re * self.cm[x] + g2.re * self.km[x],
                        g1.im * self.cm[x] + g2.im * self.km[x],
                    );
                }
            }
            if self.index2 {
                border2(a, &self.bm, &self.i2, g1, g2, n, nc);
            } else {
                border(a, &self.bm, n, nc);
            }
            p.stats.factorizations += 1;
            let made = match nc {
                0 => self.lu_c.factor(),
                _ => self.lu_c.factor_equilibrating(),
            };
            if let Err(e) = made {
                return Err(self.singular(p, e, [MATRIX_C, MATRIX_C3, MATRIX_C2]));
            }
            self.h_c = h;
        }
        if real && !close(self.h_r, h) {
            self.h_r = f64::NAN;
            let g = self.k.gamma0 * h;
            let a = self.lu_r.matrix_mut();
            for j in 0..n {
                for i in 0..n {
                    let x = i + n * j;
                    a[i + big * j] = self.m[x] + g * self.cm[x] + g * g * self.km[x];
                }
            }
            if self.index2 {
                border2(a, &self.bm, &self.i2, g, g * g, n, nc);
            } else {
                border(a, &self.bm, n, nc);
            }
            p.stats.factorizations += 1;
            let made = match nc {
                0 => self.lu_r.factor(),
                _ => self.lu_r.factor_equilibrating(),
            };
            if let Err(e) = made {
                return Err(self.singular(p, e, [MATRIX_R, MATRIX_R3, MATRIX_R2]));
            }
            self.h_r = h;
        }
        Ok(())
    }

    /// The failure for a singular iteration matrix (named plain, index 3, index 2): its pivot
    /// column names a coordinate, or (index 3, 2) a multiplier of a constraint.
    pub(super) fn singular(&self, p: &Problem, e: Singular, names: [&'static str; 3]) -> Failure {
        let k = match (self.nc, self.index2) {
            (0, _) => 0,
            (_, false) => 1,
            (_, true) => 2,
        };
        p.singular(names[k], e)
    }

    /// Starting stage accelerations (and multipliers): the previous step's collocation
    /// polynomial of the acceleration (degree s − 1 through its stages), extrapolated; qdd₀
    /// (λ₀) at the first step.
    pub(super) fn start_values(&mut self, cur: &State, h: f64) {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
        let c = self.k.c;
        if self.h_prev > 0.0 {
            for i in 0..s {
                let x = 1.0 + c[i] * h / self.h_prev;
                let mut w = [0.0; 3];
                for j in 0..s {
                    w[j] = (0..s)
                        .filter(|&m| m != j)
                        .map(|m| (x - c[m]) / (c[j] - c[m]))
                        .product();
                }
                for r in 0..n {
                    self.acc[i * n + r] = (0..s).map(|j| w[j] * self.acc_prev[j * n + r]).sum();
                }
                for r in 0..nc {
                    self.lam[i * nc + r] = (0..s).map(|j| w[j] * self.lam_prev[j * nc + r]).sum();
                }
            }
        } else {
            for i in 0..s {
                self.acc[i * n..(i + 1) * n].copy_from_slice(&cur.qdd);
                self.lam[i * nc..(i + 1) * nc].copy_from_slice(&cur.lambda[..nc]);
            }
        }
        // index 2: μ is zero on the exact solution
        self.mu.fill(0.0);
    }

    /// Stage positions and velocities of the current stage accelerations (and, at index 2,
    /// multipliers μ: Q_i += h Σ_j a_ij B₀ᵀM_j).
    pub(super) fn stages(&mut self, cur: &State, h: f64) {
        let (s, n) = (self.k.s, self.n);
        if self.index2 {
            self.position_corrections();
        }
        let (a, a2, c) = (&self.k.a, &self.k.a2, &self.k.c);
        for i in 0..s {
            for r in 0..n {
                let (mut v, mut q) = (0.0, 0.0);
                for j in 0..s {
                    v += a[i][j] * self.acc[j * n + r];
                    q += a2[i][j] * self.acc[j * n + r];
                }
                self.vs[i * n + r] = cur.qd[r] + h * v;
                self.qs[i * n + r] = cur.q[r] + h * c[i] * cur.qd[r] + h * h * q;
                if self.index2 {
                    let m: f64 = (0..s).map(|j| a[i][j] * self.bmu[j * n + r]).sum();
                    self.qs[i * n + r] += h * m;
                }
            }
        }
    }

    /// Newton's correction δ = −(I ⊗ M + hA ⊗ C + h²A² ⊗ K)⁻¹ r through the eigen-blocks; at
    /// index 3 also the λ corrections, the constraint rows of block μ being
    /// B W_μ = −[(T⁻¹ ⊗ I) Φ]_μ / (h²μ²); at index 2 also the μ corrections, whose unknowns in
    /// block μ are Z_μ/(hμ), with the rows B W_μ + BBᵀ Z_μ/(hμ) = −[(T⁻¹ ⊗ I) Φ]_μ / (h²μ²)
    /// and B W_μ = −[(T⁻¹ ⊗ I) Φ̇]_μ / (hμ).
    pub(super) fn correction(&mut self, p: &mut Problem, h: f64) {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
        let (t, ti, kc) = (&self.k.t, &self.k.ti, self.k.complex);
        let index2 = self.index2;
        if let Some(kr) = self.k.real {
            for r in 0..n {
                self.rho_r[r] = -(0..s)
                    .map(|j| ti[kr][j].re * self.res[j * n + r])
                    .sum::<f64>();
            }
            let g = self.k.lambda[kr].re * h;
            if nc > 0 {
                let scale = 1.0 / (g * g);
                for r in 0..nc {
                    self.rho_r[n + r] = -scale
                        * (0..s)
                            .map(|j| ti[kr][j].re * self.phis[j * nc + r])
                            .sum::<f64>();
                }
            }
            if index2 {
                for r in 0..nc {
                    self.rho_r[n + nc + r] = -(0..s)
                        .map(|j| ti[kr][j].re * self.psis[j * nc + r])
                        .sum::<f64>()
                        / g;
                }
            }
            self.lu_r.solve(&mut self.rho_r);
            p.stats.solves += 1;
            if index2 {
                for r in 0..nc {
                    self.rho_r[n + nc + r] *= g;
                }
            }
        }
        for r in 0..n {
            let mut z = C64::default();
            for j in 0..s {
                z = z - ti[kc][j] * re(self.res[j * n + r]);
            }
            self.rho_c[r] = z;
        }
        let g1 = self.k.lambda[kc] * re(h);
        if nc > 0 {
            let g2 = g1 * g1;
            for r in 0..nc {
                let mut z = C64::default();
                for j in 0..s {
                    z = z - ti[kc][j] * re(self.phis[j * nc + r]);
                }
                self.rho_c[n + r] = z / g2;
            }
        }
        if index2 {
            for r in 0..nc {
                let mut z = C64::default();
                for j in 0..s {
                    z = z - ti[kc][j] * re(self.psis[j * nc + r]);
                }
                self.rho_c[n + nc + r] = z / g1;
            }
        }
        self.lu_c.solve(&mut self.rho_c);
        p.stats.solves += 1;
        if index2 {
            for r in 0..nc {
                self.rho_c[n + nc + r] = self.rho_c[n + nc + r] * g1;
            }
        }
        let back = |rho_c: &[C64], rho_r: &[f64], i: usize, r: usize| {
            let mut d = 2.0 * (t[i][kc] * rho_c[r]).re;
            if let Some(kr) = self.k.real {
                d += t[i][kr].re * rho_r[r];
            }
            d
        };
        for i in 0..s {
            for r in 0..n {
                self.delta[i * n + r] = back(&self.rho_c, &self.rho_r, i, r);
            }
            for r in 0..nc {
                self.dlam[i * nc + r] = back(&self.rho_c, &self.rho_r, i, n + r);
            }
            if index2 {
                for r in 0..nc {
                    self.dmu[i * nc + r] = back(&self.rho_c, &self.rho_r, i, n + nc + r);
                }
            }
        }
    }

    /// Weighted RMS norm of the stage position and velocity corrections h²A²δ, hAδ (and, at
    /// index 3, of the λ corrections).
    pub(super) fn correction_norm(&self, h: f64) -> f64 {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
        let (a, a2) = (&self.k.a, &self.k.a2);
        let mut sum = 0.0;
        let mut largest = Argmax::default();
        for i in 0..s {
            for r in 0..n {
                let (mut dv, mut dq) = (0.0, 0.0);
                for j in 0..s {
                    dv += a[i][j] * self.delta[j * n + r];
                    dq += a2[i][j] * self.delta[j * n + r];
                }
                let (eq, ev) = (h * h * dq / self.scq[r], h * dv / self.scv[r]);
                sum += eq * eq + ev * ev;
                largest.see(eq * eq, 0, r);
                largest.see(ev * ev, 1, r);
            }
            for r in 0..nc {
                let el = self.dlam[i * nc + r] / self.scl[r];
                sum += el * el;
                largest.see(el * el, 2, r);
            }
        }
        self.newton_largest.set(largest.at);
        if self.index2 {
            sum += self.mu_correction_sum(h);
        }
        (sum / (2 * s * n + s * nc).max(1) as f64).sqrt()
    }

    /// Simplified Newton on the stage accelerations (RADAU5's iteration and stopping rules).
    pub(super) fn newton(
        &mut self,
        p: &mut Problem,
        cur: &State,
        h: f64,
        tol: &Tol,
    ) -> Result<usize, NewtonFail> {
        let (s, n) = (self.k.s, self.n);
        let nit = tol.max_iterations;
        self.faccon = self.faccon.max(f64::EPSILON).powf(0.8);
        self.theta = tol.keep_below;
        let (mut newt, mut dynold, mut thqold) = (0usize, 1.0, 1.0);
        let mut last = f64::INFINITY;
        let mut dyn1 = f64::INFINITY;
        let mut residual_only = false;
        let fail = |h_next: f64, newt: usize, last: f64, cause: Option<Failure>| NewtonFail {
            h_next,
            iterations: newt,
            correction: last,
            cause,
        };
        loop {
            // the corrections have converged and only the constraints' residuals are still
            // above their tolerance: up to `nit` more iterations for them
            if newt >= nit && !(residual_only && newt < 2 * nit) {
                return Err(fail(0.5 * h, newt, last, None));
            }
            self.stages(cur, h);
            self.phi_max = 0.0;
            self.psi_max = 0.0;
            self.phi_floor = 0.0;
            self.psi_floor = 0.0;
            for i in 0..s {
                let (lo, hi) = (i * n, (i + 1) * n);
                let ti = cur.t + self.k.c[i] * h;
                let mut r = p.residual(
                    ti,
                    &self.qs[lo..hi],
                    &self.vs[lo..hi],
                    &self.acc[lo..hi],
                    &mut self.res[lo..hi],
                );
                if self.nc > 0 && r.is_ok() {
                    r = self.constraint_residual(p, i, ti);
                }
                if let Err(e) = r {
                    return Err(fail(0.5 * h, newt, last, Some(e)));
                }
            }
            self.correction(p, h);
            newt += 1;
            p.stats.newton_iterations += 1;
            let dyno = self.correction_norm(h);
            last = dyno;
            if newt == 1 {
                dyn1 = dyno;
            }
            if !dyno.is_finite() {
                return Err(fail(0.5 * h, newt, last, None));
            }
            if newt > 1 && newt < nit {
                let thq = dyno / dynold;
                self.theta = if newt == 2 {
                    thq
                } else {
                    (thq * thqold).sqrt()
                };
                thqold = thq;
                if self.theta < 0.99 {
                    self.faccon = self.theta / (1.0 - self.theta);
                    let left = (nit - 1 - newt) as i32;
                    let dyth = self.faccon * dyno * self.theta.powi(left) / tol.kappa;
                    if tol.adaptive && dyth >= 1.0 {
                        // predicted not to converge in the iterations left: a smaller step
                        let qnewt = dyth.clamp(1e-4, 20.0);
                        let hhfac = 0.8 * qnewt.powf(-1.0 / (4.0 + left as f64));
                        return Err(fail(hhfac * h, newt, last, None));
                    }
                } else if tol.adaptive || (self.theta >= 2.0 && newt > 3) || dyno > 1e3 * dyn1 {
                    return Err(fail(0.5 * h, newt, last, None));
                } else {
                    // a fixed step cannot shrink: keep iterating through an early transient,
                    // without credit for a contraction not yet seen. The ratio of corrections
                    // is a poor guide early on when the frozen matrices lag a fast rotation:
                    // on the tumbling body at h = 1 ms the residual falls 40× in the first
                    // iteration while the correction, along a soft direction of the
                    // iteration matrix, does not, and the third iteration falls 300×
                    self.faccon = 1.0;
                }
            }
            dynold = dyno.max(f64::EPSILON);
            for (x, d) in self.acc.iter_mut().zip(&self.delta) {
                *x += d;
            }
            for (x, d) in self.lam.iter_mut().zip(&self.dlam) {
                *x += d;
            }
            for (x, d) in self.mu.iter_mut().zip(&self.dmu) {
                *x += d;
            }
            // index 3 and 2: the largest |Φ_i| after this update, predicted from its value
            // before; at index 2 |Φ̇_i| before it (the prediction falls short there: 4e-11
            // after an update predicted below 1e-11 on the pendulum at rtol 1e-4)
            let phi_ok = self.nc == 0
                || (self.phi_max * self.faccon.min(1.0) <= self.tol_phi.max(self.phi_floor)
                    && self.psi_max <= self.tol_phi.max(self.psi_floor));
            residual_only = self.faccon * dyno <= tol.kappa;
            if residual_only && phi_ok {
                self.stages(cur, h);
                // index 2: the new state's |Φ̇| too (the simplified Newton's Z is frozen at
                // the start of the step, so an update may leave Φ̇ above what it was before)
                if !self.index2 || self.final_rate_closed(p, cur.t + h) {
                    return Ok(newt);
                }
            }
        }
    }
}
