//! Radau in the stabilized index-2 form (Gear, Gupta & Leimkuhler 1985): the stage
//! multipliers M_i of the velocity constraints as unknowns besides (A_i, Λ_i), the blocks
//! bordered by both constraint rows, and the error estimate for an index-2 DAE.

use super::super::State;
use super::super::constrained::rate_floor;
use super::super::problem::Problem;
use super::estimate::floored;
use super::{Radau, Tol};
use crate::error::Failure;
use crate::linalg::Field;
use crate::options::IterationMatrix;

impl Radau {
    /// Index 2: whether `own_end` holds the last accepted step's own end values (none since a
    /// start or a re-centring).
    pub(super) fn own_end_valid(&self) -> bool {
        self.index2 && self.h_prev > 0.0
    }

    /// Index 2: K̃Bᵀ (n × nc), BBᵀ and ZBᵀ (nc × nc) of the frozen K̃ = K_t − ∂(Bᵀλ)/∂q, B and
    /// Z = ∂(B v + Φ_t)/∂q, the blocks of μ in the iteration matrix.
    pub(super) fn index2_matrices(&mut self) {
        let (n, nc) = (self.n, self.nc);
        for k in 0..nc {
            for i in 0..n {
                self.i2.kbt[i + n * k] = (0..n)
                    .map(|j| self.km[i + n * j] * self.bm[k + nc * j])
                    .sum();
            }
            for l in 0..nc {
                self.i2.bbt[k + nc * l] = (0..n)
                    .map(|j| self.bm[k + nc * j] * self.bm[l + nc * j])
                    .sum();
                self.i2.zbt[k + nc * l] = (0..n)
                    .map(|j| self.i2.z[k + nc * j] * self.bm[l + nc * j])
                    .sum();
            }
        }
    }

    /// Index 2: Z = ∂(B v + Φ_t)/∂q at the start of the step (q₀, qd₀), B(q₀) in `bm` (zero
    /// with `MassOnly`). The Φ̇ rows of the iteration matrix need it: the stage positions move
    /// with the accelerations as h²μ² against hμ for the velocities, so leaving it out costs
    /// Newton a contraction of about h·‖Z‖/‖B‖ per iteration, which limited the steps of fast
    /// loops.
    pub(super) fn rate_jacobian(&mut self, p: &mut Problem, cur: &State) {
        if p.iteration == IterationMatrix::MassOnly {
            self.i2.z.fill(0.0);
        } else if let Some(c) = p.loops.closed_mut() {
            c.rate_jacobian(
                p.model.erased(),
                &mut p.stats,
                cur.t,
                &cur.q,
                &cur.qd,
                &self.bm,
                &mut self.i2.z,
            );
        }
    }

    /// Index 2: the stage position corrections B₀ᵀM_j of the current stage multipliers μ
    /// into `bmu` (stage j at j·n..).
    pub(super) fn position_corrections(&mut self) {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
        for j in 0..s {
            for r in 0..n {
                self.bmu[j * n + r] = (0..nc)
                    .map(|k| self.bm[k + nc * r] * self.mu[j * nc + k])
                    .sum();
            }
        }
    }

    /// Index 2: the accelerations and multipliers of an accepted step from the index-1
    /// equations at its (q, qd), in place of the last stage's: λ (and with it qdd = A_s) is
    /// of order s only, and the interpolant between outputs, which uses qdd at both ends,
    /// carried that error into the velocities between steps (Cash's pendulum at rtol 1e-8:
    /// 2e-9 between steps against 4e-11 at them). One evaluation of M and h and one solve
    /// of the bordered system per step.
    pub(super) fn consistent_end(
        &mut self,
        p: &mut Problem,
        t: f64,
        next: &mut State,
    ) -> Result<(), Failure> {
        if !self.index2 {
            return Ok(());
        }
        p.accel(t, &next.q, &next.qd, &mut next.qdd)?;
        if let Some(c) = p.loops.closed() {
            next.lambda[..self.nc].copy_from_slice(&c.lambda);
        }
        Ok(())
    }

    /// Index 2: whether |Φ̇| = |B(Q_s)V_s + Φ_t| of the last stage (the new state), at t, is
    /// within the constraint tolerance, or within what rounding leaves of it (`rate_floor`).
    pub(super) fn final_rate_closed(&mut self, p: &mut Problem, t: f64) -> bool {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
        let (lo, hi) = ((s - 1) * n, s * n);
        let Some(c) = p.loops.closed_mut() else {
            return true;
        };
        c.eval_b(p.model.erased(), &mut p.stats, t, &self.qs[lo..hi]);
        p.model.constraint_rate(t, &self.qs[lo..hi], &mut self.phit);
        p.stats.constraints += 1;
        let v = &self.vs[lo..hi];
        let rate = (0..nc)
            .map(|k| (self.phit[k] + (0..n).map(|j| c.b[k + nc * j] * v[j]).sum::<f64>()).abs())
            .fold(0.0, f64::max);
        rate <= self.tol_phi.max(rate_floor(&c.b, nc, v, &self.phit))
    }

    /// Index 2: the weighted RMS of the stage position corrections h Σ_j a_ij B₀ᵀδM_j
    /// (sum of squares, added to Newton's norm).
    pub(super) fn mu_correction_sum(&self, h: f64) -> f64 {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
        let mut sum = 0.0;
        for i in 0..s {
            for r in 0..n {
                let mut x = 0.0;
                for j in 0..s {
                    let btd: f64 = (0..nc)
                        .map(|k| self.bm[k + nc * r] * self.dmu[j * nc + k])
                        .sum();
                    x += self.k.a[i][j] * btd;
                }
                let e = h * x / self.scq[r];
                sum += e * e;
            }
        }
        sum
    }

    /// Index 2: the filter (E − gJ)⁻¹ on y = (q, v, λ, μ), E = diag(I, M, 0, 0),
    /// f = (v + B₀ᵀμ, h + Bᵀλ, Φ, Bv + Φ_t), in second-order form with the real block:
    ///
    /// [M + gC + g²K̃, −Bᵀ, g²K̃Bᵀ; B, 0, BBᵀ; B, 0, 0] (e_v, g e_λ, e_μ)
    ///   = (b_v − gK̃ r_q, −(Φ + B r_q)/g, −Φ̇/g),   e_q = r_q + g (e_v + Bᵀe_μ);
    ///
    /// into `err` as (e_q, e_v + h M_d⁻¹Bᵀe_λ): λ's error by the velocities it moves in one
    /// step, each coordinate by its own inertia M_ii (M_d, the diagonal of M; module notes,
    /// "λ in the error test"); `phix` and `psix` hold Φ and Φ̇ (zero for the first estimate).
    /// `tmp` keeps (e_v, g e_λ, e_μ) for the estimate's second evaluation.
    fn filter2(&mut self, p: &mut Problem, g: f64, h: f64) {
        let (n, nc) = (self.n, self.nc);
        self.filter_rhs(g);
        for k in 0..nc {
            self.tmp[n + nc + k] = -self.psix[k] / g;
        }
        self.lu_r.solve(&mut self.tmp);
        p.stats.solves += 1;
        let least = self.least_inertia();
        for i in 0..n {
            let btm: f64 = (0..nc)
                .map(|k| self.bm[k + nc * i] * self.tmp[n + nc + k])
                .sum();
            self.err[i] = self.rq[i] + g * (self.tmp[i] + btm);
            // the velocities that e_v and e_λ move in one step
            self.err[n + i] = self.tmp[i] + self.lambda_velocity(i, h, g, least);
        }
    }

    /// Index 2: RADAU5's estimate for the index-2 DAE E y' = f(y); q and qd are differential
    /// components (unscaled), λ an index-2 one, measured by the velocities h M_d⁻¹Bᵀe_λ it
    /// moves (`filter2`), μ (zero on the exact solution) left out.
    pub(super) fn estimate2(
        &mut self,
        p: &mut Problem,
        cur: &State,
        next: &State,
        h: f64,
        tol: &Tol,
    ) -> f64 {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
        let g = self.k.gamma0 * self.h_r;
        self.embedded_difference(cur, h);
        // the positions' derivative has B₀ᵀμ too: Σ_i e_i (hA B₀ᵀM)_i = h Σ_j (b̂ − b)_j B₀ᵀM_j
        for r in 0..n {
            self.rq[r] += h
                * (0..s)
                    .map(|j| self.k.db[j] * self.bmu[j * n + r])
                    .sum::<f64>();
        }
        self.mass_times_rv();
        // γ₀h Φ(q₀) and γ₀h Φ̇(q₀, v₀): below the constraint tolerance, taken as 0
        self.phix.fill(0.0);
        self.psix.fill(0.0);
        self.filter2(p, g, h);
        let mut err = self.error_over_motion(cur, next, tol);
        if err >= 1.0 && (self.first || self.reject) {
            // RADAU5: f(y₀ + err) in place of f(y₀); its position row less f_q(y₀) is
            // e_v + B₀ᵀe_μ (e_μ still in `tmp`)
            for r in 0..n {
                let btm: f64 = (0..nc)
                    .map(|k| self.bm[k + nc * r] * self.tmp[n + nc + k])
                    .sum();
                self.rq[r] += g * (self.tmp[r] + btm);
            }
            // e_v and e_λ as the filter solved them (`tmp`), not as the norm weighs them
            for r in 0..n {
                self.qx[r] = cur.q[r] + self.err[r];
                self.vx[r] = cur.qd[r] + self.tmp[r];
            }
            for k in 0..nc {
                let lambda0 = if self.own_end_valid() {
                    self.own_end[n + k]
                } else {
                    cur.lambda[k]
                };
                self.lx[k] = lambda0 + self.tmp[n + k] / g;
            }
            if self.residual_at(p, cur) {
                if let Some(c) = p.loops.closed_mut() {
                    // Φ̇ at (q₀ + e_q, v₀ + e_v), with B(q₀ + e_q) from `residual_at`
                    p.model.constraint_rate(cur.t, &self.qx, &mut self.psix);
                    p.stats.constraints += 1;
                    for k in 0..nc {
                        self.psix[k] += (0..n).map(|j| c.b[k + nc * j] * self.vx[j]).sum::<f64>();
                    }
                }
                for r in 0..n {
                    self.bv[r] -= g * self.ax[r];
                }
                if self.psix.iter().all(|x| x.is_finite()) {
                    self.filter2(p, g, h);
                    err = self.motion_norm(tol);
                }
            }
        }
        floored(err)
    }
}

/// The frozen matrices that border an index-2 block besides B: K̃Bᵀ (n × nc), BBᵀ,
/// Z = ∂(B v + Φ_t)/∂q at the start of the step (nc × n) and ZBᵀ (nc × nc).
#[derive(Default)]
pub(super) struct Blocks {
    pub kbt: Vec<f64>,
    pub bbt: Vec<f64>,
    pub z: Vec<f64>,
    pub zbt: Vec<f64>,
}

/// Borders the n × n block of the (n + 2nc) × (n + 2nc) column-major matrix `a` for the
/// stabilized index-2 form: columns of Λ (−Bᵀ), of μ (g2·K̃Bᵀ over BBᵀ), rows of Φ (B, 0,
/// BBᵀ) and of Φ̇ (B + g1·Z, 0, g1·ZBᵀ); `g1` = hμ and `g2` = h²μ² of the block.
pub(super) fn border2<T: Field>(
    a: &mut [T],
    b: &[f64],
    m: &Blocks,
    g1: T,
    g2: T,
    n: usize,
    nc: usize,
) {
    let Blocks { kbt, bbt, z, zbt } = m;
    let big = n + 2 * nc;
    for j in n..big {
        for i in 0..big {
            a[i + big * j] = T::default();
        }
    }
    for j in 0..n {
        for k in 0..nc {
            let bkj = T::from_f64(b[k + nc * j]);
            a[j + big * (n + k)] = -bkj;
            a[(n + k) + big * j] = bkj;
            a[(n + nc + k) + big * j] = bkj + g1 * T::from_f64(z[k + nc * j]);
            a[j + big * (n + nc + k)] = g2 * T::from_f64(kbt[j + n * k]);
        }
    }
    for k in 0..nc {
        for l in 0..nc {
            a[(n + k) + big * (n + nc + l)] = T::from_f64(bbt[k + nc * l]);
            a[(n + nc + k) + big * (n + nc + l)] = g1 * T::from_f64(zbt[k + nc * l]);
        }
    }
}
