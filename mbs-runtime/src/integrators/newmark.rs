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
//! c = (1 − α_f)/(1 − α_m).
//!
//! ## Step control: what rtol means
//! Step control (when adaptive) uses the local error estimate of Zienkiewicz & Xie (1991) for
//! the positions, e_q ≈ h² (β − 1/6)(a₁ − a₀), of order 3 in h. Without constraints, with
//! projection, Baumgarte or partitioning and at index 3, that is the whole test
//! (`ErrorTest::Positions`); at index 2 it covers positions and velocities
//! (`ErrorTest::PositionsVelocities`):
//!
//! - velocities: the leading term of their local error, e_qd ≈ C·h³·q⁽⁴⁾ with
//!   C = ½((1 − γ)δ² + γ(1 + δ)²) − ⅙, δ = α_m − α_f (a ≈ qdd(t + δh), Arnold & Brüls 2007;
//!   1/12 for the trapezoidal rule), q⁽⁴⁾ ≈ 2·qdd[t₋₁, t₀, t₁] from the accelerations of the
//!   last three states (none on the first step after a start), plus (γ − ½ + δ)·h·Δqdd for a
//!   first-order Newmark (γ ≠ ½);
//! - when the step changes, a is rescaled (a − qdd ≈ δ·h·q⁽³⁾ was made with the previous
//!   step): without it the damped members lose their order 2 in qd at every change of step,
//!   which the velocity estimate saw (a third of the steps rejected on pendulum3).
//!
//! Either test is held against a transformed tolerance: a step h is accepted when the RMS norm
//! of the estimate is ≤ 1 against rtol·f, atol·f, f = 0.3·√rtol, so rtol' = 0.3·rtol^1.5. An
//! order-2 scheme whose local error is held at tol per step has a global error ∝ tol^⅔; this
//! makes it follow rtol. f ≥ 10⁴ε/rtol: no local tolerance below 10⁴ε (at index 2 the rounding
//! of the accelerations would reject the step; with the positions alone 100ε would do, but the
//! tumbling body at rtol 1e-10 then took more than 10⁶ steps). No weight f·(atol + rtol·|y_i|)
//! counts below 100ε times the largest entry of its kind, as in every scheme's test (taken
//! before the factor f, that floor sat f times lower, below rounding: the four-bar in
//! micrometres, its velocities of 10⁴ rad/s weighed at atol·f ≈ 1e-13 rad/s under rtol 1e-7,
//! stopped at h_min at index 2). Newton's tolerance follows
//! (rtol·f, atol·f, floored at 4ε). 0.3 is measured. At index 3, whose test sees the
//! positions alone while the velocities, of order 2 too, go untested, f = 0.07·√rtol and the
//! floor is 10³ε: with 0.3 its runs fell 0.9–3.1 digits short of rtol, up to 1.42 digits below
//! the median of the other schemes at the same rtol (HHT on Cash's pendulum at rtol 1e-4:
//! 2.58 digits against 4.07), now 0.5–2.4 short and within a digit of that median (a local
//! tolerance 4.3 times tighter: for order 2 about 4.3^⅓ ≈ 1.6 times the steps); the lower
//! floor keeps the digits following rtol to ≈ 2e-8 where they stalled from ≈ 4e-8 (the
//! Cartesian double pendulum at rtol 1e-8: 7.04 digits where 6.27).
//!
//! Measured (`cargo test --release --test tolerance_proportionality -- --nocapture`): the
//! largest mixed error over (q, qd) (Test Set for IVP Solvers, floor 0.01) as digits on
//! pendulum3, the Cartesian double pendulum, the four-bar, slider-crank (a) and fastlink. From
//! rtol 1e-4 to 1e-7 the digits gain 1.0–1.1 per decade at index 2 (gen-α at ρ∞ 0.8: pendulum3
//! 4.07 5.07 6.07 7.07, four-bar 2.47 3.63 4.69 5.71, fastlink 1.86 3.08 4.18 5.22), 1.0–1.4
//! with projection or partitioning, 0.8–1.1 on average at index 3; they land from 0.1 digits
//! better than rtol to 2.2 short at index 2, 0.2–2.8 short with projection, from 0.1 better to
//! 2.8 short with partitioning and 0.5–2.4 short at index 3, the amplifying loops (four-bar, slider-crank, fastlink) the
//! furthest. Below rtol 1e-7 (2e-8 at index 3) the local tolerance reaches its floor, the
//! runs at 1e-8 still gain 0.18–0.78 digits over 1e-7 (the test asserts every form to 1e-8
//! but gen-α with projection, 1.09 digits below the others' median there on pendulum3), and
//! below it the digits stall (6.3–7.5 on pendulum3, 4.6–6.5 on the loops). Before the transformation (the test per step at
//! rtol itself, as at index 3 and with projection until then) the runs fell 2.9–5.5 digits
//! short of rtol on average, gaining ⅔ of a digit per decade. The transformation costs what order 2 costs: dpend to 2 s at rtol
//! 1e-6 takes 14,957 steps where the per-step test took 1,001 (`tests/work_counters.rs`),
//! and on stiff models the high frequencies a step load excites are resolved rather than
//! damped away (`tests/hard_cases/chain16.rs`: HHT 34,839 steps where it took 341 and lost
//! 2 % of the energy). An error per unit step (rtol·h/1 s) was tried first at index 2: it
//! failed on fastlink (30 ms) at every rtol, its steps falling to 1e-12 s. The velocity
//! estimate stays with index 2: on stiff models (the spring pendulum at k = 1e6, the stiff
//! chain of `tests/hard_cases/`) it took the runs past a million steps.

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
//!
//! At index 3 the error test controls the **positions only** (`ErrorTest::Positions`): the
//! velocity estimate sees the multipliers' transients in qdd, and with it the adaptive
//! index-3 runs of the slider-crank and the four-bar stopped with `StepTooSmall` at every
//! rtol. The velocities, whose Φ̇ is only O(h²), are not tested; they follow the positions
//! at the scheme's order 2, 0.5–2.4 digits short of rtol with the tighter local tolerance
//! index 3 takes (above) where index 2 is 0.1 better to 2.2 short: use index 2 for them.
//!
//! ## Constraints at index 2 (on request)
//! With `Index2`, the stabilized index-2 generalized-α of Arnold, Brüls & Cardona (2015,
//! after Gear, Gupta & Leimkuhler): a second multiplier ν corrects the positions,
//!
//! ```text
//! q₁ = q₀ + h qd₀ + h²(½ − β) a₀ + h² β (a₁ + B(q₀)ᵀν)
//! M(q₁) qdd₁ = h(q₁, qd₁) + B(q₁)ᵀλ₁,   Φ(q₁, t₁) = 0,   B(q₁) qd₁ + Φ_t(q₁, t₁) = 0
//! ```
//!
//! (ν scaled by β'; its direction taken at the start of the step, B(q₀)ᵀ rather than
//! B(q₁)ᵀ: they differ by O(h)·ν, and the step stays affine in (a, ν)). Newton solves for
//! (qdd₁, λ₁, ν) with the scaled matrix of [`super::newton`]. Positions and velocities both
//! satisfy the constraints at every step to the constraint tolerance; q, qd and λ converge
//! with order 2 at fixed steps for ρ∞ < 1 (`tests/newmark_index2.rs`: pendulum3, orders 2.00
//! at h = 8 … 1 ms), and the error test covers q and qd (`ErrorTest::PositionsVelocities`).
//! Newton takes about as many iterations as at index 3 (four-bar at h = 1 ms: 2.0 against
//! 1.8 per step), its matrix n more evaluations of B and Φ_t. It is not the default: for the
//! same digits in (q, qd) index 3 is cheaper (`examples/work_precision.rs`, fastlink: gen-α
//! at 3 digits 47 ms at index 2 and 24 ms at index 3, at 5 digits 434 ms and 247 ms). The
//! undamped members (ρ∞ = 1) are refused with adaptive steps, as at index 3: on
//! the fast loops (slider-crank, four-bar) their accelerations oscillate from step to step
//! and the adaptive runs took 15–25 times the steps of gen-α.

use super::at::{Affine, At, Weights};
use super::constrained::{Constrained, Mode};
use super::newton::{AccelNewton, NewtonTol};
use super::problem::{Loops, Problem};
use super::step_control::{
    ErrorNorm, Largest, Tolerances, next_step, order_two_factor, order_two_floored,
};
use super::{Attempt, Control, State, Step, Stepper};
use crate::charts::Recentring;
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
    /// a rescaled to the attempted step
    a0: Vec<f64>,
    qhat: Vec<f64>,
    vhat: Vec<f64>,
    qdd: Vec<f64>,
    err: Vec<f64>,
    /// the velocities' error estimate
    err_v: Vec<f64>,
    /// qdd of the accepted state before the current one and the step between them, for the
    /// velocities' estimate (`None` after a start)
    qdd_prev: Vec<f64>,
    h_prev: Option<f64>,
    newton: AccelNewton,
    /// index 3 and index 2: the multipliers being solved for (empty otherwise)
    lam: Vec<f64>,
    /// the constraints are solved at index 2
    index2: bool,
    /// the last error test
    test: ErrorNorm,
}

impl AlphaFamily {
    fn new(n: usize, alpha_m: f64, alpha_f: f64, beta: f64, gamma: f64) -> AlphaFamily {
        let z = || vec![0.0; n];
        AlphaFamily {
            test: ErrorNorm::default(),
            alpha_m,
            alpha_f,
            beta,
            gamma,
            n,
            a: z(),
            a_next: z(),
            a0: z(),
            qhat: z(),
            vhat: z(),
            qdd: z(),
            err: z(),
            err_v: z(),
            qdd_prev: z(),
            h_prev: None,
            newton: AccelNewton::new(n),
            lam: Vec::new(),
            index2: false,
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

/// The local error allowed is rtol' = `TOL_FACTOR`·rtol^1.5 (atol alike), which makes the
/// global error of an order-2 scheme follow rtol (see the module notes); 0.3 is measured.
const TOL_FACTOR: f64 = 0.3;

/// The least local tolerance, 10⁴ε: at index 2 the rounding of the accelerations would reject
/// the step below it; where the test sees positions only, 100ε would do, but an order-2 scheme
/// then takes millions of steps at rtol 1e-10 (the tumbling body to 10 s: more than 10⁶).
const FLOOR: f64 = 1e4 * f64::EPSILON;

/// At index 3 (positions alone tested, velocities of order 2 untested): rtol' =
/// `TOL_FACTOR_INDEX3`·rtol^1.5, measured so that its runs land within a digit of the other
/// schemes at the same rtol (with 0.3 the index-3 runs fell up to 1.4 digits below their
/// median); the floor 10³ε, so that the digits still follow rtol to ≈ 2e-8.
const TOL_FACTOR_INDEX3: f64 = 0.07;

/// The least local tolerance at index 3, 10³ε (see [`TOL_FACTOR_INDEX3`]).
const FLOOR_INDEX3: f64 = 1e3 * f64::EPSILON;

impl AlphaFamily {
    /// The constraints are solved at index 3.
    fn index3(&self) -> bool {
        !self.lam.is_empty() && !self.index2
    }

    /// The factor c of the local tolerance c·rtol^1.5 and its floor: smaller at index 3,
    /// whose test sees the positions alone (see the module notes).
    fn tolerance_map(&self) -> (f64, f64) {
        if self.index3() {
            (TOL_FACTOR_INDEX3, FLOOR_INDEX3)
        } else {
            (TOL_FACTOR, FLOOR)
        }
    }

    /// C of the velocities' local error C·h³·q⁽⁴⁾: with a ≈ qdd(t + δh), δ = α_m − α_f
    /// (Arnold & Brüls 2007) and γ = ½ − δ, qd₀ + h((1 − γ)a₀ + γa₁) differs from the Taylor
    /// series by (½((1 − γ)δ² + γ(1 + δ)²) − ⅙)·h³·q⁽⁴⁾ (1/12 for the trapezoidal rule).
    fn velocity_error_constant(&self) -> f64 {
        let (d, g) = (self.alpha_m - self.alpha_f, self.gamma);
        0.5 * ((1.0 - g) * d * d + g * (1.0 + d) * (1.0 + d)) - 1.0 / 6.0
    }
}

impl Stepper for AlphaFamily {
    fn last_test(&self) -> ErrorNorm {
        self.test
    }

    fn newton_largest(&self) -> Option<(usize, usize)> {
        self.newton.largest
    }

    fn tolerance_floor(&self, rtol: f64) -> Option<f64> {
        let (c, floor) = self.tolerance_map();
        order_two_floored(rtol, c, floor)
    }

    fn error_test(&self, p: &Problem) -> ErrorTest {
        match p.loops.closed() {
            Some(c) if c.mode == Mode::Index2 => ErrorTest::PositionsVelocities,
            _ => ErrorTest::Positions,
        }
    }

    fn start(&mut self, p: &mut Problem, s: &State, _ctl: &Control) -> Result<(), Failure> {
        self.a.copy_from_slice(&s.qdd);
        self.h_prev = None;
        let solved = p
            .loops
            .closed()
            .filter(|c| matches!(c.mode, Mode::Index3 | Mode::Index2));
        if let Some(c) = solved {
            self.index2 = c.mode == Mode::Index2;
            if self.index2 {
                self.newton.enable_index2(c.nc, c.scaling, c.tol);
            } else {
                self.newton.enable_index3(c.nc, c.scaling, c.tol);
            }
            if self.lam.len() != c.nc {
                self.lam = vec![0.0; c.nc];
            }
        }
        Ok(())
    }

    /// The auxiliary acceleration is mapped as an acceleration; the velocities' estimate
    /// starts again (its last acceleration is of another configuration).
    fn rechart(
        &mut self,
        _p: &mut Problem,
        s: &State,
        _ctl: &Control,
        moved: &[Recentring],
        evaluated: bool,
    ) -> Result<(), Failure> {
        if evaluated {
            // coordinates of the model's own that the map does not cover (a wrapper's): the
            // acceleration-like variable starts again from the accelerations, as at t₀
            self.a.copy_from_slice(&s.qdd);
        } else {
            for r in moved {
                r.map_acceleration(&mut self.a);
            }
        }
        self.h_prev = None;
        self.newton.forget();
        Ok(())
    }

    fn attempt(&mut self, step: Step<'_>) -> Result<Attempt, Failure> {
        let Step(p, cur, h, ctl, next) = step;
        let (am, af, b, g) = (self.alpha_m, self.alpha_f, self.beta, self.gamma);
        // a₁ = c·qdd₁ + a_c, with a_c from the current state
        let c = (1.0 - af) / (1.0 - am);
        // index 2: a − qdd ≈ (α_m − α_f)·h·q⁽³⁾ with the step that made a, rescaled to this
        // step, which keeps the order 2 of the damped members when the step changes
        let ratio = match self.h_prev {
            Some(hp) if self.index2 => h / hp,
            _ => 1.0,
        };
        for i in 0..self.n {
            self.a0[i] = cur.qdd[i] + ratio * (self.a[i] - cur.qdd[i]);
        }
        for i in 0..self.n {
            let ac = (af * cur.qdd[i] - am * self.a0[i]) / (1.0 - am);
            self.qhat[i] = cur.q[i] + h * cur.qd[i] + h * h * ((0.5 - b) * self.a0[i] + b * ac);
            self.vhat[i] = cur.qd[i] + h * ((1.0 - g) * self.a0[i] + g * ac);
            self.qdd[i] = cur.qdd[i];
        }
        let nl = self.lam.len();
        self.lam.copy_from_slice(&cur.lambda[..nl]);
        if self.index2 {
            self.newton.index2_start(p, cur.t, &cur.q);
        }
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
        // the step's tolerance is rtol·f, f = c·√rtol (see the module notes), Newton's too
        let f = match ctl.adaptive {
            Some(tol) => {
                let (c, floor) = self.tolerance_map();
                order_two_factor(tol.rtol, c, floor)
            }
            None => 1.0,
        };
        let newton = match ctl.adaptive {
            Some(_) => NewtonTol {
                rtol: (ctl.newton.rtol * f).max(4.0 * f64::EPSILON),
                atol: ctl.newton.atol * f,
                ..ctl.newton
            },
            None => ctl.newton,
        };
        let result = self
            .newton
            .solve_index3(p, step, &mut self.qdd, &mut self.lam, &newton);
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
            self.a_next[i] = c * self.qdd[i] + (af * cur.qdd[i] - am * self.a0[i]) / (1.0 - am);
        }
        next.lambda[..self.lam.len()].copy_from_slice(&self.lam);
        let Some(tol) = ctl.adaptive else {
            p.watch_accepted(cur.t + h, &next.q)?;
            return Ok(Attempt::Accepted { h_next: h });
        };
        let k = h * h * (b - 1.0 / 6.0);
        // velocities: the leading term C·h³·q⁽⁴⁾ of their local error, q⁽⁴⁾ from the
        // accelerations at t₋₁, t₀, t₁ (2·qdd[t₋₁, t₀, t₁]); none on the first step after a
        // start
        let kv = h * h * h * self.velocity_error_constant();
        // γ ≠ ½ − δ (a first-order Newmark): (γ − ½ + δ)·h²·q⁽³⁾ first
        let k1 = h * (g - 0.5 + am - af);
        let d2 = |i: usize| match self.h_prev {
            Some(hp) => {
                ((self.qdd[i] - cur.qdd[i]) / h - (cur.qdd[i] - self.qdd_prev[i]) / hp) / (h + hp)
            }
            None => 0.0,
        };
        for i in 0..self.n {
            self.err[i] = k * (self.a_next[i] - self.a0[i]);
            self.err_v[i] = kv * 2.0 * d2(i) + k1 * (self.qdd[i] - cur.qdd[i]);
        }
        if self.index3() {
            // index 3: along the constraints: the multipliers' transients move q only across
            // them, where Φ(q₁) = 0 holds anyway
            p.tangent_part(cur.t + h, &next.q, &mut self.err)?;
        }
        // the local tolerances rtol·f and atol·f, the rounding floor under them as under
        // every scheme's (100ε times the largest entry of a kind)
        let tol = Tolerances {
            rtol: tol.rtol * f,
            atol: tol.atol * f,
            ..tol
        };
        let eq = tol.norm(&self.err, &cur.q, &next.q, cur.q.len());
        self.test = eq;
        // index 2: positions and velocities, otherwise positions (local error ∝ h³)
        let err = if self.index2 {
            let ev = tol.norm(&self.err_v, &cur.qd, &next.qd, cur.qd.len());
            self.test.floored |= ev.floored;
            if ev.value > eq.value {
                self.test.held_by = ev.held_by.map(Largest::as_velocity);
            }
            (0.5 * (eq.value * eq.value + ev.value * ev.value)).sqrt()
        } else {
            eq.value
        };
        let order = 2;
        if err <= 1.0 {
            p.watch_accepted(cur.t + h, &next.q)?;
            Ok(Attempt::Accepted {
                h_next: next_step(h, err, order, 2.0),
            })
        } else {
            Ok(Attempt::RejectedError {
                h_next: next_step(h, err, order, 1.0),
            })
        }
    }

    fn accepted(&mut self, _p: &mut Problem, prev: &State, cur: &State) {
        std::mem::swap(&mut self.a, &mut self.a_next);
        self.qdd_prev.copy_from_slice(&prev.qdd);
        self.h_prev = Some(cur.t - prev.t);
    }
}

/// The iteration matrix of an index-3 generalized-α step of size `h` (N × N column-major,
/// N = NQ + NC), evaluated at `state` (q, qd, qdd, λ), with the constraint rows scaled by
/// 1/β' or not: the matrix the integrator factorises, exposed for condition studies.
pub fn index3_iteration_matrix<M: Model + 'static>(
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
    let mut p = Problem::new(Box::new(model), crate::options::IterationMatrix::Auto);
    p.loops = Loops::Closed(Box::new(Constrained::new(
        p.model.erased(),
        Mode::Index3,
        &options,
    )));
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
