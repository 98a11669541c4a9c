//! Newton on accelerations, shared by every implicit scheme. Each scheme writes its step as
//! positions and velocities affine in the unknown accelerations a,
//! q = q̂ + β'·a, v = v̂ + γ'·a, and solves τ(t, q, v, a) = M a − h = 0 with the iteration
//! matrix ∂τ/∂a = M + γ'·C_t + β'·K_t (modified Newton: the factorisation is reused across
//! iterations and steps while convergence is fast, refreshed when it slows or fails).
//! Convergence follows Hairer & Wanner: with the contraction θ = ‖δ_k‖/‖δ_{k−1}‖, stop when
//! θ/(1 − θ)·‖δ_k‖ ≤ κ in the norm of the position and velocity corrections.
//!
//! ## Index 3
//! With constraints solved at index 3 (`Index3Newton::enable`), the unknowns are (a, λ) and
//! the equations τ(t, q, v, a) − B(q)ᵀλ = 0, Φ(q, t)/β' = 0, with the iteration matrix
//!
//! ```text
//! [ M + γ'C_t + β'(K_t − ∂(Bᵀλ)/∂q)   −Bᵀ ]
//! [ B                                   0  ]
//! ```
//!
//! Dividing the constraint rows by β' = O(h²) is the scaling of Bottasso, Dopico & Trainelli
//! (2008) written for acceleration unknowns: unscaled (rows β'B, residual Φ) the condition
//! number grows as h⁻², scaled it stays bounded as h → 0. The λ corrections count in the
//! convergence norm with the Newton tolerance; every weight is floored at the variable's
//! rounding noise (a rounding error ε|q| in Φ moves λ by ε|q|/β' and v by ε|q|γ'/β'), so that
//! tight tolerances at small steps do not ask for digits that do not exist. Convergence also
//! requires the predicted |Φ_i| after the update to be below the constraint tolerance. The matrix is made afresh at every
//! step (kept only within it): on the index-3 pendulum, matrices kept across steps needed
//! 2–3 times the iterations of fresh ones and left λ less converged.
//!
//! ## Index 2
//! With the stabilized index-2 form (`AccelNewton::enable_index2`), the positions also move
//! along B(q₀)ᵀ by a second multiplier ν (scaled: q = q̂ + β'(a + B₀ᵀν)), and the unknowns
//! (a, λ, ν) solve τ − Bᵀλ = 0, Φ/β' = 0, (B v + Φ_t)/γ' = 0 with
//!
//! ```text
//! [ M + γ'C_t + β'(K_t − ∂(Bᵀλ)/∂q)   −Bᵀ   0    ]
//! [ B                                   0    B B₀ᵀ ]
//! [ B                                   0    0    ]
//! ```
//!
//! plus, in the Φ̇ rows, β'/γ'·Z (along a) and β'/γ'·Z B₀ᵀ (along ν), Z = ∂(B v + Φ_t)/∂q by
//! forward differences (n evaluations of B and Φ_t per matrix; without it Newton took 3.2
//! iterations per step on the four-bar at h = 1 ms, with it 2.0, index 3 1.8); the O(h²)
//! coupling β'K_t B₀ᵀ is left out. Φ̇ = 0 fixes a across the constraints, so the rounding
//! floors are ε|q| for q, ε|v| for v and ε|v|/γ' for λ; convergence requires |Φ_i| and
//! |Φ̇_i|/max(1, |v|) below the constraint tolerance.

use super::at::{Affine, At, Weights};
use super::constrained::closure_floor;
use super::problem::Problem;
use super::step_control::Argmax;
use crate::error::Failure;
use crate::linalg::Lu;
use crate::options::IterationMatrix;

const INDEX3_MATRIX: &str = "the index-3 iteration matrix [M + γ'C + β'K, −Bᵀ; B, 0]";
/// What a singular stabilized index-2 iteration matrix is named.
const INDEX2_MATRIX: &str = "the stabilized index-2 iteration matrix [M + γ'C + β'K, −Bᵀ, 0; B, 0, B B₀ᵀ; B + (β'/γ')Z, 0, (β'/γ')Z B₀ᵀ]";

/// Weights of the convergence test: a correction δq_i counts as δq_i / (atol + rtol·|q_i|),
/// likewise for velocities; converged when the predicted remaining correction is ≤ κ.
#[derive(Clone, Copy, Debug)]
pub(crate) struct NewtonTol {
    pub atol: f64,
    pub rtol: f64,
    pub kappa: f64,
    pub max_iterations: usize,
    pub reuse: bool,
    /// Radau: the contraction below which its matrices are kept for the next step (`None`:
    /// by their cost)
    pub keep_below: Option<f64>,
    /// fixed steps: the absolute part of each kind's weight (positions, velocities,
    /// multipliers) is atol or rtol times the largest value of that kind the step handles,
    /// whichever is smaller ([`NewtonTol::absolute`])
    pub follows_motion: bool,
}

impl NewtonTol {
    /// The absolute part of the weights of a kind whose largest value in the step is
    /// `largest`. At a fixed step there is no error tolerance for Newton's to follow, and an
    /// atol in SI units is loose for a motion whose values are small in them: the 8-bar chain
    /// 10⁶ times longer (its velocities 10³ times slower) under Newmark and the midpoint
    /// rule at the same dimensionless step ended 1.1e-4 rad from the unit chain's angles
    /// after 2 s of the unit chain's time. Where the kind is at zero, atol; where its values
    /// are rounding errors, the iteration also converges on a correction within atol
    /// itself (`settled` in [`AccelNewton::solve_index3`]).
    pub fn absolute(&self, largest: f64) -> f64 {
        if self.follows_motion && largest > 0.0 {
            self.atol.min(self.rtol * largest)
        } else {
            self.atol
        }
    }
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
    /// index 3: constraints, scaling and tolerance on Φ, and buffers
    nc: usize,
    scaled: bool,
    /// [`super::constrained::multiplier_scale`] at the matrix last made: the rounding floor
    /// of λ's corrections scales with it
    sigma: f64,
    tol_phi: f64,
    l0: Vec<f64>,
    phi_max: f64,
    /// what rounding leaves of Φ at the last residual ([`closure_floor`])
    phi_floor: f64,
    /// stabilized index 2: the second multiplier ν (scaled: q = q̂ + β'(a + B₀ᵀν)), its
    /// guess, B₀ = B(q₀) of the step's start, and Φ_t
    index2: bool,
    nu: Vec<f64>,
    b0: Vec<f64>,
    phi_t: Vec<f64>,
    /// index 2: B at the matrix's q and Z = ∂(B v + Φ_t)/∂q there (nc × n)
    bq: Vec<f64>,
    z: Vec<f64>,
    mm: Vec<f64>,
    kc: Vec<f64>,
    valid: bool,
    /// (β', γ') the factorisation was made with
    coeffs: (f64, f64),
    refresh: bool,
    eta: f64,
    q: Vec<f64>,
    v: Vec<f64>,
    r: Vec<f64>,
    a0: Vec<f64>,
    /// the component of the last iteration's correction with the largest weighted term:
    /// (block, index), block 0 positions, 1 velocities, 2 multipliers
    pub largest: Option<(usize, usize)>,
}

impl AccelNewton {
    pub fn new(n: usize) -> AccelNewton {
        AccelNewton {
            lu: Lu::new(n),
            n,
            nc: 0,
            scaled: true,
            sigma: 1.0,
            tol_phi: f64::INFINITY,
            l0: Vec::new(),
            phi_max: 0.0,
            phi_floor: 0.0,
            index2: false,
            nu: Vec::new(),
            b0: Vec::new(),
            phi_t: Vec::new(),
            bq: Vec::new(),
            z: Vec::new(),
            mm: Vec::new(),
            kc: Vec::new(),
            valid: false,
            coeffs: (f64::NAN, f64::NAN),
            refresh: true,
            eta: 1.0,
            q: vec![0.0; n],
            v: vec![0.0; n],
            r: vec![0.0; n],
            a0: vec![0.0; n],
            largest: None,
        }
    }

    /// Solves for (a, λ) at index 3 from now on: `nc` constraints, the constraint rows
    /// scaled by 1/β' when `scaled`, |Φ_i| ≤ `tol_phi` at convergence.
    pub fn enable_index3(&mut self, nc: usize, scaled: bool, tol_phi: f64) {
        self.enable(nc, false, scaled, tol_phi);
    }

    /// Drops the factorised matrix: the next solve makes a fresh one (a rotation joint's
    /// chart moved, so the coordinates mean another configuration).
    pub fn forget(&mut self) {
        self.valid = false;
    }

    /// Solves the stabilized index-2 step for (a, λ, ν) from now on (see the module notes):
    /// as [`AccelNewton::enable_index3`], with Φ̇ = 0 too. Each step's B₀ is set by
    /// [`AccelNewton::index2_start`].
    pub fn enable_index2(&mut self, nc: usize, scaled: bool, tol_phi: f64) {
        self.enable(nc, true, scaled, tol_phi);
    }

    fn enable(&mut self, nc: usize, index2: bool, scaled: bool, tol_phi: f64) {
        let (n, z) = (self.n, |k: usize| vec![0.0; k]);
        self.scaled = scaled;
        self.tol_phi = tol_phi;
        self.valid = false;
        if self.nc == nc && self.index2 == index2 {
            // a restart: the buffers are there
            return;
        }
        self.nc = nc;
        self.index2 = index2;
        let rows = if index2 { n + 2 * nc } else { n + nc };
        self.lu = Lu::new(rows);
        self.r = z(rows);
        self.l0 = z(nc);
        (self.mm, self.kc) = (z(n * n), z(n * n));
        if index2 {
            (self.nu, self.b0, self.phi_t) = (z(nc), z(nc * n), z(nc));
            (self.bq, self.z) = (z(nc * n), z(nc * n));
        }
        self.valid = false;
    }

    /// Stabilized index 2: B₀ = B(q₀) at the start (t₀, q₀) of the step to solve, along
    /// which the second multiplier moves the positions; ν starts from zero.
    pub fn index2_start(&mut self, p: &mut Problem, t0: f64, q0: &[f64]) {
        if let Some(c) = p.loops.closed_mut() {
            c.eval_b(p.model.erased(), &mut p.stats, t0, q0);
            self.b0.copy_from_slice(&c.b);
        }
        self.nu.fill(0.0);
    }

    /// Solves τ(t, q̂ + β'a, v̂ + γ'a, a) = 0; `a` holds the guess and receives the solution.
    /// Returns the iterations used. `q` and `v` of the solution are then in [`AccelNewton::q`]
    /// and [`AccelNewton::v`].
    pub fn solve(
        &mut self,
        p: &mut Problem,
        step: Affine,
        a: &mut [f64],
        tol: &NewtonTol,
    ) -> Result<usize, NewtonFail> {
        self.solve_index3(p, step, a, &mut [], tol)
    }

    /// [`AccelNewton::solve`] with the multipliers λ as unknowns too (after
    /// [`AccelNewton::enable_index3`]; `lambda` empty otherwise).
    pub fn solve_index3(
        &mut self,
        p: &mut Problem,
        step: Affine,
        a: &mut [f64],
        lambda: &mut [f64],
        tol: &NewtonTol,
    ) -> Result<usize, NewtonFail> {
        let (t, w) = (step.t, step.w);
        let Weights { beta, gamma } = w;
        let nc = lambda.len();
        debug_assert_eq!(nc, self.nc);
        self.a0.copy_from_slice(a);
        self.l0.copy_from_slice(lambda);
        // an iteration matrix made for a step within 20 % of this one is still a good
        // approximation (modified Newton); the contraction test refreshes it when it is not
        let close = |x: f64, y: f64| (x - y).abs() <= 0.2 * x.abs().max(y.abs());
        let same = close(self.coeffs.0, beta) && close(self.coeffs.1, gamma);
        let mut total = 0;
        let mut last = f64::INFINITY;
        for pass in 0..2 {
            // index 3: a fresh matrix at every step (see the module notes)
            let fresh = !(tol.reuse && self.valid && same && !self.refresh && pass == 0 && nc == 0);
            if pass == 1 {
                // the reused matrix failed: start again from the guess with a fresh one
                a.copy_from_slice(&self.a0);
                lambda.copy_from_slice(&self.l0);
                self.nu.fill(0.0);
            }
            if fresh {
                self.affine(step, a);
                let made = if nc == 0 {
                    p.iteration_matrix(At::new(t, &self.q, &self.v), a, w, &mut self.lu)
                } else {
                    self.index3_matrix(p, t, a, lambda, w).and_then(|_| {
                        p.stats.factorizations += 1;
                        let name = if self.index2 {
                            INDEX2_MATRIX
                        } else {
                            INDEX3_MATRIX
                        };
                        self.lu
                            .factor_equilibrating()
                            .map_err(|s| p.singular(name, s))
                    })
                };
                if let Err(e) = made {
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
            let mut settled = false;
            // the absolute weights of q, v and λ, at fixed steps from the values the step
            // handles
            let (atol_q, atol_v, atol_l) = if tol.follows_motion {
                let peak = |x: &[f64]| x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let amax = peak(a);
                (
                    tol.absolute(peak(step.qhat) + beta * amax),
                    tol.absolute(peak(step.vhat) + gamma * amax),
                    tol.absolute(peak(lambda)),
                )
            } else {
                (tol.atol, tol.atol, tol.atol)
            };
            for it in 0..tol.max_iterations {
                self.affine(step, a);
                let n = self.n;
                let mut res = p.residual(t, &self.q, &self.v, a, &mut self.r[..n]);
                if nc > 0 && res.is_ok() {
                    res = self.index3_residual(p, t, lambda, w);
                }
                if let Err(e) = res {
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
                // index 3: no variable resolves below the rounding of Φ: q to ~ε|q|, λ to
                // ~ε|q|/β' (Φ/β' is solved for), v = v̂ + γ'a to ~ε|q|γ'/β'
                let (fq, fv, fl) = if self.index2 {
                    // index 2: Φ̇ = 0 fixes a across the constraints to ~ε|v|/γ' (Φ, through
                    // ν, moves q alone): v to ~ε|v|, λ to ~ε|v|/γ'
                    let qmax = self.q.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                    let vmax = self.v.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                    let fv = 10.0 * f64::EPSILON * vmax;
                    (10.0 * f64::EPSILON * qmax, fv, fv * self.sigma / gamma)
                } else if nc > 0 {
                    let qmax = self.q.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                    let fq = 10.0 * f64::EPSILON * qmax;
                    // λ moves by about σ per unit of Φ/β'
                    (fq, fq * gamma / beta, fq * self.sigma / beta)
                } else {
                    (0.0, 0.0, 0.0)
                };
                // s in the weights of the motion's magnitude, plain in those of atol itself
                let (mut s, mut plain) = (0.0, 0.0);
                let mut largest = Argmax::default();
                if self.index2 {
                    for k in 0..nc {
                        self.nu[k] -= self.r[n + nc + k];
                    }
                }
                for i in 0..n {
                    let d = -self.r[i];
                    a[i] += d;
                    // index 2: q moves by β'(δa + B₀ᵀδν)
                    let dq = if self.index2 {
                        d - (0..nc)
                            .map(|k| self.b0[k + nc * i] * self.r[n + nc + k])
                            .sum::<f64>()
                    } else {
                        d
                    };
                    let eq = beta * dq / (atol_q + tol.rtol * self.q[i].abs() + fq);
                    let ev = gamma * d / (atol_v + tol.rtol * self.v[i].abs() + fv);
                    s += eq * eq + ev * ev;
                    if tol.follows_motion {
                        let pq = beta * dq / (tol.atol + tol.rtol * self.q[i].abs() + fq);
                        let pv = gamma * d / (tol.atol + tol.rtol * self.v[i].abs() + fv);
                        plain += pq * pq + pv * pv;
                    }
                    largest.see(eq * eq, 0, i);
                    largest.see(ev * ev, 1, i);
                }
                for k in 0..nc {
                    let d = -self.r[n + k];
                    lambda[k] += d;
                    let el = d / (atol_l + tol.rtol * lambda[k].abs() + fl);
                    s += el * el;
                    if tol.follows_motion {
                        let pl = d / (tol.atol + tol.rtol * lambda[k].abs() + fl);
                        plain += pl * pl;
                    }
                    largest.see(el * el, 2, k);
                }
                self.largest = largest.at;
                let norm = (s / (2 * n + nc).max(1) as f64).sqrt();
                let plain = (plain / (2 * n + nc).max(1) as f64).sqrt();
                // index 3: Φ after this update, predicted from its value before
                let phi_ok = |eta: f64| {
                    nc == 0 || self.phi_max * eta.min(1.0) <= self.tol_phi.max(self.phi_floor)
                };
                settled = tol.follows_motion && plain <= 1e-3 * tol.kappa && phi_ok(1.0);
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
                if (eta * norm <= tol.kappa || norm == 0.0) && phi_ok(eta) {
                    self.eta = eta;
                    self.affine(step, a);
                    return Ok(total);
                }
                prev = norm;
            }
            // stalled or out of iterations at the rounding of the values: where the weights of
            // the motion's magnitude ask for more than it resolves (a fixed step from a static
            // equilibrium at rest, whose velocities and accelerations are rounding errors: the
            // sprung arm so started stopped in Newton at t = 0 under the Newmark family and
            // the midpoint rule), converged if its last correction is within atol itself
            if settled {
                self.eta = 1.0;
                self.affine(step, a);
                return Ok(total);
            }
            if fresh {
                break;
            }
        }
        self.refresh = true;
        a.copy_from_slice(&self.a0);
        lambda.copy_from_slice(&self.l0);
        self.nu.fill(0.0);
        Err(NewtonFail {
            iterations: total,
            correction: last,
            cause: None,
        })
    }

    /// r[..n] −= Bᵀλ at the current q; r[n..n + nc] = Φ(q)/β' (scaled) or Φ(q); index 2:
    /// r[n + nc..] = (B(q)v + Φ_t)/γ' (scaled) or B(q)v + Φ_t.
    fn index3_residual(
        &mut self,
        p: &mut Problem,
        t: f64,
        lambda: &[f64],
        w: Weights,
    ) -> Result<(), Failure> {
        let Weights { beta, gamma } = w;
        let (n, nc) = (self.n, self.nc);
        // open loops have no multipliers and no constraint rows
        if let Some(c) = p.loops.closed_mut() {
            c.eval_b(p.model.erased(), &mut p.stats, t, &self.q);
            c.eval_phi(p.model.erased(), &mut p.stats, t, &self.q);
            for j in 0..n {
                self.r[j] -= (0..nc).map(|k| c.b[k + nc * j] * lambda[k]).sum::<f64>();
            }
            let s = if self.scaled { 1.0 / beta } else { 1.0 };
            for k in 0..nc {
                self.r[n + k] = s * c.phi[k];
            }
            self.phi_max = c.worst().0;
            // Φ (and Φ̇ per unit of velocity scale, whose rounding is within it) closes to
            // the tolerance or to what rounding leaves of it
            self.phi_floor = closure_floor(&c.b, nc, &self.q);
            if self.index2 {
                p.model.constraint_rate(t, &self.q, &mut self.phi_t);
                p.stats.constraints += 1;
                let s = if self.scaled { 1.0 / gamma } else { 1.0 };
                // |Φ̇| counts against the constraint tolerance per unit of velocity scale
                let vmax = self.v.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                for k in 0..nc {
                    let rate =
                        self.phi_t[k] + (0..n).map(|j| c.b[k + nc * j] * self.v[j]).sum::<f64>();
                    self.r[n + nc + k] = s * rate;
                    self.phi_max = self.phi_max.max(rate.abs() / vmax);
                }
            }
        }
        p.check("τ − Bᵀλ", &self.r[..n])
    }

    /// The index-3 iteration matrix at the current (q, v, a, λ), unfactorised, in `self.lu`.
    fn index3_matrix(
        &mut self,
        p: &mut Problem,
        t: f64,
        a: &[f64],
        lambda: &[f64],
        w: Weights,
    ) -> Result<(), Failure> {
        let (n, nc) = (self.n, self.nc);
        let big = if self.index2 { n + 2 * nc } else { n + nc };
        let beta = w.beta;
        p.iteration_block(At::new(t, &self.q, &self.v), a, w, &mut self.mm)?;
        if p.iteration != IterationMatrix::MassOnly {
            p.model.constraint_tangent(t, &self.q, lambda, &mut self.kc);
            p.stats.constraints += 1;
        } else {
            self.kc.fill(0.0);
        }
        // B borders the matrix (nothing for open loops)
        let b: &[f64] = match p.loops.closed_mut() {
            Some(c) => {
                c.eval_b(p.model.erased(), &mut p.stats, t, &self.q);
                &c.b
            }
            None => &[],
        };
        let with_z = self.index2 && p.iteration != IterationMatrix::MassOnly;
        if self.index2 {
            self.bq.copy_from_slice(b);
        }
        if with_z {
            self.rate_jacobian(p, t);
        }
        let b: &[f64] = match (self.index2, p.loops.closed()) {
            (true, _) => &self.bq,
            (false, Some(c)) => &c.b,
            (false, None) => &[],
        };
        let block = (0..n * n).fold(0.0f64, |m, x| m.max((self.mm[x] - beta * self.kc[x]).abs()));
        self.sigma = super::constrained::multiplier_scale(block, b);
        let s = if self.scaled { 1.0 } else { beta };
        let m = self.lu.matrix_mut();
        m.fill(0.0);
        for j in 0..n {
            for i in 0..n {
                let x = i + n * j;
                m[i + big * j] = self.mm[x] - beta * self.kc[x];
            }
            for k in 0..nc {
                let bkj = b[k + nc * j];
                m[j + big * (n + k)] = -bkj;
                m[(n + k) + big * j] = s * bkj;
            }
        }
        if self.index2 {
            // Φ̇ rows: B + β'/γ'·Z along a, β'/γ'·Z B₀ᵀ along ν; Φ rows: B B₀ᵀ along ν
            let s2 = if self.scaled { 1.0 } else { w.gamma };
            let r = if with_z { beta / w.gamma } else { 0.0 };
            for j in 0..n {
                for k in 0..nc {
                    m[(n + nc + k) + big * j] = s2 * (b[k + nc * j] + r * self.z[k + nc * j]);
                }
            }
            for k in 0..nc {
                for l in 0..nc {
                    m[(n + nc + k) + big * (n + nc + l)] = s2
                        * r
                        * (0..n)
                            .map(|j| self.z[k + nc * j] * self.b0[l + nc * j])
                            .sum::<f64>();
                }
            }
            for k in 0..nc {
                for l in 0..nc {
                    m[(n + k) + big * (n + nc + l)] = s
                        * (0..n)
                            .map(|j| b[k + nc * j] * self.b0[l + nc * j])
                            .sum::<f64>();
                }
            }
        }
        Failure::non_finite("iteration matrix", m, |i| p.label((i % big).min(n - 1)))
    }

    /// Index 2: Z = ∂(B v + Φ_t)/∂q at the current (q, v), with B(q) in `self.bq`.
    fn rate_jacobian(&mut self, p: &mut Problem, t: f64) {
        if let Some(c) = p.loops.closed_mut() {
            c.rate_jacobian(
                p.model.erased(),
                &mut p.stats,
                t,
                &self.q,
                &self.v,
                &self.bq,
                &mut self.z,
            );
        }
    }

    /// The index-3 iteration matrix (N × N, N = n + nc, column-major) at (t, q̂ + β'a,
    /// v̂ + γ'a, a, λ), unfactorised: for condition studies.
    pub fn index3_matrix_at(
        &mut self,
        p: &mut Problem,
        at: At,
        a: &[f64],
        lambda: &[f64],
        w: Weights,
    ) -> Result<Vec<f64>, Failure> {
        self.q.copy_from_slice(at.q);
        self.v.copy_from_slice(at.qd);
        self.index3_matrix(p, at.t, a, lambda, w)?;
        self.valid = false;
        Ok(self.lu.matrix_mut().to_vec())
    }

    fn affine(&mut self, step: Affine, a: &[f64]) {
        let Affine {
            qhat,
            vhat,
            w: Weights { beta, gamma },
            ..
        } = step;
        let nc = self.nc;
        for i in 0..self.n {
            // index 2: the second multiplier moves q along B₀ᵀ
            let nu = if self.index2 {
                (0..nc).map(|k| self.b0[k + nc * i] * self.nu[k]).sum()
            } else {
                0.0
            };
            self.q[i] = qhat[i] + beta * (a[i] + nu);
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
