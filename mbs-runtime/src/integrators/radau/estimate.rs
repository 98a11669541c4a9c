//! RADAU5's error estimates: the embedded formula filtered by (I − hγ₀J)⁻¹ for the ODE, and
//! its form for the index-3 DAE E y' = f(y).

use super::super::State;
use super::super::problem::Problem;
use super::{Radau, Tol};

impl Radau {
    /// err = (I − gJ)⁻¹ (r_q, r_v) in second-order form, into `err` = (e_q, e_v):
    /// (M + gC + g²K) e_v = M r_v − g K r_q, e_q = r_q + g e_v.
    pub(super) fn filter(&mut self, p: &mut Problem, g: f64) {
        let n = self.n;
        for i in 0..n {
            let mut x = 0.0;
            for j in 0..n {
                x += self.m[i + n * j] * self.rv[j] - g * self.km[i + n * j] * self.rq[j];
            }
            self.tmp[i] = x;
        }
        self.lu_r.solve(&mut self.tmp);
        p.stats.solves += 1;
        for i in 0..n {
            self.err[n + i] = self.tmp[i];
            self.err[i] = self.rq[i] + g * self.tmp[i];
        }
    }

    /// The embedded formula's difference from the step's solution, before filtering, into
    /// (r_q, r_v): r_q = h² Σ d̂_q,j a_j, r_v = h (γ₀ qdd₀ + Σ d̂_b,j a_j).
    pub(super) fn embedded_difference(&mut self, cur: &State, h: f64) {
        let (s, n, g0) = (self.k.s, self.n, self.k.gamma0);
        let own = self.own_end_valid();
        for r in 0..n {
            let (mut x, mut y) = (0.0, 0.0);
            for j in 0..s {
                x += self.k.dq[j] * self.acc[j * n + r];
                y += self.k.db[j] * self.acc[j * n + r];
            }
            self.rq[r] = h * h * x;
            let qdd0 = if own { self.own_end[r] } else { cur.qdd[r] };
            self.rv[r] = h * (g0 * qdd0 + y);
        }
    }

    /// RADAU5's error estimate of the converged step (`next` holds y₁), as a weighted norm.
    pub(super) fn estimate(
        &mut self,
        p: &mut Problem,
        cur: &State,
        next: &State,
        h: f64,
        tol: &Tol,
    ) -> f64 {
        let n = self.n;
        // the filter matrix was factorised with h_r (equal to h up to rounding)
        let g = self.k.gamma0 * self.h_r;
        self.embedded_difference(cur, h);
        self.filter(p, g);
        self.y0[..n].copy_from_slice(&cur.q);
        self.y0[n..].copy_from_slice(&cur.qd);
        self.y1[..n].copy_from_slice(&next.q);
        self.y1[n..].copy_from_slice(&next.qd);
        let mut err = self.weighted_norm(tol);
        if err >= 1.0 && (self.first || self.reject) {
            // RADAU5: replace f(y₀) by f(y₀ + err), which damps the estimate's stiff part
            for r in 0..n {
                self.qx[r] = cur.q[r] + self.err[r];
                self.vx[r] = cur.qd[r] + self.err[n + r];
            }
            if p.accel(cur.t, &self.qx, &self.vx, &mut self.ax).is_ok() {
                for r in 0..n {
                    self.rq[r] += g * self.err[n + r];
                    self.rv[r] += g * (self.ax[r] - cur.qdd[r]);
                }
                self.filter(p, g);
                err = self.weighted_norm(tol);
            }
        }
        floored(err)
    }

    /// The right-hand side the index-3 and index-2 filters share, into `tmp`:
    /// b_v − gK̃ r_q (n rows), then −(Φ + B r_q)/g (nc rows).
    pub(super) fn filter_rhs(&mut self, g: f64) {
        let (n, nc) = (self.n, self.nc);
        for i in 0..n {
            let mut x = self.bv[i];
            for j in 0..n {
                x -= g * self.km[i + n * j] * self.rq[j];
            }
            self.tmp[i] = x;
        }
        for k in 0..nc {
            let brq: f64 = (0..n).map(|j| self.bm[k + nc * j] * self.rq[j]).sum();
            self.tmp[n + k] = -(self.phix[k] + brq) / g;
        }
    }

    /// Index 3: the filter (E − gJ)⁻¹ on y = (q, v, λ), E = diag(I, M, 0), in second-order
    /// form with the real block: [M + gC + g²K̃, −Bᵀ; B, 0] (e_v, g e_λ) =
    /// (b_v − gK̃ r_q, −(Φ + B r_q)/g), e_q = r_q + g e_v; into `err` as
    /// (e_q, h e_v + h² M_d⁻¹Bᵀe_λ), both in positions (M_d the diagonal of M; the module
    /// notes on the error estimate). `tmp` keeps (e_v, g e_λ) for the second evaluation.
    pub(super) fn filter3(&mut self, p: &mut Problem, g: f64, h: f64) {
        let n = self.n;
        self.filter_rhs(g);
        self.lu_r.solve(&mut self.tmp);
        p.stats.solves += 1;
        let least = self.least_inertia();
        for i in 0..n {
            self.err[i] = self.rq[i] + g * self.tmp[i];
            // the positions that e_v and e_λ move in one step
            self.err[n + i] = h * (self.tmp[i] + self.lambda_velocity(i, h, g, least));
        }
    }

    /// The velocity of coordinate i that λ's error moves in a step h: h (Bᵀe_λ)_i over its own
    /// inertia M_ii, not below `least` ([`Self::least_inertia`]); e_λ is `tmp[n..n + nc]`
    /// over g, as the filters solve it. A generalised force over an inertia, times a time: in
    /// the units of qd whatever the model's.
    pub(super) fn lambda_velocity(&self, i: usize, h: f64, g: f64, least: f64) -> f64 {
        let (n, nc) = (self.n, self.nc);
        let btl: f64 = (0..nc).map(|k| self.bm[k + nc * i] * self.tmp[n + k]).sum();
        h * btl / (g * self.m[i + n * i].max(least))
    }

    /// 1e-12 of M's largest diagonal entry, the least inertia [`Self::lambda_velocity`]
    /// divides by (which a positive definite M never falls below in practice).
    pub(super) fn least_inertia(&self) -> f64 {
        let n = self.n;
        1e-12 * (0..n).fold(0.0f64, |m, i| m.max(self.m[i + n * i]))
    }

    /// The weighted norm of `err`'s two position-valued blocks (index 3: e_q, and what e_v
    /// and e_λ move the positions in a step), both against the positions' weights.
    fn error_in_positions(&mut self, cur: &State, next: &State, tol: &Tol) -> f64 {
        self.norm_against([&cur.q, &cur.q], [&next.q, &next.q], tol)
    }

    /// [`Self::motion_norm`] with the weights of its two blocks taken from `before` and
    /// `after` (stacked into `y0`, `y1`).
    fn norm_against(&mut self, before: [&[f64]; 2], after: [&[f64]; 2], tol: &Tol) -> f64 {
        let n = self.n;
        for (b, (y0, y1)) in before.iter().zip(&after).enumerate() {
            self.y0[b * n..(b + 1) * n].copy_from_slice(y0);
            self.y1[b * n..(b + 1) * n].copy_from_slice(y1);
        }
        self.motion_norm(tol)
    }

    /// bv = M r_v: the velocity row's bracket of the constrained estimates (index 3 and 2).
    pub(super) fn mass_times_rv(&mut self) {
        let n = self.n;
        for i in 0..n {
            self.bv[i] = (0..n).map(|j| self.m[i + n * j] * self.rv[j]).sum();
        }
    }

    /// The weighted norm of `err` against the states stacked in `y0`, `y1` (q and qd, then
    /// λ), noting whether the rounding floor set a weight (`Stats::floored_steps`).
    pub(super) fn weighted_norm(&mut self, tol: &Tol) -> f64 {
        let norm = tol.weights.norm(&self.err, &self.y0, &self.y1, self.n);
        self.test = norm;
        norm.value
    }

    /// The weighted norm of `err`'s positions and velocities alone, the weights taken from
    /// the states before and after the step (index 2, where λ's error is in the velocities').
    pub(super) fn error_over_motion(&mut self, cur: &State, next: &State, tol: &Tol) -> f64 {
        self.norm_against([&cur.q, &cur.qd], [&next.q, &next.qd], tol)
    }

    /// [`Self::weighted_norm`] over the positions and velocities alone.
    pub(super) fn motion_norm(&mut self, tol: &Tol) -> f64 {
        let n = self.n;
        let norm = tol
            .weights
            .norm(&self.err[..2 * n], &self.y0[..2 * n], &self.y1[..2 * n], n);
        self.test = norm;
        norm.value
    }

    /// Index 3: RADAU5's estimate for the DAE E y' = f(y), y = (q, v, λ), f = (v, h + Bᵀλ,
    /// Φ), the velocities' and multipliers' errors counted by the positions they move in a
    /// step (h e_v + h² M_d⁻¹Bᵀe_λ), where RADAU5 weighs them by h and h² in their own units.
    pub(super) fn estimate3(
        &mut self,
        p: &mut Problem,
        cur: &State,
        next: &State,
        h: f64,
        tol: &Tol,
    ) -> f64 {
        let (n, nc) = (self.n, self.nc);
        let g = self.k.gamma0 * self.h_r;
        self.embedded_difference(cur, h);
        // the velocity row's bracket M r_v (γ₀h f_v(y₀) = g M qdd₀ with qdd₀, λ₀ consistent);
        // the constraint row's γ₀h Φ(q₀) ≈ 0 (|Φ(q₀)| is within the Newton tolerance)
        self.mass_times_rv();
        self.phix.fill(0.0);
        self.filter3(p, g, h);
        let mut err = self.error_in_positions(cur, next, tol);
        if err >= 1.0 && (self.first || self.reject) {
            // RADAU5: f(y₀ + err) in place of f(y₀); its velocity row, less M qdd₀, is
            // −(τ(q₀ + e_q, v₀ + e_v, qdd₀) − Bᵀ(λ₀ + e_λ)) up to O(e_q) terms
            for r in 0..n {
                self.qx[r] = cur.q[r] + self.err[r];
                self.vx[r] = cur.qd[r] + self.tmp[r];
            }
            for k in 0..nc {
                self.lx[k] = cur.lambda[k] + self.tmp[n + k] / g;
            }
            if self.residual_at(p, cur) {
                for r in 0..n {
                    self.rq[r] += g * self.tmp[r];
                    self.bv[r] -= g * self.ax[r];
                }
                self.filter3(p, g, h);
                err = self.motion_norm(tol);
            }
        }
        floored(err)
    }

    /// τ(t₀, qx, vx, qdd₀) − B(qx)ᵀ lx into `ax` and Φ(qx) into `phix`; false when an
    /// evaluation fails or is not finite.
    pub(super) fn residual_at(&mut self, p: &mut Problem, cur: &State) -> bool {
        let (n, nc) = (self.n, self.nc);
        let qdd0: &[f64] = if self.own_end_valid() {
            &self.own_end[..n]
        } else {
            &cur.qdd
        };
        if p.residual(cur.t, &self.qx, &self.vx, qdd0, &mut self.ax)
            .is_err()
        {
            return false;
        }
        if let Some(c) = p.loops.closed_mut() {
            c.eval_b(p.model.erased(), &mut p.stats, cur.t, &self.qx);
            c.eval_phi(p.model.erased(), &mut p.stats, cur.t, &self.qx);
            for j in 0..n {
                self.ax[j] -= (0..nc).map(|k| c.b[k + nc * j] * self.lx[k]).sum::<f64>();
            }
            self.phix.copy_from_slice(&c.phi);
        }
        self.ax.iter().chain(&self.phix).all(|x| x.is_finite())
    }
}

/// An error estimate as the step test reads it: at least 1e-10, and a NaN estimate (an
/// overflowing filter) a failed test, not a pass.
pub(super) fn floored(err: f64) -> f64 {
    if err.is_nan() {
        f64::INFINITY
    } else {
        err.max(1e-10)
    }
}
