//! Radau at index 3 (and what the stabilized index-2 form shares with it): the stage
//! multipliers as unknowns, B and ∂(Bᵀλ)/∂q frozen with the iteration matrices, and the
//! bordered blocks.

use super::super::State;
use super::super::constrained::{closure_floor, rate_floor};
use super::super::problem::Problem;
use super::Radau;
use crate::error::Failure;
use crate::linalg::{C64, Field, Lu};
use crate::options::IterationMatrix;

impl Radau {
    /// Solves for (A_i, Λ_i) at index 3, or for (A_i, Λ_i, M_i) in the stabilized index-2 form
    /// (`index2`), from now on: `nc` constraints, |Φ_i| (and at index 2 |Φ̇_i|) ≤ `tol_phi` at
    /// convergence. The only allocation: the augmented matrices and their buffers.
    pub(super) fn enable_constraints(&mut self, nc: usize, tol_phi: f64, index2: bool) {
        let (n, s) = (self.n, self.k.s);
        self.tol_phi = tol_phi;
        if self.nc == nc && self.index2 == index2 {
            // a restart (after a controller's sample): the buffers are there
            self.h_c = f64::NAN;
            self.h_r = f64::NAN;
            return;
        }
        let z = |k: usize| vec![0.0; k];
        // the blocks' size: n + nc at index 3, n + 2nc at index 2 (μ too)
        let big = n + if index2 { 2 * nc } else { nc };
        self.nc = nc;
        self.index2 = index2;
        self.tol_phi = tol_phi;
        self.ainv = inverse_row_norm(&self.k.a, s);
        self.a2inv = inverse_row_norm(&self.k.a2, s);
        self.lu_r = Lu::new(big);
        self.lu_c = Lu::new(big);
        self.h_c = f64::NAN;
        self.h_r = f64::NAN;
        self.rho_r = z(big);
        self.rho_c = vec![C64::default(); big];
        self.tmp = z(big);
        self.bm = z(nc * n);
        self.kc = z(n * n);
        self.lam = z(s * nc);
        self.lam_prev = z(s * nc);
        self.phis = z(s * nc);
        self.dlam = z(s * nc);
        self.scl = z(nc);
        self.err = z(2 * n + nc);
        self.y0 = z(2 * n + nc);
        self.y1 = z(2 * n + nc);
        self.bv = z(n);
        self.phix = z(nc);
        self.lx = z(nc);
        if index2 {
            self.mu = z(s * nc);
            self.dmu = z(s * nc);
            self.bmu = z(s * n);
            self.psis = z(s * nc);
            self.phit = z(nc);
            self.i2 = super::index2::Blocks {
                kbt: z(n * nc),
                bbt: z(nc * nc),
                z: z(nc * n),
                zbt: z(nc * nc),
            };
            self.own_end = z(n + nc);
            self.psix = z(nc);
        }
    }

    /// Index 3: ∂(Bᵀλ)/∂q and B at the start of the step (with λ₀), frozen with M, C_t, K_t;
    /// K_t − ∂(Bᵀλ)/∂q replaces K_t in `km`.
    pub(super) fn constraint_matrices(
        &mut self,
        p: &mut Problem,
        cur: &State,
    ) -> Result<(), Failure> {
        let (n, nc) = (self.n, self.nc);
        if p.iteration != IterationMatrix::MassOnly {
            p.model
                .constraint_tangent(cur.t, &cur.q, &cur.lambda, &mut self.kc);
            p.stats.constraints += 1;
            p.check("∂(Bᵀλ)/∂q", &self.kc)?;
            for (k, c) in self.km.iter_mut().zip(&self.kc) {
                *k -= c;
            }
        }
        if let Some(c) = p.loops.closed_mut() {
            c.eval_b(p.model.erased(), &mut p.stats, cur.t, &cur.q);
            self.bm.copy_from_slice(&c.b);
        }
        Failure::non_finite("B = ∂Φ/∂q", &self.bm, |i| p.label((i / nc).min(n - 1)))?;
        if self.index2 {
            self.rate_jacobian(p, cur);
            Failure::non_finite("∂(B qd + Φ_t)/∂q", &self.i2.z, |i| {
                p.label((i / nc).min(n - 1))
            })?;
            self.index2_matrices();
        }
        Ok(())
    }

    /// Index 3 and 2, stage i: r_i −= B(Q_i)ᵀΛ_i, Φ(Q_i, t) into `phis`, the largest |Φ_i|
    /// kept; at index 2 also Φ̇_i = B(Q_i)V_i + Φ_t(Q_i, t) into `psis` (its largest |Φ̇_i| in
    /// `psi_max`).
    pub(super) fn constraint_residual(
        &mut self,
        p: &mut Problem,
        i: usize,
        t: f64,
    ) -> Result<(), Failure> {
        let (n, nc) = (self.n, self.nc);
        let (lo, hi) = (i * n, (i + 1) * n);
        if let Some(c) = p.loops.closed_mut() {
            c.eval_b(p.model.erased(), &mut p.stats, t, &self.qs[lo..hi]);
            c.eval_phi(p.model.erased(), &mut p.stats, t, &self.qs[lo..hi]);
            let lam = &self.lam[i * nc..(i + 1) * nc];
            for j in 0..n {
                self.res[lo + j] -= (0..nc).map(|k| c.b[k + nc * j] * lam[k]).sum::<f64>();
            }
            self.phis[i * nc..(i + 1) * nc].copy_from_slice(&c.phi);
            self.phi_max = self.phi_max.max(c.worst().0);
            let floor = closure_floor(&c.b, nc, &self.qs[lo..hi]);
            self.phi_floor = self.phi_floor.max(floor);
            if self.index2 {
                p.model.constraint_rate(t, &self.qs[lo..hi], &mut self.phit);
                p.stats.constraints += 1;
                let v = &self.vs[lo..hi];
                for k in 0..nc {
                    let x = self.phit[k] + (0..n).map(|j| c.b[k + nc * j] * v[j]).sum::<f64>();
                    self.psis[i * nc + k] = x;
                    self.psi_max = self.psi_max.max(x.abs());
                }
                let floor = rate_floor(&c.b, nc, v, &self.phit);
                self.psi_floor = self.psi_floor.max(floor);
            }
        }
        p.check("τ − Bᵀλ", &self.res[lo..hi])
    }
}

/// Borders the n × n block of the (n + nc) × (n + nc) column-major matrix `a` with −Bᵀ
/// (columns n..) and B (rows n..), and zeroes the corner (B nc × n, column-major).
pub(super) fn border<T: Field>(a: &mut [T], b: &[f64], n: usize, nc: usize) {
    let big = n + nc;
    for j in 0..n {
        for k in 0..nc {
            let bkj = b[k + nc * j];
            a[j + big * (n + k)] = T::from_f64(-bkj);
            a[(n + k) + big * j] = T::from_f64(bkj);
        }
    }
    for j in n..big {
        for i in n..big {
            a[i + big * j] = T::default();
        }
    }
}

/// ‖X⁻¹‖∞ (largest absolute row sum) of an invertible s × s matrix X, s ≤ 3 (Gauss–Jordan).
pub(super) fn inverse_row_norm(x: &[[f64; 3]; 3], s: usize) -> f64 {
    let mut a = *x;
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate().take(s) {
        row[i] = 1.0;
    }
    for k in 0..s {
        let p = (k..s)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
            .unwrap_or(k);
        a.swap(k, p);
        inv.swap(k, p);
        let d = a[k][k];
        for j in 0..s {
            a[k][j] /= d;
            inv[k][j] /= d;
        }
        for i in (0..s).filter(|&i| i != k) {
            let f = a[i][k];
            for j in 0..s {
                a[i][j] -= f * a[k][j];
                inv[i][j] -= f * inv[k][j];
            }
        }
    }
    (0..s)
        .map(|i| (0..s).map(|j| inv[i][j].abs()).sum::<f64>())
        .fold(0.0, f64::max)
}
