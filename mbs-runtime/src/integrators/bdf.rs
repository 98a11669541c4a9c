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
//!   of (q, qd), against the transformed tolerance rtol' = 0.1·rtol^1.25, atol kept
//!   (`Tolerances::transformed`). With the user's rtol itself the global error was ∝ rtol^0.8
//!   (error per step at orders 3–5: tol^(p/(p+1))), 2.9 digits short of rtol on average over
//!   the closed loops of `tests/tolerance_proportionality.rs` with projection and 4.6 at worst
//!   (slider-crank, rtol 1e-10); transformed, it gains 0.75–1.0 digits per decade of rtol and
//!   is 1.6 digits short on average over the same loops, like DOPRI5 (1.6); the loops differ
//!   more than the schemes (BDF from 0.2 to 2.7 digits short on average, model by model).
//!   A failed test shrinks h by max(0.2, s·err^(−1/(k+1))), s = 0.9·(2m+1)/(2m+i) with i
//!   Newton iterations out of m allowed.
//! - Newton stops at κ = `tolerance_factor` in the user's weights atol + rtol·|y|, not in
//!   the error test's transformed ones (3× looser at rtol 1e-4, 30× at 1e-8). Measured, not
//!   kept: Newton in the transformed weights (κ as before, floored at 10ε/rtol') moved the
//!   digits of `tests/tolerance_proportionality.rs` by −0.81 to +0.83 (mean +0.03 over its
//!   112 BDF runs, mostly ±0.1; fastlink with partitioning 2.19 → 2.97 at rtol 1e-4 and 6.13 →
//!   5.32 at 1e-7, Cash's pendulum 8.98 → 9.10 at 1e-10), and global control with
//!   partitioning on fastlink at rtol 1e-8 then ended in `GlobalToleranceNotMet`, where it
//!   returned a run: Newton's remainder is not what keeps BDF short of rtol.
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
//! - Stability limits on undamped oscillations (below).
//! - Fixed steps: constant h and no error test, the order rising by one each step up to
//!   `max_order` (step s uses order min(s, max_order): every point of its formula has been
//!   computed) and as far as h is stable on the fastest oscillation (below). The order-1
//!   first step limits fixed-step accuracy to O(h²) from the start; variable order is meant
//!   to be used adaptively.
//! - Dense output: the driver's quintic Hermite interpolation of (q, qd, qdd) at the step ends.
//!
//! # Undamped stiff oscillations
//!
//! BDF3–5 are unstable on part of the imaginary axis: an undamped mode of frequency ω grows
//! when hω lies in (0, 1.93) for BDF3 (by up to 4.6 % a step), (0, 4.69) for BDF4 (19 %) and
//! (0.714, 9.38) for BDF5 (38 %). On a stiff undamped chain (`chain30_stiff`: modes from 4 to
//! 1.6e5 rad/s) the order selection, which sees only accuracy, took orders 4–5 and the error
//! test then held h where the parasitic growth balanced the tolerance: 586,920 and 635,988
//! steps at rtol 1e-6 and 1e-8 (hω_max ≈ 0.5), where BDF capped at order 2 takes 472 and 2,435
//! for the same error. SUNDIALS CVODE behaves alike on such chains, and its stability-limit
//! detection (STALD: the dominant characteristic root estimated from the scaled derivatives
//! of the last steps, the order lowered by one when the root leaves the unit circle) made it
//! worse there: many undamped modes at once leave no single dominant root, and BDF4 and BDF3,
//! one order down at a time, are unstable on them too. Hairer & Wanner (Solving ODEs II, V.2)
//! give the A(α) regions behind this; lightly damped oscillations want orders ≤ 2.
//!
//! Here the scheme looks at the spectrum instead. Whenever Newton builds a fresh iteration
//! matrix from the model's tangents, M, C_t and K_t are there at no evaluation: a power
//! iteration on M⁻¹K_t (12 iterations from the previous direction, a Cholesky of M and 24
//! n² products) gives ω_max of the fastest undamped mode, xᵀK_t x > 0 tells an oscillation
//! from a static instability, and ζ = xᵀC_t x / (2ω xᵀM x) its damping ratio. Order k > 2 is
//! then allowed steps with h·ω_max ≤ 0.3, 0.4, 0.7 (k = 3, 4, 5: growth below 0.2 % a step,
//! BDF5 stable) unless ζ > cos α_k (the mode lies in the order's A(α) sector, α = 86°, 73°,
//! 52°). Since a chain's modes fill [ω_min, ω_max], a mode lies in the unstable band as soon
//! as h·ω_max exceeds the limit, even when ω_max itself is beyond it (BDF5 at hω_max > 9.38).
//! - Order selection: each candidate's step factor is the smaller of its accuracy factor and
//!   its stability factor limit/(h·ω_max); the order rises only where its step is stable.
//! - When stability holds the chosen order k > 3 below what accuracy allows, order 2 (error
//!   from ∇³y_{n+1}) is taken if its step is 10 times longer on 3 selections in a row; near
//!   the limit (BDF5 resolving an oscillation at hω ≈ 0.7, springpend at k = 1e8) the
//!   estimates of order 2 swing with the phase, and a drop there would trade a resolved,
//!   stable oscillation for BDF2's damping of it.
//! - Between selections, a fresh estimate that puts h beyond order k's limit shrinks h to the
//!   limit when that costs less than a factor 10, and otherwise drops to the highest stable
//!   order at once.
//! - Finite-difference and mass-only iteration matrices (models without tangents) give no M,
//!   K_t apart: no estimate, no limit (dpend, chain8 and seed2dof run as before).
//!
//! On `chain30_stiff` over 2 s (`cargo test --release --test bdf_stiff_oscillation --
//! --nocapture`): 105 / 472 / 2,437 steps at rtol 1e-4 / 1e-6 / 1e-8, orders 3–5 never taken,
//! the error of BDF capped at order 2 (4.5e-2, 2.2e-3, 8.5e-5; Radau5: 16 / 32 / 78 steps).
//! At rtol 1e-4 the unlimited BDF5 did better (45 steps, 3.6e-3): its steps put every stiff
//! mode beyond BDF5's unstable band (h·ω_min,stiff > 9.38), which ω_max alone cannot tell;
//! likewise springpend's single radial mode from the slow-manifold start at k = 1e8 (286 steps,
//! was 45). Where the oscillation must be followed, the high order stays: springpend at
//! k = 1e8 from r = 1 + 9.81/k runs 92 % of its 20,962 steps at order 5 with hω ≤ 0.7 (it
//! took 23,901 when rejected past the limit).
//!
//! Every buffer is allocated in [`Bdf::new`]; steps allocate nothing.

use super::at::{Affine, Weights};
use super::newton::AccelNewton;
use super::problem::Problem;
use super::step_control::{ErrorNorm, Tolerances, elementary_factor, optimal_factor};
use super::{Attempt, Control, State, Step, Stepper};
use crate::charts::Recentring;
use crate::error::Failure;
use crate::linalg::{cholesky, cholesky_solve};

const MAX_ORDER: usize = 5;
/// The error test's tolerance: rtol' = 0.1·rtol^1.25, atol kept (see the module
/// documentation).
const TOL_FACTOR: f64 = 0.1;
const TOL_EXPONENT: f64 = 1.25;
/// γ_k = Σ_{i=1..k} 1/i
const GAMMA: [f64; MAX_ORDER + 1] = [0.0, 1.0, 1.5, 11.0 / 6.0, 25.0 / 12.0, 137.0 / 60.0];
/// step factor limits: shrinking by at most 5 on a rejection, growing by at most 10
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;

/// h·ω of an undamped oscillation up to which order k is used (orders 1 and 2 are A-stable):
/// BDF3 and BDF4 amplify it by 1 + 1.3e-4 and 1 + 7e-5 a step there (their growth on the
/// imaginary axis goes as (hω)^(k+1) up to 1.93 and 4.69, peaking at 4.6 % and 19 % a step);
/// BDF5 is stable up to hω = 0.714 (then unstable up to 9.38, by up to 38 % a step), 0.6 leaves
/// room for an estimate of ω from below.
const OSCILLATION_LIMIT: [f64; MAX_ORDER + 1] =
    [f64::INFINITY, f64::INFINITY, f64::INFINITY, 0.3, 0.4, 0.7];
/// cos α_k of the A(α_k)-stable orders (α = 86.03°, 73.35°, 51.84°): a mode of damping ratio
/// ζ > cos α_k lies in the sector order k is stable in, whatever h.
const COS_ALPHA: [f64; MAX_ORDER + 1] = [0.0, 0.0, 0.0, 0.0692, 0.2865, 0.6182];
/// a stability-limited order k > 2 drops to order 2 at a selection when order 2's error allows a
/// step this many times longer: near the limit (an oscillation resolved at hω ≈ 0.7 by BDF5)
/// the estimates of order 2 swing with the oscillation's phase, and a drop there would trade
/// a stable resolved oscillation for BDF2's damping of it
const DROP_GAIN: f64 = 10.0;
/// … on this many selections in a row
const DROP_VOTES: usize = 3;
/// power iterations per fresh iteration matrix, each continuing from the last direction
const POWER_ITERATIONS: usize = 12;

/// The fastest undamped mode, from M and K_t of the last iteration matrix: a power iteration on
/// M⁻¹K_t (warm-started from the previous direction) gives ω² of the fastest mode, the Rayleigh
/// quotients xᵀK_t x and xᵀC_t x its sign (an oscillation, or a static instability) and its
/// damping ratio ζ = xᵀC_t x / (2ω xᵀM x).
struct Spectrum {
    n: usize,
    /// Cholesky factor of M
    chol: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
    /// an estimate is there and the fastest mode oscillates
    oscillating: bool,
    omega: f64,
    zeta: f64,
}

impl Spectrum {
    fn new(n: usize) -> Spectrum {
        Spectrum {
            n,
            chol: vec![0.0; n * n],
            x: vec![0.0; n],
            y: vec![0.0; n],
            oscillating: false,
            omega: 0.0,
            zeta: 0.0,
        }
    }

    fn forget(&mut self) {
        self.oscillating = false;
        self.x.fill(0.0);
    }

    /// y = A x (A n × n, column-major)
    fn product(n: usize, a: &[f64], x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        for (j, xj) in x.iter().enumerate() {
            for (yi, aij) in y.iter_mut().zip(&a[j * n..(j + 1) * n]) {
                *yi += aij * xj;
            }
        }
    }

    fn dot(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }

    fn estimate(&mut self, m: &[f64], c: &[f64], k: &[f64]) {
        let n = self.n;
        self.oscillating = false;
        self.chol.copy_from_slice(m);
        if cholesky(&mut self.chol, n).is_err() {
            return;
        }
        if self.x.iter().all(|x| *x == 0.0) {
            for (i, x) in self.x.iter_mut().enumerate() {
                *x = 1.0 + 0.37 * i as f64 * if i % 2 == 0 { 1.0 } else { -1.0 };
            }
        }
        let norm = Self::dot(&self.x, &self.x).sqrt();
        self.x.iter_mut().for_each(|x| *x /= norm);
        let mut lambda = 0.0;
        for _ in 0..POWER_ITERATIONS {
            Self::product(n, k, &self.x, &mut self.y);
            cholesky_solve(&self.chol, n, &mut self.y);
            lambda = Self::dot(&self.y, &self.y).sqrt();
            if !(lambda > 0.0 && lambda.is_finite()) {
                // no stiffness (or not a number): nothing to limit
                self.x.fill(0.0);
                return;
            }
            for (x, y) in self.x.iter_mut().zip(&self.y) {
                *x = y / lambda;
            }
        }
        Self::product(n, k, &self.x, &mut self.y);
        let xkx = Self::dot(&self.x, &self.y);
        Self::product(n, m, &self.x, &mut self.y);
        let xmx = Self::dot(&self.x, &self.y);
        Self::product(n, c, &self.x, &mut self.y);
        let xcx = Self::dot(&self.x, &self.y);
        self.omega = lambda.sqrt();
        self.zeta = xcx / (2.0 * self.omega * xmx);
        self.oscillating = xkx > 0.0 && xmx > 0.0 && self.zeta.is_finite();
    }

    /// The largest factor on h that order k may take from h for stability: unlimited but on an
    /// oscillation order k's sector leaves out.
    fn factor(&self, k: usize, h: f64) -> f64 {
        if k <= 2 || !self.oscillating || self.zeta > COS_ALPHA[k] {
            f64::INFINITY
        } else {
            OSCILLATION_LIMIT[k] / (self.omega * h)
        }
    }
}

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
    spectrum: Spectrum,
    /// selections in a row at which order 2 would have taken DROP_GAIN times the step
    drop_votes: usize,
    /// the last error test
    test: ErrorNorm,
}

impl Bdf {
    pub fn new(n: usize, max_order: usize) -> Bdf {
        let z = |m: usize| vec![0.0; m];
        Bdf {
            test: ErrorNorm::default(),
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
            spectrum: Spectrum::new(n),
            drop_votes: 0,
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

impl Stepper for Bdf {
    fn last_test(&self) -> ErrorNorm {
        self.test
    }

    fn newton_largest(&self) -> Option<(usize, usize)> {
        self.newton.largest
    }

    fn tolerance_floor(&self, rtol: f64) -> Option<f64> {
        Tolerances::transformed_floored(rtol, TOL_FACTOR, TOL_EXPONENT)
    }

    fn start(&mut self, _p: &mut Problem, s: &State, _ctl: &Control) -> Result<(), Failure> {
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
        self.spectrum.forget();
        self.drop_votes = 0;
        Ok(())
    }

    /// The history is of the old chart: BDF starts again at order 1 (as after a sample),
    /// with fresh matrices.
    fn rechart(
        &mut self,
        p: &mut Problem,
        s: &State,
        ctl: &Control,
        _moved: &[Recentring],
        _evaluated: bool,
    ) -> Result<(), Failure> {
        self.newton.forget();
        self.start(p, s, ctl)
    }

    fn attempt(&mut self, step: Step<'_>) -> Result<Attempt, Failure> {
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
        let made = p.stats.tangents;
        let r = self.newton.solve(p, step, &mut self.a, &ctl.newton);
        if p.stats.tangents != made
            && let Some((m, c, k)) = p.last_tangents()
        {
            self.spectrum.estimate(m, c, k);
        }
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
            // fixed steps: raise the order by one per step, no error test, as far as h is
            // stable on the fastest oscillation
            let mut order = (k + 1).min(self.max_order);
            while order > 2 && self.spectrum.factor(order, h) < 1.0 {
                order -= 1;
            }
            self.next_order = order;
            self.reselected = self.next_order != k;
            p.watch_accepted(cur.t + h, &next.q)?;
            return Ok(Attempt::Accepted { h_next: h });
        };
        let tol = tol.transformed(TOL_FACTOR, TOL_EXPONENT);
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
        let norm = tol.norm(&self.err, &self.y0, &self.y1, self.y0.len() / 2);
        let err = norm.value;
        self.test = norm;
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
                tol.error_norm(&self.err, &self.y0, &self.y1, self.y0.len() / 2)
            } else {
                f64::INFINITY
            };
            let err_p = if k < self.max_order {
                for i in 0..m {
                    self.err[i] = error_const(k + 1) * (self.corr[i] - self.d[(k + 1) * m + i]);
                }
                tol.error_norm(&self.err, &self.y0, &self.y1, self.y0.len() / 2)
            } else {
                f64::INFINITY
            };
            // step factors err^(−1/(order+1)), each within what stability allows the order;
            // the first of the largest wins
            let mut best = (k, 0.0);
            let mut consider = |order: usize, err: f64| {
                let f = optimal_factor(err, order).min(self.spectrum.factor(order, h) / safety);
                if f > best.1 {
                    best = (order, f);
                }
            };
            consider(k - 1, err_m);
            consider(k, err);
            if k < self.max_order {
                consider(k + 1, err_p);
            }
            // stability holds every order above 2 below what accuracy allows: consider the
            // A-stable order 2 too, its error from ∇³y_{n+1} = Σ_{j=3..k} ∇ʲyₙ + ∇^{k+1}y_{n+1}
            let f = best.1;
            if k > 3 && f < optimal_factor(err, k).max(optimal_factor(err_m, k - 1)) {
                for i in 0..m {
                    let mut s = self.corr[i];
                    for j in 3..=k {
                        s += self.d[j * m + i];
                    }
                    self.err[i] = error_const(2) * s;
                }
                let err_2 = tol.error_norm(&self.err, &self.y0, &self.y1, self.y0.len() / 2);
                if optimal_factor(err_2, 2) > DROP_GAIN * f {
                    self.drop_votes += 1;
                    if self.drop_votes >= DROP_VOTES {
                        best = (2, optimal_factor(err_2, 2));
                    }
                } else {
                    self.drop_votes = 0;
                }
            } else {
                self.drop_votes = 0;
            }
            self.next_order = best.0;
            self.reselected = true;
            h_next = h * (safety * best.1).min(MAX_FACTOR);
        } else if k > 2 && self.spectrum.factor(k, h) < 1.0 {
            // a fresh estimate finds h beyond order k's limit: shrink h to it when that costs
            // less than DROP_GAIN, else drop at once to the highest order stable at h
            let stable = self.spectrum.factor(k, h);
            if stable * DROP_GAIN >= 1.0 {
                h_next = h * stable;
            } else {
                let mut order = k - 1;
                while order > 2 && self.spectrum.factor(order, h) < 1.0 {
                    order -= 1;
                }
                self.next_order = order;
                self.reselected = true;
            }
        }
        p.watch_accepted(cur.t + h, &next.q)?;
        Ok(Attempt::Accepted { h_next })
    }

    fn accepted(&mut self, p: &mut Problem, _prev: &State, cur: &State) {
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
