//! The Newmark family in second-order form, one implementation: generalized-α as written by
//! Arnold & Brüls (2007) for nonlinear systems, with an acceleration-like variable a,
//!
//! ```text
//! q₁ = q₀ + h qd₀ + h²(½ − β) a₀ + h² β a₁
//! qd₁ = qd₀ + h (1 − γ) a₀ + h γ a₁
//! (1 − α_m) a₁ + α_m a₀ = (1 − α_f) qdd₁ + α_f qdd₀,   M(q₁) qdd₁ = h(q₁, qd₁)
//! ```
//!
//! - Newmark (1959): α_m = α_f = 0 (a = qdd); (¼, ½) is the trapezoidal rule, order 2, no
//!   numerical damping, unconditionally stable;
//! - HHT-α (Hilber, Hughes & Taylor 1977): α_m = 0, α_f = −α, β = (1 − α)²/4, γ = ½ − α;
//! - generalized-α (Chung & Hulbert 1993): α_m, α_f from ρ∞, order 2, unconditionally stable,
//!   damping the high frequencies to ρ∞ while preserving the low ones.
//!
//! For linear systems the form is equivalent to Chung & Hulbert's. Newton solves for qdd₁
//! with the iteration matrix M + γ'·C_t + β'·K_t, γ' = γ h c, β' = β h² c,
//! c = (1 − α_f)/(1 − α_m). Step control (when adaptive) uses the local error estimate of
//! Zienkiewicz & Xie (1991), e ≈ h² (β − 1/6)(a₁ − a₀), of order 3 in h.
//!
//! ## Constraints at index 3
//! With `Index3`, the step solves M qdd₁ = h₁ + B₁ᵀλ₁, Φ(q₁, t₁) = 0 for (qdd₁, λ₁) (Arnold &
//! Brüls 2007, §4): the positions satisfy the constraints at every step to the constraint
//! tolerance, the velocities only to O(h²). Newton uses the scaled iteration matrix of
//! [`super::newton`]. λ₁ converges with order 2 for ρ∞ < 1; at ρ∞ = 1 (α_m = α_f = ½, and
//! the trapezoidal Newmark) nothing damps the O(h) error the first step leaves in λ, which
//! then oscillates from step to step (Cardona & Géradin 1989).
//!
//! With adaptive steps at index 3 the error estimate is taken along the constraints (its
//! M-orthogonal tangent part: the multipliers' transients move q only across them, where
//! Φ(q₁) = 0 holds anyway); without that, on the index-3 pendulum a third of the attempts
//! were rejected. The positions keep the accuracy asked for; λ does not: each change of step
//! leaves an O(h·Δh/h) transient in λ (the velocities satisfy Φ̇ = 0 only to O(h²), and the
//! balance between that error and λ depends on h), measured up to 1e-3 on the pendulum at
//! rtol 1e-10. For accurate multipliers use fixed steps (λ of order 2 for ρ∞ < 1).

use super::at::{Affine, At, Weights};
use super::constrained::{Constrained, Mode};
use super::newton::AccelNewton;
use super::problem::{Loops, Problem};
use super::step_control::next_step;
use super::{Attempt, Control, State, Step, Stepper};
use crate::error::Failure;
use crate::model::Model;
use crate::options::{GenAlphaParams, HhtParams, NewmarkParams};
use crate::stats::ErrorTest;

pub(crate) struct AlphaFamily {
    alpha_m: f64,
    alpha_f: f64,
    beta: f64,
    gamma: f64,
    n: usize,
    /// acceleration-like variable of the current state, and its candidate for the next
    a: Vec<f64>,
    a_next: Vec<f64>,
    qhat: Vec<f64>,
    vhat: Vec<f64>,
    qdd: Vec<f64>,
    err: Vec<f64>,
    newton: AccelNewton,
    /// index 3: the multipliers being solved for (empty otherwise)
    lam: Vec<f64>,
}

impl AlphaFamily {
    fn new(n: usize, alpha_m: f64, alpha_f: f64, beta: f64, gamma: f64) -> AlphaFamily {
        let z = || vec![0.0; n];
        AlphaFamily {
            alpha_m,
            alpha_f,
            beta,
            gamma,
            n,
            a: z(),
            a_next: z(),
            qhat: z(),
            vhat: z(),
            qdd: z(),
            err: z(),
            newton: AccelNewton::new(n),
            lam: Vec::new(),
        }
    }

    pub fn newmark(n: usize, p: NewmarkParams) -> AlphaFamily {
        AlphaFamily::new(n, 0.0, 0.0, p.beta, p.gamma)
    }

    pub fn hht(n: usize, p: HhtParams) -> AlphaFamily {
        AlphaFamily::new(
            n,
            0.0,
            -p.alpha,
            0.25 * (1.0 - p.alpha) * (1.0 - p.alpha),
            0.5 - p.alpha,
        )
    }

    pub fn gen_alpha(n: usize, p: GenAlphaParams) -> AlphaFamily {
        AlphaFamily::new(n, p.alpha_m, p.alpha_f, p.beta, p.gamma)
    }
}

impl<M: Model> Stepper<M> for AlphaFamily {
    fn error_test(&self, _p: &Problem<M>) -> ErrorTest {
        ErrorTest::Positions
    }

    fn start(&mut self, p: &mut Problem<M>, s: &State, _ctl: &Control) -> Result<(), Failure> {
        self.a.copy_from_slice(&s.qdd);
        if let Some(c) = p.loops.index3() {
            self.newton.enable_index3(c.nc, c.scaling, c.tol);
            if self.lam.len() != c.nc {
                self.lam = vec![0.0; c.nc];
            }
        }
        Ok(())
    }

    fn attempt(&mut self, step: Step<'_, M>) -> Result<Attempt, Failure> {
        let Step(p, cur, h, ctl, next) = step;
        let (am, af, b, g) = (self.alpha_m, self.alpha_f, self.beta, self.gamma);
        // a₁ = c·qdd₁ + a_c, with a_c from the current state
        let c = (1.0 - af) / (1.0 - am);
        for i in 0..self.n {
            let ac = (af * cur.qdd[i] - am * self.a[i]) / (1.0 - am);
            self.qhat[i] = cur.q[i] + h * cur.qd[i] + h * h * ((0.5 - b) * self.a[i] + b * ac);
            self.vhat[i] = cur.qd[i] + h * ((1.0 - g) * self.a[i] + g * ac);
            self.qdd[i] = cur.qdd[i];
        }
        let nl = self.lam.len();
        self.lam.copy_from_slice(&cur.lambda[..nl]);
        let (bp, gp) = (b * h * h * c, g * h * c);
        let step = Affine {
            t: cur.t + h,
            qhat: &self.qhat,
            vhat: &self.vhat,
            w: Weights {
                beta: bp,
                gamma: gp,
            },
        };
        let result = self
            .newton
            .solve_index3(p, step, &mut self.qdd, &mut self.lam, &ctl.newton);
        match result {
            Ok(_) => {}
            Err(f) => {
                return Ok(f.reject(h));
            }
        }
        for i in 0..self.n {
            next.q[i] = self.newton.q()[i];
            next.qd[i] = self.newton.v()[i];
            next.qdd[i] = self.qdd[i];
            self.a_next[i] = c * self.qdd[i] + (af * cur.qdd[i] - am * self.a[i]) / (1.0 - am);
        }
        next.lambda[..self.lam.len()].copy_from_slice(&self.lam);
        let Some(tol) = ctl.adaptive else {
            p.watch_accepted(cur.t + h, &next.q)?;
            return Ok(Attempt::Accepted { h_next: h });
        };
        let k = h * h * (b - 1.0 / 6.0);
        for i in 0..self.n {
            self.err[i] = k * (self.a_next[i] - self.a[i]);
        }
        if !self.lam.is_empty() {
            // index 3: the multipliers' transients move q only across the constraints, where
            // Φ(q₁) = 0 holds anyway; the error is measured along them
            p.tangent_part(cur.t + h, &next.q, &mut self.err)?;
        }
        let err = tol.error_norm(&self.err, &cur.q, &next.q);
        if err <= 1.0 {
            p.watch_accepted(cur.t + h, &next.q)?;
            Ok(Attempt::Accepted {
                h_next: next_step(h, err, 2, 2.0),
            })
        } else {
            Ok(Attempt::RejectedError {
                h_next: next_step(h, err, 2, 1.0),
            })
        }
    }

    fn accepted(&mut self, _p: &mut Problem<M>, _prev: &State, _cur: &State) {
        std::mem::swap(&mut self.a, &mut self.a_next);
    }
}

/// The iteration matrix of an index-3 generalized-α step of size `h` (N × N column-major,
/// N = NQ + NC), evaluated at `state` (q, qd, qdd, λ), with the constraint rows scaled by
/// 1/β' or not: the matrix the integrator factorises, exposed for condition studies.
pub fn index3_iteration_matrix<M: Model>(
    model: M,
    params: GenAlphaParams,
    h: f64,
    state: &State,
    scaled: bool,
) -> Result<Vec<f64>, Failure> {
    let options = crate::options::ConstraintOptions {
        scaling: scaled,
        ..Default::default()
    };
    let mut p = Problem::new(model, crate::options::IterationMatrix::Auto);
    p.loops = Loops::Closed(Box::new(Constrained::new(&p.model, Mode::Index3, &options)));
    let mut newton = AccelNewton::new(M::NQ);
    newton.enable_index3(M::NC, scaled, options.tolerance);
    let c = (1.0 - params.alpha_f) / (1.0 - params.alpha_m);
    let (bp, gp) = (params.beta * h * h * c, params.gamma * h * c);
    newton.index3_matrix_at(
        &mut p,
        At::new(state.t, &state.q, &state.qd),
        &state.qdd,
        &state.lambda,
        Weights {
            beta: bp,
            gamma: gp,
        },
    )
}
