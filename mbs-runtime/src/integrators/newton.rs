//! Newton on accelerations, shared by every implicit scheme. Each scheme writes its step as
//! positions and velocities affine in the unknown accelerations a,
//! q = q̂ + β'·a, v = v̂ + γ'·a, and solves τ(t, q, v, a) = M a − h = 0 with the iteration
//! matrix ∂τ/∂a = M + γ'·C_t + β'·K_t (modified Newton: the factorisation is reused across
//! iterations and steps while convergence is fast, refreshed when it slows or fails).
//! Convergence follows Hairer & Wanner: with the contraction θ = ‖δ_k‖/‖δ_{k−1}‖, stop when
//! θ/(1 − θ)·‖δ_k‖ ≤ κ in the norm of the position and velocity corrections.

use super::problem::Problem;
use crate::error::Failure;
use crate::linalg::Lu;
use crate::model::Model;

/// Weights of the convergence test: a correction δq_i counts as δq_i / (atol + rtol·|q_i|),
/// likewise for velocities; converged when the predicted remaining correction is ≤ κ.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NewtonTol {
    pub atol: f64,
    pub rtol: f64,
    pub kappa: f64,
    pub max_iterations: usize,
    pub reuse: bool,
}

/// How a solve ended when it did not converge.
#[derive(Clone, Debug)]
pub(crate) struct NewtonFail {
    pub iterations: usize,
    pub correction: f64,
    /// an evaluation or factorisation failure during the iterations, if that was the cause
    pub cause: Option<Failure>,
}

impl NewtonFail {
    /// The attempt rejected, with a step a quarter of `h` to try next.
    pub fn reject(self, h: f64) -> super::Attempt {
        super::Attempt::RejectedNewton {
            h_next: 0.25 * h,
            iterations: self.iterations,
            correction: self.correction,
            cause: self.cause,
        }
    }
}

pub(crate) struct AccelNewton {
    pub lu: Lu<f64>,
    n: usize,
    valid: bool,
    /// (β', γ') the factorisation was made with
    coeffs: (f64, f64),
    refresh: bool,
    eta: f64,
    q: Vec<f64>,
    v: Vec<f64>,
    r: Vec<f64>,
    a0: Vec<f64>,
}

impl AccelNewton {
    pub fn new(n: usize) -> AccelNewton {
        AccelNewton {
            lu: Lu::new(n),
            n,
            valid: false,
            coeffs: (f64::NAN, f64::NAN),
            refresh: true,
            eta: 1.0,
            q: vec![0.0; n],
            v: vec![0.0; n],
            r: vec![0.0; n],
            a0: vec![0.0; n],
        }
    }

    /// Solves τ(t, q̂ + β'a, v̂ + γ'a, a) = 0; `a` holds the guess and receives the solution.
    /// Returns the iterations used. `q` and `v` of the solution are then in [`AccelNewton::q`]
    /// and [`AccelNewton::v`].
    #[allow(clippy::too_many_arguments)]
    pub fn solve<M: Model>(
        &mut self,
        p: &mut Problem<M>,
        t: f64,
        qhat: &[f64],
        vhat: &[f64],
        beta: f64,
        gamma: f64,
        a: &mut [f64],
        tol: &NewtonTol,
    ) -> Result<usize, NewtonFail> {
        self.a0.copy_from_slice(a);
        // an iteration matrix made for a step within 20 % of this one is still a good
        // approximation (modified Newton); the contraction test refreshes it when it is not
        let close = |x: f64, y: f64| (x - y).abs() <= 0.2 * x.abs().max(y.abs());
        let same = close(self.coeffs.0, beta) && close(self.coeffs.1, gamma);
        let mut total = 0;
        let mut last = f64::INFINITY;
        for pass in 0..2 {
            let fresh = !(tol.reuse && self.valid && same && !self.refresh && pass == 0);
            if pass == 1 {
                // the reused matrix failed: start again from the guess with a fresh one
                a.copy_from_slice(&self.a0);
            }
            if fresh {
                self.affine(qhat, vhat, beta, gamma, a);
                if let Err(e) =
                    p.iteration_matrix(t, &self.q, &self.v, a, beta, gamma, &mut self.lu)
                {
                    self.valid = false;
                    return Err(NewtonFail {
                        iterations: total,
                        correction: last,
                        cause: Some(e),
                    });
                }
                self.valid = true;
                self.coeffs = (beta, gamma);
                self.refresh = false;
            }
            let mut prev = f64::NAN;
            let mut eta = self.eta.max(f64::EPSILON).powf(0.8);
            for it in 0..tol.max_iterations {
                self.affine(qhat, vhat, beta, gamma, a);
                if let Err(e) = p.residual(t, &self.q, &self.v, a, &mut self.r) {
                    self.valid = false;
                    return Err(NewtonFail {
                        iterations: total,
                        correction: last,
                        cause: Some(e),
                    });
                }
                self.lu.solve(&mut self.r);
                p.stats.solves += 1;
                p.stats.newton_iterations += 1;
                total += 1;
                let mut s = 0.0;
                for i in 0..self.n {
                    let d = -self.r[i];
                    a[i] += d;
                    let eq = beta * d / (tol.atol + tol.rtol * self.q[i].abs());
                    let ev = gamma * d / (tol.atol + tol.rtol * self.v[i].abs());
                    s += eq * eq + ev * ev;
                }
                let norm = (s / (2 * self.n).max(1) as f64).sqrt();
                last = norm;
                if !norm.is_finite() {
                    break;
                }
                if it > 0 {
                    let theta = norm / prev;
                    if theta >= 0.99 {
                        break;
                    }
                    eta = theta / (1.0 - theta);
                    if theta > 0.5 {
                        self.refresh = true;
                    }
                }
                if eta * norm <= tol.kappa || norm == 0.0 {
                    self.eta = eta;
                    self.affine(qhat, vhat, beta, gamma, a);
                    return Ok(total);
                }
                prev = norm;
            }
            if fresh {
                break;
            }
        }
        self.refresh = true;
        a.copy_from_slice(&self.a0);
        Err(NewtonFail {
            iterations: total,
            correction: last,
            cause: None,
        })
    }

    fn affine(&mut self, qhat: &[f64], vhat: &[f64], beta: f64, gamma: f64, a: &[f64]) {
        for i in 0..self.n {
            self.q[i] = qhat[i] + beta * a[i];
            self.v[i] = vhat[i] + gamma * a[i];
        }
    }

    /// Positions of the last solution.
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// Velocities of the last solution.
    pub fn v(&self) -> &[f64] {
        &self.v
    }
}
