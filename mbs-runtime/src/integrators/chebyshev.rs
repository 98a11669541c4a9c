//! Runge–Kutta–Chebyshev of order 2 (RKC: van der Houwen & Sommeijer 1980; Sommeijer,
//! Shampine & Verwer 1998), adaptive or fixed step, its number of stages s chosen at each
//! step from estimates of the fastest modes.
//!
//! An s-stage explicit scheme whose stability polynomial is a shifted, damped Chebyshev
//! polynomial, R_s(z) = a_s + b_s T_s(w₀ + w₁z), w₀ = 1 + ε/s², covers the real interval
//! hλ ∈ [−β(s), 0], β(s) = (1 + w₀)/w₁ ≈ 0.54 s² here: its cost grows as the square root of
//! the stiffness, where a classical scheme's grows linearly (RK4 takes four evaluations per
//! 2.785 of hρ, RKC four stages reach 8.1, ten 53). It suits motions whose fast modes decay —
//! a motor's electrical pole, a regularised friction law, a stiff damper — and not stiff
//! undamped oscillations, which no explicit scheme takes cheaply.
//!
//! The damping is ε = 2, not the 2/13 of Sommeijer et al.: with 2/13 the region pinches
//! around the real interval (half-width 1.09 at hλ = −3.45 with 3 stages, 1.43 at −4.9 with
//! 4), and the walking hexapod's friction modes, slightly oscillating, sat in the pinches at
//! h = 1 ms: the run went on with its motors' voltage saturated (9.6 kJ drawn instead of
//! 1.2 kJ). With ε = 2, β is 17 % shorter but the region has no pinch: from Re z = −0.5 to
//! −β/1.5 it holds a strip of half-width 1.56 (3 stages) to 2.29 (15), and near the imaginary
//! axis 0.30 (3) to 0.38 (15) — "holds" meaning |R_s(z)| ≤ max(1, e^(Re z))·1.01^(|Im z|/2π):
//! like every order-2 explicit scheme RKC amplifies an undamped oscillation a little
//! (|R(iy)| = 1 + O(y⁴)), accepted up to 1 % of its amplitude a period. RKC is for decaying
//! fast modes; on undamped ones it takes hω ≤ 0.3, where RK4 takes 2.8.
//!
//! The stages (y = (q, qd), F = (qd, qdd), Y₀ = yₙ):
//! Y₁ = Y₀ + μ̃₁hF₀,
//! Yⱼ = (1 − μⱼ − νⱼ)Y₀ + μⱼYⱼ₋₁ + νⱼYⱼ₋₂ + μ̃ⱼhF(Yⱼ₋₁) + γ̃ⱼhF₀ (j = 2…s), yₙ₊₁ = Y_s,
//! with bⱼ = T″ⱼ(w₀)/T′ⱼ(w₀)² (b₀ = b₁ = b₂), aⱼ = 1 − bⱼTⱼ(w₀), w₁ = T′_s(w₀)/T″_s(w₀),
//! μ̃₁ = b₁w₁, μⱼ = 2w₀bⱼ/bⱼ₋₁, νⱼ = −bⱼ/bⱼ₋₂, μ̃ⱼ = 2w₁bⱼ/bⱼ₋₁, γ̃ⱼ = −aⱼ₋₁μ̃ⱼ. A step
//! costs s evaluations (s − 1 stages and the new state's).
//!
//! The number of stages is the least that holds, with a margin of 1.5 on hλ, the estimates of:
//! - the fastest mode, from the explicit schemes' power iteration on J² (`explicit.rs`),
//!   its eigenvalue (complex for an oscillating pair) from the Krylov space {δ, Jδ}; every
//!   8 steps and after a lurch (2 evaluations), the last 4 estimates held at once: one
//!   iteration moves about within a cluster of modes of similar modulus (on the hexapod,
//!   from 842 to 4,459 1/s between checks);
//! - the mode farthest off the real axis, by a power iteration on p(J) = J(J + ρI)
//!   ([`OffAxis`]), every 16 steps (4 evaluations): a decaying mode faster than an
//!   oscillating one hides it from the first estimate, and RKC's region is narrow across.
//!
//! With a fixed step, a step no number of stages up to [`MAX_STAGES`] holds is refused with
//! `UnstableStep` (taken with MAX_STAGES when `Options::stability_check` is off). With
//! adaptive steps, the error estimate is 4/5 of the trapezoidal rule's defect (Sommeijer et
//! al.), tested against rtol·f and atol·f, f = 0.3·√rtol, as the Newmark family's (order 2,
//! so that the global error follows rtol: dpend 3.61 to 7.66 digits at rtol 1e-4 to 1e-8,
//! `tests/scheme_rkc.rs`), the step chosen by the PI controller; a step the stages cannot
//! hold is retried smaller. What the estimates do not see — an oscillating mode near the
//! origin behind a much faster decaying one converges slowly in the second iteration — the
//! error test of adaptive steps catches; with a fixed step it is the user's h.

use super::explicit::{Probe, StabilityWatch, dot, ritz};
use super::problem::Problem;
use super::step_control::{
    Decision, ErrorNorm, PiController, Tolerances, order_two_factor, order_two_floored,
};
use super::{Attempt, State, Step, Stepper};
use crate::error::Failure;
use nalgebra::Complex;
use std::f64::consts::PI;

/// The damping ε of w₀ = 1 + ε/s² (see the module's docs).
const DAMPING: f64 = 2.0;

/// The most stages a step takes (β ≈ 21,000): beyond, round-off in the recursion grows.
pub(crate) const MAX_STAGES: usize = 200;

/// The margin of β(s) over the estimated hρ (ρ moves between two estimates).
const MARGIN: f64 = 1.5;

/// The local error test's tolerances for the user's: rtol·f and atol·f, f = c·√rtol, so that
/// the global error of an order-2 scheme follows rtol (as the Newmark family's).
const TOL_FACTOR: f64 = 0.3;
/// No local tolerance below this (the rounding of a step).
const FLOOR: f64 = 100.0 * f64::EPSILON;

/// The growth of an undamped oscillation's amplitude a period that the stages accept.
const GROWTH: f64 = 0.01;

/// The largest h·ρ a step takes of a mode growing as e^(ρt), a choice (RK4's reach on the
/// negative real axis, 2.785, rounded down): RKC's polynomials, which grow as T_s on the
/// positive axis, hold such a mode by their bound |R| ≤ e^z at any h, but not to any
/// accuracy.
const GROWING: f64 = 2.67;

/// Steps between two estimates of the fastest mode, and of the mode farthest off the axis.
const EVERY: usize = 8;
const OFF_AXIS_EVERY: usize = 16;
/// Estimates of the fastest mode the stages hold at once.
const RECENT: usize = 4;

/// The recursion's coefficients for one number of stages.
struct Coefficients {
    s: usize,
    mu: Vec<f64>,
    nu: Vec<f64>,
    mu_t: Vec<f64>,
    gamma_t: Vec<f64>,
    /// stage times (fractions of h)
    c: Vec<f64>,
    /// T_j(w₀), T′_j(w₀), T″_j(w₀), scratch
    t: [Vec<f64>; 3],
}

/// T_j(x), T′_j(x), T″_j(x) for j = 0..=s into `t`.
fn chebyshev(x: f64, s: usize, t: &mut [Vec<f64>; 3]) {
    let [t0, t1, t2] = t;
    (t0[0], t1[0], t2[0]) = (1.0, 0.0, 0.0);
    (t0[1], t1[1], t2[1]) = (x, 1.0, 0.0);
    for j in 2..=s {
        t0[j] = 2.0 * x * t0[j - 1] - t0[j - 2];
        t1[j] = 2.0 * t0[j - 1] + 2.0 * x * t1[j - 1] - t1[j - 2];
        t2[j] = 4.0 * t1[j - 1] + 2.0 * x * t2[j - 1] - t2[j - 2];
    }
}

/// w₀ and w₁ of s stages, with T_j(w₀) and its derivatives left in `t`.
fn shift(s: usize, t: &mut [Vec<f64>; 3]) -> (f64, f64) {
    let w0 = 1.0 + DAMPING / (s * s) as f64;
    chebyshev(w0, s, t);
    (w0, t[1][s] / t[2][s])
}

impl Coefficients {
    fn new() -> Coefficients {
        let z = || vec![0.0; MAX_STAGES + 1];
        Coefficients {
            s: 0,
            mu: z(),
            nu: z(),
            mu_t: z(),
            gamma_t: z(),
            c: z(),
            t: [z(), z(), z()],
        }
    }

    /// The coefficients of s ≥ 2 stages.
    fn set(&mut self, s: usize) {
        if self.s == s {
            return;
        }
        self.s = s;
        let (w0, w1) = shift(s, &mut self.t);
        let [t, d, dd] = &self.t;
        let b = |j: usize| {
            let j = j.max(2);
            dd[j] / (d[j] * d[j])
        };
        let a = |j: usize| 1.0 - b(j) * t[j];
        self.mu_t[1] = b(1) * w1;
        self.c[0] = 0.0;
        self.c[1] = self.mu_t[1];
        for j in 2..=s {
            self.mu[j] = 2.0 * w0 * b(j) / b(j - 1);
            self.nu[j] = -b(j) / b(j - 2);
            self.mu_t[j] = 2.0 * w1 * b(j) / b(j - 1);
            self.gamma_t[j] = -a(j - 1) * self.mu_t[j];
            self.c[j] = self.mu[j] * self.c[j - 1]
                + self.nu[j] * self.c[j - 2]
                + self.mu_t[j]
                + self.gamma_t[j];
        }
    }
}

/// The amplification a step may give a mode hλ = z: its own growth e^(Re z) when it grows,
/// and GROWTH a period on an oscillation (order-2 explicit schemes amplify every undamped
/// oscillation a little, |R(iy)| = 1 + O(y⁴)).
fn allowance(z: Complex<f64>) -> f64 {
    z.re.exp().max(1.0) * (1.0 + GROWTH).powf(z.im.abs() / (2.0 * PI))
}

/// The stability polynomial of every number of stages: R_s(z) = a_s + b_s T_s(w₀ + w₁z).
struct Polynomials {
    w0: Vec<f64>,
    w1: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    /// β(s) = (1 + w₀)/w₁, the real interval [−β, 0] where |R_s| ≤ 1 (0 below 2 stages)
    beta: Vec<f64>,
}

impl Polynomials {
    fn new() -> Polynomials {
        let z = || vec![0.0; MAX_STAGES + 1];
        let mut t = [z(), z(), z()];
        let mut p = Polynomials {
            w0: z(),
            w1: z(),
            a: z(),
            b: z(),
            beta: z(),
        };
        for s in 2..=MAX_STAGES {
            let (w0, w1) = shift(s, &mut t);
            let b = t[2][s] / (t[1][s] * t[1][s]);
            (p.w0[s], p.w1[s], p.b[s], p.a[s]) = (w0, w1, b, 1.0 - b * t[0][s]);
            p.beta[s] = (1.0 + w0) / w1;
        }
        p
    }

    /// |R_s(z)|.
    fn amplification(&self, s: usize, z: Complex<f64>) -> f64 {
        let x = self.w0[s] + self.w1[s] * z;
        let (mut t0, mut t1) = (Complex::new(1.0, 0.0), x);
        for _ in 2..=s {
            (t0, t1) = (t1, 2.0 * x * t1 - t0);
        }
        (self.a[s] + self.b[s] * t1).norm()
    }

    /// The fewest stages that hold every hλ in `zs`, and MARGIN·hλ: within the real interval
    /// (MARGIN·|Re hλ| ≤ β(s)) and amplified by no more than [`allowance`].
    fn stages_for(&self, zs: &[Complex<f64>]) -> Option<usize> {
        let reach = zs.iter().map(|z| z.re.abs()).fold(0.0, f64::max);
        let first = self.beta.partition_point(|&b| b < MARGIN * reach).max(2);
        let held = |s: usize, z: Complex<f64>| self.amplification(s, z) <= allowance(z);
        (first..=MAX_STAGES).find(|&s| zs.iter().all(|&z| held(s, z) && held(s, MARGIN * z)))
    }
}

/// The mode farthest off the real axis. On the real segment [−ρ, 0] the polynomial
/// p(λ) = λ(λ + ρ) stays within |p| ≤ ρ²/4; a mode off it, λ = a + ib, gives
/// |p(λ)|² = (a(a + ρ) − b²)² + b²(2a + ρ)², larger as b grows (ρ²/4 + b² at a = −ρ/2, about
/// bρ near the origin). So a power iteration on p(J) (two Jacobian products each), with ρ the
/// fastest mode's modulus, finds the mode of largest |p| — an oscillating one whenever one
/// lies off the segment by more than a little — which a power iteration on J alone does not
/// see behind a faster decaying mode. Its eigenvalue μ comes from the Krylov space
/// {d, p(J)d} as the watch's does (`explicit::ritz`), and the mode is a root of
/// λ² + ρλ − μ = 0 (both roots, mirror images about −ρ/2, are checked).
struct OffAxis {
    probe: Probe,
    /// the direction d, p(J)d, p(J)²d, and J applied to one of them (each 2n)
    d: Vec<f64>,
    u: Vec<f64>,
    w: Vec<f64>,
    j: Vec<f64>,
    /// the two roots λ of the last estimate
    modes: [Complex<f64>; 2],
}

/// A start with components on every coordinate and both halves.
fn seed(v: &mut [f64]) {
    for (i, x) in v.iter_mut().enumerate() {
        *x = 1.0 + (i as f64 * 0.618_034).fract() - if i % 3 == 0 { 1.2 } else { 0.0 };
    }
}

impl OffAxis {
    fn new(n: usize) -> OffAxis {
        let z = || vec![0.0; 2 * n];
        let mut d = z();
        seed(&mut d);
        OffAxis {
            probe: Probe::new(n),
            d,
            u: z(),
            w: z(),
            j: z(),
            modes: [Complex::new(0.0, 0.0); 2],
        }
    }

    /// out = p(J)·x = J(Jx) + ρJx.
    fn apply_p(
        probe: &mut Probe,
        p: &mut Problem,
        cur: &State,
        rho: f64,
        x: &[f64],
        j: &mut [f64],
        out: &mut [f64],
    ) -> Result<(), Failure> {
        let n = x.len() / 2;
        {
            let (jq, jv) = j.split_at_mut(n);
            probe.apply_j(p, cur, &x[..n], &x[n..], jq, jv)?;
        }
        let (oq, ov) = out.split_at_mut(n);
        probe.apply_j(p, cur, &j[..n], &j[n..], oq, ov)?;
        for (o, a) in out.iter_mut().zip(j.iter()) {
            *o += rho * a;
        }
        Ok(())
    }

    /// One power iteration on p(J), or with `settle` iterations until |μ| changes by less
    /// than 1 %; ρ the fastest mode's modulus.
    fn estimate(
        &mut self,
        p: &mut Problem,
        cur: &State,
        rho: f64,
        settle: bool,
    ) -> Result<(), Failure> {
        let mut last = f64::NAN;
        for _ in 0..if settle { 30 } else { 1 } {
            let size = dot(&self.d, &self.d).sqrt();
            if !(size > 0.0) || !size.is_finite() {
                seed(&mut self.d);
            }
            let size = dot(&self.d, &self.d).sqrt();
            self.d.iter_mut().for_each(|x| *x /= size);
            Self::apply_p(
                &mut self.probe,
                p,
                cur,
                rho,
                &self.d,
                &mut self.j,
                &mut self.u,
            )?;
            Self::apply_p(
                &mut self.probe,
                p,
                cur,
                rho,
                &self.u,
                &mut self.j,
                &mut self.w,
            )?;
            let (d, u, w) = (&self.d, &self.u, &self.w);
            let (re, im) = ritz(dot(d, d), dot(d, u), dot(u, u), dot(d, w), dot(u, w));
            let mu = Complex::new(re, im);
            let root = (Complex::new(rho * rho, 0.0) + 4.0 * mu).sqrt();
            self.modes =
                [0.5 * (-rho + root), 0.5 * (-rho - root)].map(|z| Complex::new(z.re, z.im.abs()));
            std::mem::swap(&mut self.d, &mut self.w);
            if (mu.norm() - last).abs() <= 1e-2 * mu.norm() {
                break;
            }
            last = mu.norm();
        }
        Ok(())
    }
}

pub(crate) struct Chebyshev {
    n: usize,
    k: Coefficients,
    poly: Polynomials,
    /// Y_{j−2}, Y_{j−1}, Y_j (positions, velocities) in turn, and F(Y_{j−1})'s accelerations
    yq: [Vec<f64>; 3],
    yv: [Vec<f64>; 3],
    acc: Vec<f64>,
    watch: StabilityWatch,
    off_axis: OffAxis,
    /// the last RECENT estimates of the fastest mode
    recent: [Complex<f64>; RECENT],
    /// the stages of the step
    stages: usize,
    /// adaptive steps: the error estimate, the states it is weighed against, the controller
    err: Vec<f64>,
    y0: Vec<f64>,
    y1: Vec<f64>,
    pi: PiController,
    /// the fastest mode is to be estimated anew before the next attempt (after a rejection)
    stale: bool,
    /// the last error test
    test: ErrorNorm,
}

impl Chebyshev {
    pub fn new(n: usize) -> Chebyshev {
        let z = || vec![0.0; n];
        Chebyshev {
            test: ErrorNorm::default(),
            n,
            k: Coefficients::new(),
            poly: Polynomials::new(),
            yq: [z(), z(), z()],
            yv: [z(), z(), z()],
            acc: z(),
            watch: StabilityWatch::new(n),
            off_axis: OffAxis::new(n),
            recent: [Complex::new(0.0, 0.0); RECENT],
            stages: 2,
            err: vec![0.0; 2 * n],
            y0: vec![0.0; 2 * n],
            y1: vec![0.0; 2 * n],
            pi: PiController::new(2, 0.08),
            stale: false,
        }
    }

    /// hλ of the fastest mode in the last RECENT estimates (one power iteration each, which
    /// moves about within a cluster of modes of similar modulus) and of the mode farthest off
    /// the real axis (both roots).
    fn zs(&self, h: f64) -> [Complex<f64>; RECENT + 2] {
        let mut zs = [Complex::new(0.0, 0.0); RECENT + 2];
        for (z, m) in zs.iter_mut().zip(&self.recent) {
            *z = h * m;
        }
        // a root right of the axis is the mirror of one beyond −ρ (ρ underestimated), or the
        // rounding of an undamped oscillation's: taken on the axis
        for (z, m) in zs[RECENT..].iter_mut().zip(&self.off_axis.modes) {
            *z = h * Complex::new(m.re.min(0.0), m.im);
        }
        zs
    }

    /// The largest modulus of the recent estimates of the fastest mode.
    fn rho(&self) -> f64 {
        self.recent.iter().map(|m| m.norm()).fold(0.0, f64::max)
    }

    /// Estimates the fastest mode once (with `settle`, to convergence) and keeps it among
    /// the recent ones.
    fn refresh(&mut self, p: &mut Problem, cur: &State, settle: bool) -> Result<(), Failure> {
        self.watch.refresh(p, cur, settle)?;
        let (re, im) = self.watch.mode();
        self.recent.rotate_right(1);
        self.recent[0] = Complex::new(re, im);
        Ok(())
    }

    /// After a fixed step whose stages went non-finite from a finite state: the fastest mode
    /// estimated to convergence, and `UnstableStep` where h·ρ exceeds [`GROWING`] (a step
    /// that outgrew the motion rather than a model that is not finite there). The estimates
    /// give |λ| and, from a Krylov space of rounding, not always its sign: fastlink released
    /// into its spring's push is a saddle, ρ ≈ 807 1/s, and the estimate read it as decaying, which 12
    /// stages hold as a decaying mode at h = 30 ms; as a growing one the stages amplify it
    /// as T_s, and went non-finite within the first step. A bound on growing modes checked
    /// before every step refused the walking hexapod, whose Krylov space shows a ± pair of
    /// 5–6·10³ 1/s that RKC follows at 0.5 ms to 0.1 mm of RK4: here it only names what
    /// a step that has already blown up outgrew.
    fn outgrown(
        &mut self,
        p: &mut Problem,
        cur: &State,
        h: f64,
    ) -> Result<Option<Failure>, Failure> {
        self.refresh(p, cur, true)?;
        let rho = self.rho();
        let h_rho = h * rho;
        Ok((h_rho > GROWING).then(|| Failure::UnstableStep {
            scheme: "RKC",
            rho,
            h_rho,
            limit: GROWING,
            h_stable: GROWING / rho,
            at_end: false,
        }))
    }

    /// The stages for a step of size h, from the last estimates of the fastest mode and of
    /// the mode farthest off the axis (estimated anew first when due); when none up to MAX_STAGES hold
    /// them, estimated to convergence, then `Err(f)` with the largest fraction f of h some
    /// number of stages holds.
    fn choose(
        &mut self,
        p: &mut Problem,
        cur: &State,
        h: f64,
    ) -> Result<Result<usize, f64>, Failure> {
        let first = self.watch.steps() == 0;
        if self.watch.due(EVERY) || self.stale {
            self.refresh(p, cur, first)?;
            if self.watch.steps() % OFF_AXIS_EVERY == 0 || self.stale {
                let rho = self.rho();
                self.off_axis.estimate(p, cur, rho, first)?;
            }
            self.stale = false;
        }
        if let Some(s) = self.poly.stages_for(&self.zs(h)) {
            return Ok(Ok(s));
        }
        if !first {
            self.refresh(p, cur, true)?;
            let rho = self.rho();
            self.off_axis.estimate(p, cur, rho, true)?;
            if let Some(s) = self.poly.stages_for(&self.zs(h)) {
                return Ok(Ok(s));
            }
        }
        let mut f = 1.0;
        while f > 1e-6 && self.poly.stages_for(&self.zs(f * h)).is_none() {
            f *= 0.9;
        }
        Ok(Err(f))
    }
}

impl Stepper for Chebyshev {
    fn last_test(&self) -> ErrorNorm {
        self.test
    }

    fn tolerance_floor(&self, rtol: f64) -> Option<f64> {
        order_two_floored(rtol, TOL_FACTOR, FLOOR)
    }

    fn attempt(&mut self, step: Step<'_>) -> Result<Attempt, Failure> {
        let Step(p, cur, h, ctl, next) = step;
        match self.choose(p, cur, h)? {
            Ok(s) => self.stages = s,
            // the check turned off: on with the most stages
            Err(_) if ctl.adaptive.is_none() && !ctl.stability_check => self.stages = MAX_STAGES,
            // a smaller step, when adaptive
            Err(f) if ctl.adaptive.is_some() => {
                self.pi.rejected_otherwise();
                return Ok(Attempt::RejectedError { h_next: f * h });
            }
            Err(f) => {
                // the mode no number of stages holds
                let zs = self.zs(h);
                let z = zs
                    .iter()
                    .find(|z| self.poly.stages_for(&[**z]).is_none())
                    .unwrap_or(&zs[0]);
                let h_rho = z.norm();
                return Err(Failure::UnstableStep {
                    scheme: "RKC",
                    rho: h_rho / h,
                    h_rho,
                    limit: f * h_rho,
                    h_stable: f * h,
                    at_end: false,
                });
            }
        }
        if let Err(e) = self.stage_loop(p, cur, h, next) {
            self.stale = true;
            if ctl.adaptive.is_none()
                && ctl.stability_check
                && matches!(e, Failure::NonFinite { .. })
            {
                if let Some(unstable) = self.outgrown(p, cur, h)? {
                    return Err(unstable);
                }
            }
            return Attempt::after_stage_failure(e, ctl.adaptive.is_some(), h, &mut self.pi);
        }
        let Some(tol) = ctl.adaptive else {
            self.watch.accepted(cur, next);
            return Ok(Attempt::Accepted { h_next: h });
        };
        // 4/5 of the trapezoidal rule's defect (Sommeijer, Shampine & Verwer 1998)
        let n = self.n;
        for i in 0..n {
            self.err[i] = 0.8 * (cur.q[i] - next.q[i]) + 0.4 * h * (cur.qd[i] + next.qd[i]);
            self.err[n + i] = 0.8 * (cur.qd[i] - next.qd[i]) + 0.4 * h * (cur.qdd[i] + next.qdd[i]);
            (self.y0[i], self.y0[n + i]) = (cur.q[i], cur.qd[i]);
            (self.y1[i], self.y1[n + i]) = (next.q[i], next.qd[i]);
        }
        // rtol·f and atol·f, f = 0.3·√rtol (no local tolerance below 100ε)
        let f = order_two_factor(tol.rtol, TOL_FACTOR, FLOOR);
        let tol = Tolerances {
            rtol: tol.rtol * f,
            atol: tol.atol * f,
            groups: tol.groups,
        };
        let norm = tol.norm(&self.err, &self.y0, &self.y1, self.y0.len() / 2);
        self.test = norm;
        match self.pi.decide(h, norm.value) {
            Decision::Accept { h_next } => {
                self.watch.accepted(cur, next);
                Ok(Attempt::Accepted { h_next })
            }
            Decision::Reject { h_next } => {
                self.stale = true;
                Ok(Attempt::RejectedError { h_next })
            }
        }
    }
}

impl Chebyshev {
    fn stage_loop(
        &mut self,
        p: &mut Problem,
        cur: &State,
        h: f64,
        next: &mut State,
    ) -> Result<(), Failure> {
        let (n, s, t) = (self.n, self.stages, cur.t);
        self.k.set(s);
        let k = &self.k;
        // Y₁ in slot 1; Y_{j−2}, Y_{j−1} in slots (j−2)%3, (j−1)%3 (Y₀ is `cur`)
        let m1 = k.mu_t[1] * h;
        for i in 0..n {
            self.yq[1][i] = cur.q[i] + m1 * cur.qd[i];
            self.yv[1][i] = cur.qd[i] + m1 * cur.qdd[i];
        }
        for j in 2..=s {
            let (a, b, c) = (j % 3, (j - 1) % 3, (j - 2) % 3);
            p.accel(t + k.c[j - 1] * h, &self.yq[b], &self.yv[b], &mut self.acc)?;
            let (mu, nu, mt, gt) = (k.mu[j], k.nu[j], k.mu_t[j] * h, k.gamma_t[j] * h);
            let w = 1.0 - mu - nu;
            // Y_{j−2} is Y₀ at j = 2
            for i in 0..n {
                let (q2, v2) = if j == 2 {
                    (cur.q[i], cur.qd[i])
                } else {
                    (self.yq[c][i], self.yv[c][i])
                };
                let q = w * cur.q[i]
                    + mu * self.yq[b][i]
                    + nu * q2
                    + mt * self.yv[b][i]
                    + gt * cur.qd[i];
                let v = w * cur.qd[i]
                    + mu * self.yv[b][i]
                    + nu * v2
                    + mt * self.acc[i]
                    + gt * cur.qdd[i];
                self.yq[a][i] = q;
                self.yv[a][i] = v;
            }
        }
        next.q.copy_from_slice(&self.yq[s % 3]);
        next.qd.copy_from_slice(&self.yv[s % 3]);
        p.check("q", &next.q)?;
        p.check("qd", &next.qd)?;
        p.accel(t + h, &next.q, &next.qd, &mut next.qdd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// R_s(z) by the stage recursion on y' = λy (y₀ = 1), against a_s + b_s T_s(w₀ + w₁z).
    fn by_stages(k: &Coefficients, z: Complex<f64>) -> Complex<f64> {
        let s = k.s;
        let one = Complex::new(1.0, 0.0);
        let (mut y2, mut y1) = (one, one + k.mu_t[1] * z);
        for j in 2..=s {
            let w = 1.0 - k.mu[j] - k.nu[j];
            let y = w * one + k.mu[j] * y1 + k.nu[j] * y2 + k.mu_t[j] * z * y1 + k.gamma_t[j] * z;
            (y2, y1) = (y1, y);
        }
        y1
    }

    #[test]
    fn the_recursion_is_the_polynomial_of_order_two() {
        let poly = Polynomials::new();
        let mut k = Coefficients::new();
        for s in 2..=60 {
            k.set(s);
            // the last stage is at t + h
            assert!((k.c[s] - 1.0).abs() < 1e-12, "c_s = {} at s = {s}", k.c[s]);
            for z in [
                Complex::new(-0.5 * poly.beta[s], 0.0),
                Complex::new(-1.0, 1.2),
                Complex::new(-0.9 * poly.beta[s], 0.7),
            ] {
                let r = by_stages(&k, z);
                assert!(
                    (r.norm() - poly.amplification(s, z)).abs() < 1e-9,
                    "s = {s}, z = {z}"
                );
            }
            // order 2: R(z) − e^z = O(z³)
            for z in [Complex::new(-1e-2, 0.0), Complex::new(0.0, 1e-2)] {
                let err = (by_stages(&k, z) - z.exp()).norm();
                assert!(err < 0.5 * z.norm().powi(3), "s = {s}: {err:e}");
            }
        }
    }

    /// The region's claims of the module's docs: within [−β/1.5, 0], from 3 stages on, a
    /// strip of half-width 1.56 from Re z = −0.5 on and 0.30 before, and the real interval
    /// [−β, 0].
    #[test]
    fn the_region_holds_the_strip() {
        let p = Polynomials::new();
        let held = |s: usize, z: Complex<f64>| p.amplification(s, z) <= allowance(z) + 1e-12;
        for s in [3, 4, 5, 6, 8, 10, 15, 30] {
            let reach = p.beta[s] / MARGIN;
            for i in 0..=400 {
                let x = -reach * i as f64 / 400.0;
                let width = if x <= -0.5 { 1.56 } else { 0.30 };
                for y in [0.0, 0.5 * width, width] {
                    assert!(held(s, Complex::new(x, y)), "s = {s}: {x} + {y}i");
                }
                let z = Complex::new(-p.beta[s] * i as f64 / 400.0, 0.0);
                assert!(p.amplification(s, z) <= 1.0 + 1e-12);
            }
            // an undamped oscillation at hω = 0.5 grows by more than 1 % a period
            assert!(!held(s, Complex::new(0.0, 0.5)), "s = {s}");
        }
        // the widths the docs quote for 15 stages: 0.38 near the axis, 2.29 from −0.5 on
        let reach = p.beta[15] / MARGIN;
        assert!(held(15, Complex::new(0.0, 0.38)));
        for i in 0..=400 {
            let x = -0.5 - (reach - 0.5) * i as f64 / 400.0;
            assert!(held(15, Complex::new(x, 2.29)), "{x}");
        }
        // past the interval the polynomial grows (β is where T_s leaves [−1, 1]; with the
        // damping |R| is still 0.93 at 1.05 β)
        assert!(p.amplification(4, Complex::new(-1.2 * p.beta[4], 0.0)) > 1.0);
    }

    #[test]
    fn stages_cover_the_fastest_mode_with_margin() {
        let p = Polynomials::new();
        // hλ = −10 needs β(s) ≥ 15: 5 stages (β(4) = 8.1, β(5) = 13.0, β(6) = 18.9)
        assert_eq!(p.stages_for(&[Complex::new(-10.0, 0.0)]), Some(6));
        assert_eq!(p.stages_for(&[Complex::new(-0.5, 0.0)]), Some(2));
        // an oscillation beyond the strip is held by no number of stages
        assert_eq!(p.stages_for(&[Complex::new(-0.1, 5.0)]), None);
        // β grows as s² (the README: 8.1 at 4 stages, 53 at 10)
        assert!(p.beta[100] > 0.5 * 100.0 * 100.0 && p.beta[100] < 0.56 * 100.0 * 100.0);
        assert!((p.beta[4] - 8.1).abs() < 0.05 && (p.beta[10] - 53.0).abs() < 0.5);
    }
}
