//! Backward differentiation formulas of orders 1–5 with variable step and variable order, in
//! the quasi-constant-step, backward-difference form of Shampine & Reichelt, "The MATLAB ODE
//! suite", SIAM J. Sci. Comput. 18 (1997), as in MATLAB's ode15s and SciPy's `BDF` (with the
//! NDF coefficients κ set to 0: plain BDF).
//!
//! On y = (q, qd), f(y) = (qd, qdd), the array D holds the backward differences ∇ʲyₙ of the
//! interpolating polynomial at the equal spacing h, j = 0..k+2. The order-k step is
//!
//! ```text
//! y⁽⁰⁾ = Σ_{j=0..k} ∇ʲyₙ                        (predictor: extrapolated polynomial)
//! Σ_{j=1..k} (1/j) ∇ʲy_{n+1} = h f(y_{n+1})      (BDF k)
//!   ⇔ y_{n+1} = y⁽⁰⁾ − ψ + c f(y_{n+1}),  c = h/γ_k,  ψ = Σ_{j=1..k} γ_j ∇ʲyₙ / γ_k,
//! ```
//!
//! with γ_j = Σ_{i=1..j} 1/i. Written for the two halves of y, with the acceleration
//! a = qdd_{n+1} as unknown and ŷ = y⁽⁰⁾ − ψ:
//!
//! ```text
//! qd_{n+1} = ŷ_qd + c·a,   q_{n+1} = ŷ_q + c·ŷ_qd + c²·a,   τ(t_{n+1}, q_{n+1}, qd_{n+1}, a) = 0
//! ```
//!
//! solved by Newton on accelerations with β' = c², γ' = c (iteration matrix M + c·C_t +
//! c²·K_t), from the predicted acceleration ψ_qd/c.
//!
//! - Order k, A-stable for k ≤ 2, A(α)-stable for k = 3, 4, 5 (α = 86°, 73°, 52°): the
//!   high-frequency modes are damped (stiffly accurate, L-stable for k ≤ 2), so BDF suits stiff
//!   springs but dissipates lightly damped oscillations of hω ≳ 1 at low orders.
//! - Local error: (1/(k+1))·∇^{k+1}y_{n+1} = (1/(k+1))·(y_{n+1} − y⁽⁰⁾), in the weighted RMS norm
//!   of (q, qd). A failed test shrinks h by max(0.2, s·err^(−1/(k+1))), s = 0.9·(2m+1)/(2m+i)
//!   with i Newton iterations out of m allowed.
//! - Step change: when h changes (error test, order selection, the driver clipping to h_max or
//!   to an output stop), D is re-sampled at the new spacing (the R·U matrices of Shampine &
//!   Reichelt), so the formulas keep their constant-step coefficients.
//! - Order and step selection after k+1 steps of constant h and order: the error estimates of
//!   orders k−1 (from ∇ᵏy_{n+1}), k and k+1 (from ∇^{k+2}y_{n+1}) give the step factors
//!   err^(−1/(order+1)); the order with the largest factor is taken (so the order changes by at
//!   most one), and h grows by at most 10 (a rejection resets the count, so h never grows right
//!   after a rejection). Between selections h stays constant, so an error that grows within
//!   those k + 1 steps is met by a rejection rather than by shrinking h ahead (≈ 10 % of the
//!   attempts on the double pendulum). Newton failure: h/4, with the failure's cause.
//! - Start at order 1 from D = (y₀, h·f(y₀)) with the driver's first step.
//! - Fixed steps: constant h and no error test, the order rising by one each step up to
//!   `max_order` (step s uses order min(s, max_order): every point of its formula has been
//!   computed). The order-1 first step limits fixed-step accuracy to O(h²) from the start;
//!   variable order is meant to be used adaptively.
//! - Dense output: the driver's quintic Hermite interpolation of (q, qd, qdd) at the step ends.
//!
//! Every buffer is allocated in [`Bdf::new`]; steps allocate nothing.

use super::at::{Affine, Weights};
use super::newton::AccelNewton;
use super::problem::Problem;
use super::step_control::{elementary_factor, optimal_factor};
use super::{Attempt, Control, State, Step, Stepper};
use crate::error::Failure;
use crate::model::Model;

const MAX_ORDER: usize = 5;
/// γ_k = Σ_{i=1..k} 1/i
const GAMMA: [f64; MAX_ORDER + 1] = [0.0, 1.0, 1.5, 11.0 / 6.0, 25.0 / 12.0, 137.0 / 60.0];
/// step factor limits: shrinking by at most 5 on a rejection, growing by at most 10
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;

/// The error constant of order k: local error ≈ ∇^{k+1}y_{n+1}/(k+1).
fn error_const(k: usize) -> f64 {
    1.0 / (k as f64 + 1.0)
}

/// The matrix R(k, ρ) of Shampine & Reichelt: R[i][j] = Π_{l=1..i} (l − 1 − ρ j)/l.
fn compute_r(k: usize, rho: f64) -> [[f64; MAX_ORDER + 1]; MAX_ORDER + 1] {
    let mut r = [[0.0; MAX_ORDER + 1]; MAX_ORDER + 1];
    for j in 0..=k {
        r[0][j] = 1.0;
    }
    for i in 1..=k {
        for j in 1..=k {
            r[i][j] = r[i - 1][j] * (i as f64 - 1.0 - rho * j as f64) / i as f64;
        }
    }
    r
}

pub(crate) struct Bdf {
    n: usize,
    max_order: usize,
    /// order of the next step
    order: usize,
    /// the spacing D is sampled at
    h: f64,
    /// accepted steps since the last change of step or order
    n_equal: usize,
    /// D: row j (length 2n, q then qd) = ∇ʲyₙ, j = 0..=MAX_ORDER+2
    d: Vec<f64>,
    /// scratch for re-sampling D
    tmp: Vec<f64>,
    /// predictor y⁽⁰⁾, then ŷ = y⁽⁰⁾ − ψ
    ypred: Vec<f64>,
    psi: Vec<f64>,
    /// y_{n+1} − y⁽⁰⁾ = ∇^{k+1}y_{n+1} of the last attempt
    corr: Vec<f64>,
    err: Vec<f64>,
    y0: Vec<f64>,
    y1: Vec<f64>,
    qhat: Vec<f64>,
    vhat: Vec<f64>,
    a: Vec<f64>,
    /// decided by the last accepted attempt, applied in `accepted`
    next_order: usize,
    reselected: bool,
    newton: AccelNewton,
}

impl Bdf {
    pub fn new(n: usize, max_order: usize) -> Bdf {
        let z = |m: usize| vec![0.0; m];
        Bdf {
            n,
            max_order: max_order.clamp(1, MAX_ORDER),
            order: 1,
            h: 1.0,
            n_equal: 0,
            d: z((MAX_ORDER + 3) * 2 * n),
            tmp: z((MAX_ORDER + 1) * 2 * n),
            ypred: z(2 * n),
            psi: z(2 * n),
            corr: z(2 * n),
            err: z(2 * n),
            y0: z(2 * n),
            y1: z(2 * n),
            qhat: z(n),
            vhat: z(n),
            a: z(n),
            next_order: 1,
            reselected: false,
            newton: AccelNewton::new(n),
        }
    }

    /// Re-samples D[0..=k] (the interpolating polynomial of degree k) at spacing ρ·h.
    fn rescale(&mut self, rho: f64) {
        let k = self.order;
        let m = 2 * self.n;
        let r = compute_r(k, rho);
        let u = compute_r(k, 1.0);
        let mut ru = [[0.0; MAX_ORDER + 1]; MAX_ORDER + 1];
        for i in 0..=k {
            for j in 0..=k {
                ru[i][j] = (0..=k).map(|l| r[i][l] * u[l][j]).sum();
            }
        }
        // D_new[j] = Σ_i RU[i][j] D[i]
        for j in 0..=k {
            let t = &mut self.tmp[j * m..(j + 1) * m];
            t.fill(0.0);
            for i in 0..=k {
                let w = ru[i][j];
                if w != 0.0 {
                    let di = &self.d[i * m..(i + 1) * m];
                    for (x, y) in t.iter_mut().zip(di) {
                        *x += w * y;
                    }
                }
            }
        }
        self.d[..(k + 1) * m].copy_from_slice(&self.tmp[..(k + 1) * m]);
        self.h *= rho;
        self.n_equal = 0;
    }
}

impl<M: Model> Stepper<M> for Bdf {
    fn start(&mut self, _p: &mut Problem<M>, s: &State, _ctl: &Control) -> Result<(), Failure> {
        let n = self.n;
        self.d.fill(0.0);
        // D = (y₀, 1·f(y₀)) sampled at h = 1; the first attempt re-samples it at its step
        self.d[..n].copy_from_slice(&s.q);
        self.d[n..2 * n].copy_from_slice(&s.qd);
        self.d[2 * n..3 * n].copy_from_slice(&s.qd);
        self.d[3 * n..4 * n].copy_from_slice(&s.qdd);
        self.h = 1.0;
        self.order = 1;
        self.next_order = 1;
        self.n_equal = 0;
        Ok(())
    }

    fn attempt(&mut self, step: Step<'_, M>) -> Result<Attempt, Failure> {
        let Step(p, cur, h, ctl, next) = step;
        let (n, m, k) = (self.n, 2 * self.n, self.order);
        // steps on a fixed grid differ from h in the last bits: not a change of step
        if (h - self.h).abs() > 1e-10 * self.h {
            self.rescale(h / self.h);
        }
        // predictor and ψ
        self.ypred.copy_from_slice(&self.d[..m]);
        self.psi.fill(0.0);
        for j in 1..=k {
            let g = GAMMA[j] / GAMMA[k];
            let row = &self.d[j * m..(j + 1) * m];
            for i in 0..m {
                self.ypred[i] += row[i];
                self.psi[i] += g * row[i];
            }
        }
        let c = h / GAMMA[k];
        for i in 0..n {
            let yq = self.ypred[i] - self.psi[i];
            let yv = self.ypred[n + i] - self.psi[n + i];
            self.qhat[i] = yq + c * yv;
            self.vhat[i] = yv;
            self.a[i] = self.psi[n + i] / c;
        }
        let step = Affine {
            t: cur.t + h,
            qhat: &self.qhat,
            vhat: &self.vhat,
            w: Weights {
                beta: c * c,
                gamma: c,
            },
        };
        let r = self.newton.solve(p, step, &mut self.a, &ctl.newton);
        let iterations = match r {
            Ok(it) => it,
            Err(f) => {
                return Ok(f.reject(h));
            }
        };
        for i in 0..n {
            next.q[i] = self.newton.q()[i];
            next.qd[i] = self.newton.v()[i];
            next.qdd[i] = self.a[i];
            self.corr[i] = next.q[i] - self.ypred[i];
            self.corr[n + i] = next.qd[i] - self.ypred[n + i];
        }
        let Some(tol) = ctl.adaptive else {
            // fixed steps: raise the order by one per step, no error test
            self.next_order = (k + 1).min(self.max_order);
            self.reselected = self.next_order != k;
            p.watch_accepted(cur.t + h, &next.q)?;
            return Ok(Attempt::Accepted { h_next: h });
        };
        for i in 0..n {
            self.y0[i] = cur.q[i];
            self.y0[n + i] = cur.qd[i];
            self.y1[i] = next.q[i];
            self.y1[n + i] = next.qd[i];
        }
        let maxit = ctl.newton.max_iterations as f64;
        let safety = 0.9 * (2.0 * maxit + 1.0) / (2.0 * maxit + iterations as f64);
        for i in 0..m {
            self.err[i] = error_const(k) * self.corr[i];
        }
        let err = tol.error_norm(&self.err, &self.y0, &self.y1);
        if !(err <= 1.0) {
            let fac = elementary_factor(err, k, safety, MIN_FACTOR, f64::INFINITY);
            return Ok(Attempt::RejectedError { h_next: h * fac });
        }
        self.next_order = k;
        self.reselected = false;
        let mut h_next = h;
        if self.n_equal >= k {
            // orders k − 1, k, k + 1: errors from ∇ᵏy_{n+1} = ∇ᵏyₙ + corr and
            // ∇^{k+2}y_{n+1} = corr − ∇^{k+1}yₙ
            let err_m = if k > 1 {
                for i in 0..m {
                    self.err[i] = error_const(k - 1) * (self.d[k * m + i] + self.corr[i]);
                }
                tol.error_norm(&self.err, &self.y0, &self.y1)
            } else {
                f64::INFINITY
            };
            let err_p = if k < self.max_order {
                for i in 0..m {
                    self.err[i] = error_const(k + 1) * (self.corr[i] - self.d[(k + 1) * m + i]);
                }
                tol.error_norm(&self.err, &self.y0, &self.y1)
            } else {
                f64::INFINITY
            };
            // step factors err^(−1/(order+1)); the first of the largest wins
            let facs = [
                optimal_factor(err_m, k - 1),
                optimal_factor(err, k),
                optimal_factor(err_p, k + 1),
            ];
            let mut best = 0;
            for (i, f) in facs.iter().enumerate() {
                if *f > facs[best] {
                    best = i;
                }
            }
            self.next_order = k + best - 1;
            self.reselected = true;
            h_next = h * (safety * facs[best]).min(MAX_FACTOR);
        }
        p.watch_accepted(cur.t + h, &next.q)?;
        Ok(Attempt::Accepted { h_next })
    }

    fn accepted(&mut self, p: &mut Problem<M>, _prev: &State, cur: &State) {
        let (n, m, k) = (self.n, 2 * self.n, self.order);
        p.stats.record_order(k);
        // ∇^{k+2}y_{n+1} = corr − ∇^{k+1}yₙ, ∇^{k+1}y_{n+1} = corr, ∇ʲy_{n+1} = ∇ʲyₙ + ∇^{j+1}y_{n+1}
        for i in 0..m {
            let c = self.corr[i];
            self.d[(k + 2) * m + i] = c - self.d[(k + 1) * m + i];
            self.d[(k + 1) * m + i] = c;
        }
        for j in (0..=k).rev() {
            let (lo, hi) = self.d.split_at_mut((j + 1) * m);
            for (x, y) in lo[j * m..].iter_mut().zip(&hi[..m]) {
                *x += y;
            }
        }
        // the state the driver holds (equal up to rounding)
        self.d[..n].copy_from_slice(&cur.q);
        self.d[n..m].copy_from_slice(&cur.qd);
        self.n_equal += 1;
        if self.reselected {
            self.order = self.next_order;
            self.n_equal = 0;
        }
    }
}
