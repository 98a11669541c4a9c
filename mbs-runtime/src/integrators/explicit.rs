//! Explicit fixed-step schemes on the first-order form y = (q, qd), y' = (qd, M⁻¹h):
//! - explicit Euler (order 1): y₁ = y₀ + h f(y₀);
//! - classical Runge–Kutta (Kutta 1901, order 4), stability interval on the imaginary axis
//!   |hω| < 2√2 and on the real axis hλ > −2.785.
//!
//! Past its stability limit an explicit scheme amplifies the fastest mode until the numbers
//! overflow. To fail before that, every 16 steps a power iteration on J² (J = ∂f/∂y, two extra
//! evaluations; iterated to 0.1 % at the first step and before a refusal) estimates the
//! largest |λ| of the dynamics: J² has eigenvalues −ω² on an
//! oscillating mode whatever the scaling of q and qd, so ‖J²δ‖/‖δ‖ → ρ², and the sign of the
//! Rayleigh quotient δ·J²δ tells an oscillating mode (−ω²) from a decaying one (+λ²). When
//! h·ρ leaves the scheme's stability interval, the step fails with `UnstableStep`.
//!
//! Explicit Euler amplifies every undamped oscillation, by √(1 + (hω)²) a step: when the
//! fastest mode oscillates, its limit is hω < 0.226, where the amplitude doubles in one period
//! (π/x · ln(1 + x²) = ln 2); on a decaying mode it is the real interval hλ > −2.
//!
//! The state moves between two checks, and so does ρ (a pendulum started where gravity has no
//! stiffness): the check runs every 4 steps while h·ρ is above half the limit (just past it,
//! a mode grows slowly), and after a step that changed the state by more than its own size
//! (far past it, a mode grows by orders of magnitude in a step).

use super::problem::Problem;
use super::stepper::{Control, Staged};
use super::{Attempt, State, Step, Stepper};
use crate::error::Failure;

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Euler,
    Rk4,
}

pub(crate) struct Explicit {
    kind: Kind,
    n: usize,
    /// stage positions, and the stages' velocities and accelerations
    qs: Vec<f64>,
    vs: [Vec<f64>; 3],
    acc: [Vec<f64>; 3],
    /// the new state (positions, velocities, accelerations) before it is handed over
    qn: Vec<f64>,
    vn: Vec<f64>,
    an: Vec<f64>,
    watch: StabilityWatch,
}

/// The estimate of the dynamics' largest |λ| that fixed-step explicit schemes (these and
/// DOPRI5 without step control) check their step against (see the module's docs).
pub(crate) struct StabilityWatch {
    /// power iteration on J²: the direction δ = (dq, dv), J δ = (jq, jv), scratch
    dq: Vec<f64>,
    dv: Vec<f64>,
    jq: Vec<f64>,
    jv: Vec<f64>,
    /// δ before the last application of J², for the Rayleigh quotient
    d0q: Vec<f64>,
    d0v: Vec<f64>,
    probe: Probe,
    steps: usize,
    rho: f64,
    /// the fastest mode oscillates (δ·J²δ < 0)
    oscillating: bool,
    /// its eigenvalue (re, im ≥ 0), by `ritz`
    mode: (f64, f64),
    /// the last step changed the state by more than its size: check before the next one
    lurched: bool,
}

/// Explicit Euler's limit of hω on an oscillating mode: its amplitude doubles in one period.
const EULER_OSCILLATING: f64 = 0.226;

/// A start for the power iteration with components on every coordinate and both halves.
fn seed_direction(dq: &mut [f64], dv: &mut [f64]) {
    for i in 0..dq.len() {
        dq[i] = 1.0 + 0.37 * i as f64;
        dv[i] = if i % 2 == 0 { 0.5 } else { -0.8 };
    }
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The dot product of two states (positions, velocities).
fn dot_states(a: (&[f64], &[f64]), b: (&[f64], &[f64])) -> f64 {
    dot(a.0, b.0) + dot(a.1, b.1)
}

/// The eigenvalue (re, im ≥ 0) of largest modulus of J restricted to the Krylov space
/// {δ, Jδ}, from the Gram matrix of δ and Jδ (g11 = δ·δ, g12 = δ·Jδ, g22 = Jδ·Jδ) and the
/// projections of J²δ (r1 = δ·J²δ, r2 = Jδ·J²δ): J²δ ≈ c₀δ + c₁Jδ by least squares, whose
/// λ² = c₁λ + c₀ has the Ritz values as roots; δ ∥ Jδ gives the Rayleigh quotient δ·Jδ/δ·δ.
pub(crate) fn ritz(g11: f64, g12: f64, g22: f64, r1: f64, r2: f64) -> (f64, f64) {
    if g11 == 0.0 {
        // no direction (a model without coordinates): no mode
        return (0.0, 0.0);
    }
    let det = g11 * g22 - g12 * g12;
    if !(det > 1e-12 * g11 * g22) {
        return (g12 / g11, 0.0);
    }
    let c0 = (r1 * g22 - r2 * g12) / det;
    let c1 = (g11 * r2 - g12 * r1) / det;
    let disc = c1 * c1 + 4.0 * c0;
    if disc < 0.0 {
        (0.5 * c1, 0.5 * (-disc).sqrt())
    } else {
        let root = 0.5 * disc.sqrt();
        let (a, b) = (0.5 * c1 + root, 0.5 * c1 - root);
        (if a.abs() >= b.abs() { a } else { b }, 0.0)
    }
}

fn norm2(a: &[f64], b: &[f64]) -> f64 {
    a.iter().chain(b).map(|x| x * x).sum::<f64>().sqrt()
}

impl Explicit {
    fn new(kind: Kind, n: usize) -> Explicit {
        let z = || vec![0.0; n];
        Explicit {
            kind,
            n,
            qs: z(),
            vs: [z(), z(), z()],
            acc: [z(), z(), z()],
            qn: z(),
            vn: z(),
            an: z(),
            watch: StabilityWatch::new(n),
        }
    }

    pub fn euler(n: usize) -> Explicit {
        Explicit::new(Kind::Euler, n)
    }

    pub fn rk4(n: usize) -> Explicit {
        Explicit::new(Kind::Rk4, n)
    }

    fn name(&self) -> &'static str {
        match self.kind {
            Kind::Euler => "explicit Euler",
            Kind::Rk4 => "RK4",
        }
    }
}

/// Radius of the stability interval of h·λ on the axes (RK4: min(2√2, 2.785) on the
/// imaginary and real axes; Euler: 2 on the real axis, and on an oscillating mode the h·ω
/// at which its amplitude doubles in one period, since it is unstable for any).
fn limit(kind: Kind, oscillating: bool) -> f64 {
    match kind {
        Kind::Euler if oscillating => EULER_OSCILLATING,
        Kind::Euler => 2.0,
        Kind::Rk4 => 2.785,
    }
}

impl StabilityWatch {
    pub(crate) fn new(n: usize) -> StabilityWatch {
        let z = || vec![0.0; n];
        let (mut dq, mut dv) = (z(), z());
        seed_direction(&mut dq, &mut dv);
        StabilityWatch {
            dq,
            dv,
            jq: z(),
            jv: z(),
            d0q: z(),
            d0v: z(),
            probe: Probe::new(n),
            steps: 0,
            rho: 0.0,
            oscillating: false,
            mode: (0.0, 0.0),
            lurched: false,
        }
    }

    /// Before a step of size h from `cur`: every 16 steps, every 4 within a factor 2 of the
    /// limit and after a lurch, estimates ρ and refuses the step with `UnstableStep` when h·ρ
    /// exceeds `limit(oscillating)` (the scheme's stability radius for the kind of mode).
    pub(crate) fn check(
        &mut self,
        p: &mut Problem,
        cur: &State,
        h: f64,
        scheme: &'static str,
        limit: impl Fn(bool) -> f64,
    ) -> Result<(), Failure> {
        let every = if h * self.rho > 0.5 * limit(self.oscillating) {
            4
        } else {
            16
        };
        if !self.due(every) {
            return Ok(());
        }
        let first = self.steps == 0;
        self.judge(p, (cur, h, scheme), limit, first, false)
    }

    /// Estimates ρ at `s` and refuses a step h with `UnstableStep` when h·ρ exceeds the limit.
    /// At the start (`settle`), and before refusing a step, the estimate is iterated until it
    /// settles: one iteration from the seed direction can be far below ρ, and the message
    /// advises a step from it. `at_end`: `s` is the end of the step (see [`Self::after`]).
    fn judge(
        &mut self,
        p: &mut Problem,
        (s, h, scheme): (&State, f64, &'static str),
        limit: impl Fn(bool) -> f64,
        settle: bool,
        at_end: bool,
    ) -> Result<(), Failure> {
        self.refresh(p, s, false)?;
        if settle || h * self.rho > limit(self.oscillating) {
            self.settle(p, s)?;
        }
        let (h_rho, limit) = (h * self.rho, limit(self.oscillating));
        if h_rho <= limit {
            return Ok(());
        }
        // the end of a step may be a state the step blew up, whose ρ says little of the
        // model's (1e38 1/s after one DOPRI5 step of 10 s): the step advised is then at least
        // a hundredth of this one, and the checks before each smaller step judge it
        let h_stable = limit / self.rho;
        Err(Failure::UnstableStep {
            scheme,
            rho: self.rho,
            h_rho,
            limit,
            h_stable: if at_end {
                h_stable.max(0.01 * h)
            } else {
                h_stable
            },
            at_end,
        })
    }

    /// After a step of size h from `cur` to `next`, before it is accepted: when the step
    /// changed the state by more than its own size (a lurch), ρ is estimated at `next` and the
    /// step refused with `UnstableStep` when h·ρ exceeds the limit. The check before each
    /// step sees the state the step starts from; a run whose last step lurches has no next
    /// step to catch it (the double pendulum started where gravity has no stiffness, one step
    /// of explicit Euler to t_end = 10 s: ρ ≈ 0 at the start, the energy 100 % off at the end,
    /// no word).
    pub(crate) fn after(
        &mut self,
        p: &mut Problem,
        steps: (&State, &State, f64),
        scheme: &'static str,
        limit: impl Fn(bool) -> f64,
    ) -> Result<(), Failure> {
        let (cur, next, h) = steps;
        if !lurched(cur, next) {
            return Ok(());
        }
        self.judge(p, (next, h, scheme), limit, false, true)
    }

    /// Whether an estimate is due: every `every` steps, and after a lurch.
    pub(crate) fn due(&self, every: usize) -> bool {
        self.steps % every == 0 || self.lurched
    }

    /// The accepted steps so far.
    pub(crate) fn steps(&self) -> usize {
        self.steps
    }

    /// The last estimate of the fastest mode's eigenvalue (re, im ≥ 0), from the last power
    /// iteration's Krylov space {δ, Jδ}: exact once δ lies in the mode's invariant plane.
    pub(crate) fn mode(&self) -> (f64, f64) {
        self.mode
    }

    /// Estimates ρ now: one power iteration, and with `settle` more until it changes by less
    /// than 0.1 %.
    pub(crate) fn refresh(
        &mut self,
        p: &mut Problem,
        cur: &State,
        settle: bool,
    ) -> Result<(), Failure> {
        self.rho = self.estimate_rho(p, cur)?;
        if settle {
            self.settle(p, cur)?;
        }
        Ok(())
    }

    /// Iterates the estimate until it changes by less than 0.1 % (at most 30 times).
    fn settle(&mut self, p: &mut Problem, cur: &State) -> Result<(), Failure> {
        for _ in 0..30 {
            let last = self.rho;
            self.rho = self.estimate_rho(p, cur)?;
            if (self.rho - last).abs() <= 1e-3 * self.rho {
                break;
            }
        }
        Ok(())
    }

    /// After an accepted step from `cur` to `next`.
    pub(crate) fn accepted(&mut self, cur: &State, next: &State) {
        self.lurched = lurched(cur, next);
        self.steps += 1;
    }

    /// One power-iteration step on J²; returns the estimate of ρ(J).
    fn estimate_rho(&mut self, p: &mut Problem, s: &State) -> Result<f64, Failure> {
        let n0 = norm2(&self.dq, &self.dv);
        self.probe
            .apply_j(p, s, &self.dq, &self.dv, &mut self.jq, &mut self.jv)?;
        self.d0q.copy_from_slice(&self.dq);
        self.d0v.copy_from_slice(&self.dv);
        self.probe
            .apply_j(p, s, &self.jq, &self.jv, &mut self.dq, &mut self.dv)?;
        let n2 = norm2(&self.dq, &self.dv);
        if !(n2 > 0.0) || !n2.is_finite() || !(n0 > 0.0) {
            seed_direction(&mut self.dq, &mut self.dv);
            return Ok(self.rho);
        }
        // δ = d0, Jδ = j, J²δ = d
        let d0 = (self.d0q.as_slice(), self.d0v.as_slice());
        let j = (self.jq.as_slice(), self.jv.as_slice());
        let d = (self.dq.as_slice(), self.dv.as_slice());
        let dot = dot_states;
        let rayleigh = dot(d0, d);
        self.mode = ritz(dot(d0, d0), dot(d0, j), dot(j, j), rayleigh, dot(j, d));
        self.oscillating = rayleigh < 0.0;
        for x in self.dq.iter_mut().chain(self.dv.iter_mut()) {
            *x /= n2;
        }
        Ok((n2 / n0).sqrt())
    }
}

/// Whether a step changed (q, qd) by more than the larger of their size and 1: a step past
/// the stability limit on a mode the last check did not see (ρ changes with the state).
fn lurched(cur: &State, next: &State) -> bool {
    let (mut change, mut size) = (0.0f64, 1.0f64);
    for (a, b) in cur.q.iter().zip(&next.q).chain(cur.qd.iter().zip(&next.qd)) {
        change = change.max((b - a).abs());
        size = size.max(a.abs());
    }
    change > size
}

/// The point a Jacobian-vector product is probed at: q, qd and the accelerations there.
pub(crate) struct Probe {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
}

impl Probe {
    pub(crate) fn new(n: usize) -> Probe {
        Probe {
            q: vec![0.0; n],
            v: vec![0.0; n],
            a: vec![0.0; n],
        }
    }

    /// (oq, ov) = J·(iq, iv) at `s`, by a forward difference of the accelerations.
    pub(crate) fn apply_j(
        &mut self,
        p: &mut Problem,
        s: &State,
        iq: &[f64],
        iv: &[f64],
        oq: &mut [f64],
        ov: &mut [f64],
    ) -> Result<(), Failure> {
        let (pq, pv, pa) = (&mut self.q, &mut self.v, &mut self.a);
        let norm = norm2(iq, iv).max(f64::MIN_POSITIVE);
        let scale =
            s.q.iter()
                .chain(s.qd.iter())
                .map(|x| x.abs())
                .fold(1.0, f64::max);
        let eps = f64::EPSILON.sqrt() * scale / norm;
        for i in 0..s.q.len() {
            pq[i] = s.q[i] + eps * iq[i];
            pv[i] = s.qd[i] + eps * iv[i];
        }
        p.accel(s.t, pq, pv, pa)?;
        for i in 0..s.q.len() {
            oq[i] = iv[i];
            ov[i] = (pa[i] - s.qdd[i]) / eps;
        }
        Ok(())
    }
}

impl Stepper for Explicit {
    fn attempt(&mut self, step: Step<'_>) -> Result<Attempt, Failure> {
        let Step(p, cur, h, ctl, next) = step;
        self.begin(p, cur, h, ctl)?;
        for s in 1..=self.stages() {
            let (c, _, _) = self.point(p, cur, h, s)?;
            let (q, v, a) = self.stage(s);
            p.accel(cur.t + c * h, q, v, a)?;
        }
        self.complete(Step(p, cur, h, ctl, next))
    }

    fn staged(&mut self) -> Option<&mut dyn Staged> {
        Some(self)
    }
}

impl Explicit {
    /// Stage `s`'s positions and velocities, and where its accelerations go: RK4's inner
    /// stages, then the new state (Euler's only one).
    fn stage(&mut self, s: usize) -> (&[f64], &[f64], &mut [f64]) {
        if s < self.stages() {
            (&self.qs, &self.vs[s - 1], &mut self.acc[s - 1])
        } else {
            (&self.qn, &self.vn, &mut self.an)
        }
    }
}

impl Staged for Explicit {
    fn stages(&self) -> usize {
        match self.kind {
            Kind::Euler => 1,
            Kind::Rk4 => 4,
        }
    }

    fn begin(
        &mut self,
        p: &mut Problem,
        cur: &State,
        h: f64,
        ctl: &Control,
    ) -> Result<(), Failure> {
        if ctl.stability_check {
            let kind = self.kind;
            self.watch
                .check(p, cur, h, self.name(), |osc| limit(kind, osc))?;
        }
        Ok(())
    }

    fn point(
        &mut self,
        p: &Problem,
        cur: &State,
        h: f64,
        s: usize,
    ) -> Result<(f64, &[f64], &[f64]), Failure> {
        let n = self.n;
        if s < self.stages() {
            // RK4's stage s at t + c h from the previous stage's (v, a); stage 1 from (qd0, qdd0)
            let k = s - 1;
            let c = if k < 2 { 0.5 } else { 1.0 };
            let (vdone, vrest) = self.vs.split_at_mut(k);
            let (vprev, aprev): (&[f64], &[f64]) = if k == 0 {
                (&cur.qd, &cur.qdd)
            } else {
                (&vdone[k - 1], &self.acc[k - 1])
            };
            for i in 0..n {
                self.qs[i] = cur.q[i] + c * h * vprev[i];
                vrest[0][i] = cur.qd[i] + c * h * aprev[i];
            }
            return Ok((c, &self.qs, &self.vs[k]));
        }
        match self.kind {
            Kind::Euler => {
                for i in 0..n {
                    self.qn[i] = cur.q[i] + h * cur.qd[i];
                    self.vn[i] = cur.qd[i] + h * cur.qdd[i];
                }
            }
            Kind::Rk4 => {
                for i in 0..n {
                    self.qn[i] = cur.q[i]
                        + h / 6.0
                            * (cur.qd[i]
                                + 2.0 * self.vs[0][i]
                                + 2.0 * self.vs[1][i]
                                + self.vs[2][i]);
                    self.vn[i] = cur.qd[i]
                        + h / 6.0
                            * (cur.qdd[i]
                                + 2.0 * self.acc[0][i]
                                + 2.0 * self.acc[1][i]
                                + self.acc[2][i]);
                }
            }
        }
        p.check("q", &self.qn)?;
        p.check("qd", &self.vn)?;
        Ok((1.0, &self.qn, &self.vn))
    }

    fn accel_mut(&mut self, s: usize) -> &mut [f64] {
        self.stage(s).2
    }

    fn stage_failed(&mut self, e: Failure, _ctl: &Control, _h: f64) -> Result<Attempt, Failure> {
        Err(e)
    }

    fn complete(&mut self, step: Step<'_>) -> Result<Attempt, Failure> {
        let Step(p, cur, h, ctl, next) = step;
        next.q.copy_from_slice(&self.qn);
        next.qd.copy_from_slice(&self.vn);
        next.qdd.copy_from_slice(&self.an);
        if ctl.stability_check {
            let kind = self.kind;
            self.watch
                .after(p, (cur, next, h), self.name(), |osc| limit(kind, osc))?;
        }
        self.watch.accepted(cur, next);
        Ok(Attempt::Accepted { h_next: h })
    }
}
