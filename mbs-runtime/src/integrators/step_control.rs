//! Step-size control, shared by every adaptive scheme: the tolerances and the weighted error
//! norm they define, the controllers that turn an error norm into the next step, and the
//! first step.
//!
//! | controller | used by | rule |
//! |---|---|---|
//! | [`elementary_factor`] | Newmark family, BDF | h·safety·err^(−1/(k+1)) within bounds |
//! | [`PiController`] | DOPRI5 | Hairer's PI form, err^(α)/err_old^β |
//! | [`Predictive`] | Radau | RADAU5's, with Gustafsson's predictive correction |
//! | [`initial_step`] | the driver | Hairer, Nørsett & Wanner, II.4 |
//!
//! An error norm ≤ 1 accepts the step; k is the order of the error estimate (local error
//! ∝ h^(k+1)).

use super::State;
use crate::options::Options;

/// The rounding a step carries, in ε: the floor of the local tolerance rtol' and, times the
/// state's largest entry, of the weights of [`Tolerances::error_norm`].
pub(crate) const ROUNDING: f64 = 100.0;

/// Relative and absolute tolerance of the local error: a component y_i of error e_i counts as
/// e_i / (atol + rtol·|y_i|).
///
/// `groups` > 1 splits the positions and the velocities into that many equal groups, each
/// normed on its own, and the norm is the largest of theirs (as CVODES's error control with
/// sensitivities): a model with forward sensitivities ([`crate::Sensitivities`]) is its motion
/// and one group per parameter. One RMS norm over them all divided the motion's error by
/// √(1 + NS) where the sensitivities' errors are small against their weights, so that adding
/// sensitivities loosened the control of the motion itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Tolerances {
    pub rtol: f64,
    pub atol: f64,
    pub groups: usize,
}

impl Tolerances {
    /// The tolerances a scheme's error test uses for the user's `self`: rtol' = c·rtol^e, atol
    /// kept. A scheme of order p whose error test bounds the local error per step has a
    /// global error ∝ tol^(p/(p+1)); e = (p+1)/p makes it proportional to rtol, and c is
    /// measured so that the global error is about what other schemes give at the same rtol.
    /// atol is not scaled (RADAU5 scales it with rtol): it is what the user said not to
    /// resolve, and scaled down it made BDF resolve a stiff spring's oscillation of 1e-9 m
    /// under atol = 1e-8 m (springpend at k = 1e8 N/m: 24,000 steps instead of 45).
    /// rtol' never falls below 100ε (or the user's rtol, if tighter): the rounding of a step.
    pub fn transformed(self, c: f64, e: f64) -> Tolerances {
        Tolerances {
            rtol: (c * self.rtol.powf(e)).max(Self::transformed_floor(self.rtol)),
            ..self
        }
    }

    /// The floor of [`Tolerances::transformed`] for `rtol`: [`ROUNDING`]·ε, or rtol if
    /// tighter.
    pub fn transformed_floor(rtol: f64) -> f64 {
        rtol.min(ROUNDING * f64::EPSILON)
    }

    /// The local tolerance [`Tolerances::transformed`] holds for `rtol` when its floor set it
    /// (c·rtol^e below the floor), else `None`.
    pub fn transformed_floored(rtol: f64, c: f64, e: f64) -> Option<f64> {
        let floor = Self::transformed_floor(rtol);
        (c * rtol.powf(e) < floor).then_some(floor)
    }

    /// Weighted RMS norm of an error vector e against the state scales y0, y1:
    /// sqrt(mean (e_i / w_i)²), w_i = atol + rtol·max(|y0_i|, |y1_i|), but never below
    /// [`ROUNDING`]·ε (or rtol, if tighter: the floor of [`Tolerances::transformed`]) times
    /// the largest entry of the same kind: a component is computed from the others (a closed
    /// loop's velocities from one another), so its rounding follows the largest of them, and
    /// a weight below that asks for digits no step size gives (the step would shrink to
    /// h_min: fastlink's coupler turning through zero at 2e-3 rad/s while its crank turns at
    /// 1,100 rad/s, under atol = 1e-12). The entries come in blocks of `kind` of one kind
    /// (positions, then velocities, then the rest: multipliers), so that a velocity's
    /// magnitude never floors a position's weight.
    pub fn error_norm(&self, e: &[f64], y0: &[f64], y1: &[f64], kind: usize) -> f64 {
        self.norm(e, y0, y1, kind).value
    }

    /// [`Tolerances::error_norm`], and whether the floor set a weight (`Stats::floored_steps`).
    pub fn norm(&self, e: &[f64], y0: &[f64], y1: &[f64], kind: usize) -> ErrorNorm {
        let n = e.len();
        let bounds = [0, kind.min(n), (2 * kind).min(n), n];
        let block = |k: usize| {
            let r = bounds[k]..bounds[k + 1];
            (&e[r.clone()], &y0[r.clone()], &y1[r])
        };
        self.norm_of_blocks([block(0), block(1), block(2)])
    }

    /// [`Tolerances::norm`] of a vector given as its blocks (positions, velocities,
    /// multipliers), each `(e, y0, y1)` a slice of its own: a scheme whose state is kept in
    /// separate vectors does not copy it into one.
    pub fn norm_of_blocks(&self, blocks: [(&[f64], &[f64], &[f64]); 3]) -> ErrorNorm {
        let (rtol, atol) = (self.rtol, self.atol);
        let groups = self.groups.max(1);
        // the part of block `b` that belongs to group `g`: positions and velocities split
        // into `groups` equal parts when they divide; anything else is group 0's
        let part = |b: usize, g: usize| {
            let len = blocks[b].0.len();
            if groups > 1 && b < 2 && len % groups == 0 {
                let k = len / groups;
                g * k..(g + 1) * k
            } else if g == 0 {
                0..len
            } else {
                0..0
            }
        };
        let (mut value, mut nan, mut floored) = (0.0f64, false, false);
        let mut top = Argmax::default();
        let mut top_floor = 0.0;
        for g in 0..groups {
            let (mut s, mut n) = (0.0, 0usize);
            for (b, &(e, y0, y1)) in blocks.iter().enumerate() {
                let r = part(b, g);
                let (e, y0, y1) = (&e[r.clone()], &y0[r.clone()], &y1[r.clone()]);
                let len = e.len();
                let largest = y0.iter().chain(y1).fold(0.0f64, |m, y| m.max(y.abs()));
                let floor = Self::transformed_floor(rtol) * largest;
                // the part's largest term as `Argmax` takes it (the first NaN, else the first
                // of the largest), chosen without a branch: the terms come in no order a
                // branch predictor could learn
                let (mut best, mut at) = (-1.0f64, 0);
                for i in 0..len {
                    let magnitude = y0[i].abs().max(y1[i].abs());
                    let w = atol + rtol * magnitude;
                    floored |= w < floor;
                    let weight = w.max(floor);
                    let term = (e[i] / weight) * (e[i] / weight);
                    s += term;
                    let new = !(term <= best) & !best.is_nan();
                    best = if new { term } else { best };
                    at = if new { i } else { at };
                }
                n += len;
                if len > 0 && top.see(best, b, r.start + at) {
                    top_floor = floor;
                }
            }
            let v = (s / n.max(1) as f64).sqrt();
            nan |= v.is_nan();
            value = value.max(v);
        }
        // the component that weighed most, described once
        let held_by = top.at.map(|(block, index)| {
            let (e, y0, y1) = blocks[block];
            let floor = top_floor;
            let magnitude = y0[index].abs().max(y1[index].abs());
            let w = atol + rtol * magnitude;
            let set_by = if w < floor {
                WeightBy::Rounding
            } else if atol >= rtol * magnitude {
                WeightBy::Atol
            } else {
                WeightBy::Rtol
            };
            Largest {
                block,
                index,
                error: e[index],
                magnitude,
                weight: w.max(floor),
                set_by,
            }
        });
        ErrorNorm {
            value: if nan { f64::NAN } else { value },
            floored,
            held_by,
        }
    }
}

/// The largest of a run of weighted terms of a norm (the first NaN, if any), and where it is:
/// (block, index in the block), block 0 positions, 1 velocities, 2 multipliers.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Argmax {
    top: f64,
    pub at: Option<(usize, usize)>,
}

impl Default for Argmax {
    fn default() -> Argmax {
        Argmax {
            top: -1.0,
            at: None,
        }
    }
}

impl Argmax {
    /// Takes `term` of component `index` of `block` into account; true when it is the new
    /// largest.
    pub fn see(&mut self, term: f64, block: usize, index: usize) -> bool {
        let new = !(term <= self.top) && !self.top.is_nan();
        if new {
            self.top = term;
            self.at = Some((block, index));
        }
        new
    }
}

/// The component of an error vector whose term |e_i|/w_i weighed most in its norm: what held
/// the step, named by `Failure::StepTooSmall` when the step falls below h_min.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Largest {
    /// its block in the norm's vector: 0 positions, 1 velocities, 2 multipliers
    pub block: usize,
    /// its index in the block
    pub index: usize,
    pub error: f64,
    /// max(|y0_i|, |y1_i|)
    pub magnitude: f64,
    pub weight: f64,
    pub set_by: WeightBy,
}

/// A component of an error norm's vector in words: block 0 positions (`label` of the
/// coordinate, "q[3] (name)"), 1 velocities, 2 multipliers.
pub(crate) fn component_name(
    block: usize,
    index: usize,
    label: impl Fn(usize) -> String,
) -> String {
    match block {
        0 => label(index),
        1 => format!("the velocity of {}", label(index)),
        _ => format!("λ[{index}]"),
    }
}

/// What set a component's weight in an error norm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum WeightBy {
    Atol,
    Rtol,
    /// the rounding floor, [`ROUNDING`]·ε times the largest entry of its kind
    Rounding,
}

impl Largest {
    /// The same component in a vector of velocities alone (a norm taken over qd only).
    pub fn as_velocity(self) -> Largest {
        Largest {
            block: self.block + 1,
            ..self
        }
    }

    /// What held the step, in words for `Failure::StepTooSmall`: the component labelled by
    /// `label` (coordinate index → "q[3] (name)"), its error and tolerance, what set it, and
    /// the largest entry of its kind at the start (`start`: positions, velocities).
    pub fn held_by(
        &self,
        label: impl Fn(usize) -> String,
        start: [f64; 2],
    ) -> crate::error::HeldBy {
        crate::error::HeldBy {
            start: start.get(self.block).copied(),
            component: component_name(self.block, self.index, label),
            value: self.magnitude,
            error: self.error,
            tolerance: self.weight,
            set_by: match self.set_by {
                WeightBy::Atol => "atol",
                WeightBy::Rtol => "rtol",
                WeightBy::Rounding => "rounding",
            },
        }
    }
}

/// A weighted error norm ([`Tolerances::norm`]) and whether the rounding floor raised the
/// weight of some component above atol + rtol·|y|: that component was tested at the digits
/// rounding leaves it, fewer than the tolerances asked. A scheme keeps its last error test's
/// for the driver (`Stepper::last_test`; the default, none taken).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct ErrorNorm {
    pub value: f64,
    pub floored: bool,
    /// the component whose term weighed most (none for an empty vector)
    pub held_by: Option<Largest>,
}

/// The factor f = c·√rtol on both tolerances of an order-2 scheme's local error test (rtol·f,
/// atol·f), so that its global error, ∝ tol^⅔, follows rtol (Newmark family, RKC); within
/// [floor/rtol, 1]: no local tolerance below `floor`.
pub(crate) fn order_two_factor(rtol: f64, c: f64, floor: f64) -> f64 {
    (c * rtol.sqrt()).clamp((floor / rtol).min(1.0), 1.0)
}

/// The local tolerance rtol·f of [`order_two_factor`] when its floor set it (c·rtol^1.5
/// below a floor tighter than rtol), else `None`.
pub(crate) fn order_two_floored(rtol: f64, c: f64, floor: f64) -> Option<f64> {
    (c * rtol.sqrt() < floor / rtol && floor < rtol).then_some(floor)
}

/// err^(−1/(k+1)): the factor on h that brings the error of an estimate of order k to 1.
pub(crate) fn optimal_factor(err: f64, order: usize) -> f64 {
    err.powf(-1.0 / (order as f64 + 1.0))
}

/// The elementary controller: h_new/h = safety·err^(−1/(k+1)) within [min, max]; an error
/// of zero gives `max`, a non-finite one `min`.
pub(crate) fn elementary_factor(err: f64, order: usize, safety: f64, min: f64, max: f64) -> f64 {
    if err.is_nan() {
        return min;
    }
    (safety * optimal_factor(err, order)).clamp(min, max)
}

/// Next step from an error norm with the elementary controller at safety 0.9, shrinking at
/// most 5-fold and growing at most `fmax`-fold.
pub(crate) fn next_step(h: f64, err: f64, order: usize, fmax: f64) -> f64 {
    h * elementary_factor(err, order, 0.9, 0.2, fmax)
}

/// What a controller decided on an attempt, with the step to try next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Decision {
    Accept { h_next: f64 },
    Reject { h_next: f64 },
}

/// Hairer's PI controller (DOPRI5, Hairer, Nørsett & Wanner I, II.4):
/// h_new = h·0.9·err^(−α)·err_old^β, α = 1/(k+1) − 0.75β, the factor h/h_new within
/// [0.1, 5]; no growth right after a rejection. A rejected step uses the elementary part only.
#[derive(Clone, Debug)]
pub(crate) struct PiController {
    alpha: f64,
    beta: f64,
    /// error norm of the last accepted step (floored at 1e-4)
    err_old: f64,
    /// the last attempt was rejected
    rejected: bool,
}

impl PiController {
    /// For an error estimate of order `order`, with integral gain `beta` (DOPRI5: 4, 0.04).
    pub fn new(order: usize, beta: f64) -> PiController {
        PiController {
            alpha: 1.0 / (order as f64 + 1.0) - 0.75 * beta,
            beta,
            err_old: 1e-4,
            rejected: false,
        }
    }

    /// The verdict on a step of size h with error norm `err`.
    pub fn decide(&mut self, h: f64, err: f64) -> Decision {
        let fac11 = err.powf(self.alpha);
        let fac = (fac11 / self.err_old.powf(self.beta) / 0.9).clamp(0.1, 5.0);
        if err <= 1.0 {
            self.err_old = err.max(1e-4);
            let mut h_next = h / fac;
            if self.rejected {
                h_next = h_next.min(h);
            }
            self.rejected = false;
            Decision::Accept { h_next }
        } else {
            self.rejected = true;
            Decision::Reject {
                h_next: h / (fac11 / 0.9).min(5.0),
            }
        }
    }

    /// The attempt was rejected for another reason than its error (no growth after it).
    pub fn rejected_otherwise(&mut self) {
        self.rejected = true;
    }
}

/// RADAU5's controller (Hairer & Wanner II, IV.8): the quotient q = h/h_new =
/// err^(1/(k+1))/fac within [1/8, 5], fac the safety factor the caller gives (RADAU5 lowers it
/// with the Newton iterations), and on accepted steps after the first Gustafsson's predictive
/// correction (ACM TOMS 20, 1994): q ← max(q, (h_acc/h)(err²/err_acc)^(1/(k+1))/0.9), h_acc
/// and err_acc those of the previous accepted step.
#[derive(Clone, Debug)]
pub(crate) struct Predictive {
    expo: f64,
    accepted: usize,
    h_acc: f64,
    err_acc: f64,
}

impl Predictive {
    pub const SAFETY: f64 = 0.9;
    /// bounds of q = h/h_new: h shrinks by at most 5 and grows by at most 8 per step
    const MAX_QUOT: f64 = 5.0;
    const MIN_QUOT: f64 = 0.125;

    /// For an error estimate of order `order`.
    pub fn new(order: usize) -> Predictive {
        Predictive {
            expo: 1.0 / (order as f64 + 1.0),
            accepted: 0,
            h_acc: 0.0,
            err_acc: 1e-2,
        }
    }

    /// Forgets the accepted steps (a restart).
    pub fn restart(&mut self) {
        self.accepted = 0;
    }

    /// The elementary quotient h/h_new for an error norm `err` with safety factor `fac`.
    pub fn quotient(&self, err: f64, fac: f64) -> f64 {
        (err.powf(self.expo) / fac).clamp(Self::MIN_QUOT, Self::MAX_QUOT)
    }

    /// An accepted step h of error `err` whose elementary quotient is `quot`: the step to
    /// try next, with the predictive correction from the second accepted step on.
    pub fn accept(&mut self, h: f64, err: f64, quot: f64) -> f64 {
        let mut quot = quot;
        self.accepted += 1;
        if self.accepted > 1 {
            let facgus =
                (self.h_acc / h) * (err * err / self.err_acc).powf(self.expo) / Self::SAFETY;
            quot = quot.max(facgus.clamp(Self::MIN_QUOT, Self::MAX_QUOT));
        }
        self.h_acc = h;
        self.err_acc = err.max(1e-2);
        h / quot
    }
}

/// The bounds of a first step: the span of the run, h_max and h_min.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepBounds {
    pub span: f64,
    pub h_max: f64,
    pub h_min: f64,
}

impl StepBounds {
    pub fn of(o: &Options) -> StepBounds {
        StepBounds {
            span: o.t_end - o.t0,
            h_max: o.h_max,
            h_min: o.h_min(),
        }
    }
}

/// First step of adaptive schemes (Hairer, Nørsett & Wanner I, II.4): from the sizes of y, f
/// and of f's change over a trial Euler step, for a method of order `order`, within `b`.
/// `accel(t, q, qd, qdd)` evaluates the accelerations (false when it fails: the trial step's
/// size is then taken). Allocates: called once per run.
pub(crate) fn initial_step(
    s: &State,
    tol: Tolerances,
    order: usize,
    b: StepBounds,
    mut accel: impl FnMut(f64, &[f64], &[f64], &mut [f64]) -> bool,
) -> f64 {
    let Tolerances { rtol, atol, .. } = tol;
    let n = s.q.len();
    let w = |y: f64| atol + rtol * y.abs();
    let norm = |a: &[f64], b: &[f64], ya: &[f64], yb: &[f64]| {
        let ss: f64 = (0..n)
            .map(|i| (a[i] / w(ya[i])).powi(2) + (b[i] / w(yb[i])).powi(2))
            .sum();
        (ss / (2 * n).max(1) as f64).sqrt()
    };
    let d0 = norm(&s.q, &s.qd, &s.q, &s.qd);
    let d1 = norm(&s.qd, &s.qdd, &s.q, &s.qd);
    let mut h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    h0 = h0.min(b.span).min(b.h_max);
    let q1: Vec<f64> = (0..n).map(|i| s.q[i] + h0 * s.qd[i]).collect();
    let v1: Vec<f64> = (0..n).map(|i| s.qd[i] + h0 * s.qdd[i]).collect();
    let mut a1 = vec![0.0; n];
    if !accel(s.t + h0, &q1, &v1, &mut a1) {
        return h0.max(b.h_min);
    }
    let dv: Vec<f64> = (0..n).map(|i| (v1[i] - s.qd[i]) / h0).collect();
    let da: Vec<f64> = (0..n).map(|i| (a1[i] - s.qdd[i]) / h0).collect();
    let d2 = norm(&dv, &da, &s.q, &s.qd);
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / (order as f64 + 1.0))
    };
    (100.0 * h0).min(h1).min(b.span).min(b.h_max).max(b.h_min)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The component that held the norm, as `Argmax::see` takes it term by term over the
    /// whole vector: the first NaN, else the first of the largest.
    fn held_by_term_by_term(tol: Tolerances, e: &[f64], y0: &[f64], y1: &[f64], kind: usize) {
        let n = e.len();
        let bounds = [0, kind.min(n), (2 * kind).min(n), n];
        let mut top = Argmax::default();
        for b in 0..3 {
            let (start, end) = (bounds[b], bounds[b + 1]);
            let largest = (y0[start..end].iter())
                .chain(&y1[start..end])
                .fold(0.0f64, |m, y| m.max(y.abs()));
            let floor = Tolerances::transformed_floor(tol.rtol) * largest;
            for i in start..end {
                let w = (tol.atol + tol.rtol * y0[i].abs().max(y1[i].abs())).max(floor);
                top.see((e[i] / w) * (e[i] / w), b, i - start);
            }
        }
        let got = tol
            .norm(e, y0, y1, kind)
            .held_by
            .map(|l| (l.block, l.index));
        assert_eq!(got, top.at, "e = {e:?}");
    }

    #[test]
    fn the_norm_s_largest_term_is_the_first_nan_else_the_first_of_the_largest() {
        let tol = Tolerances {
            rtol: 1e-3,
            atol: 1e-6,
            groups: 1,
        };
        let (y0, y1) = ([1.0; 5], [1.0; 5]);
        let nan = f64::NAN;
        for e in [
            [1.0, 3.0, 3.0, 2.0, 0.5], // a tie within the positions
            [1.0, 3.0, 1.0, 3.0, 0.5], // a tie across blocks: the positions' one
            [1.0, 3.0, 1.0, 4.0, 0.5], // the largest among the velocities
            [9.0, 3.0, nan, 4.0, 0.5], // a NaN after a larger finite term
            [1.0, nan, 1.0, nan, 0.5], // NaNs in two blocks: the first
            [0.0, 0.0, 0.0, 0.0, 0.0], // all zero: the first
            [1.0, 1.0, 1.0, 1.0, nan], // a NaN among the multipliers
        ] {
            held_by_term_by_term(tol, &e, &y0, &y1, 2);
            // an empty velocity block and no multipliers
            held_by_term_by_term(tol, &e[..2], &y0[..2], &y1[..2], 2);
            // one block only
            held_by_term_by_term(tol, &e, &y0, &y1, 5);
        }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-14 * a.abs().max(b.abs())
    }

    /// Groups (a motion and its sensitivities) are normed apart, the largest norm counts, and
    /// a NaN in any group makes the norm NaN.
    #[test]
    fn the_norm_of_groups_is_their_largest() {
        let tol = Tolerances {
            rtol: 1e-3,
            atol: 1.0,
            groups: 2,
        };
        // positions (a, b) and velocities (c, d): group 0 is (a, c), group 1 (b, d)
        let y = [0.0; 4];
        let n = tol.error_norm(&[3.0, 0.0, 4.0, 0.0], &y, &y, 2);
        assert!(close(n, (25.0f64 / 2.0).sqrt()), "{n}");
        let n = tol.error_norm(&[3.0, 1.0, 4.0, 1.0], &y, &y, 2);
        assert!(close(n, (25.0f64 / 2.0).sqrt()), "{n}");
        let n = tol.error_norm(&[0.0, 1.0, 0.0, f64::NAN], &y, &y, 2);
        assert!(n.is_nan());
        let n = tol.error_norm(&[f64::NAN, 1.0, 0.0, 0.0], &y, &y, 2);
        assert!(n.is_nan());
        // one group: the RMS over all
        let one = Tolerances { groups: 1, ..tol };
        let n = one.error_norm(&[3.0, 1.0, 4.0, 1.0], &y, &y, 2);
        assert!(close(n, (27.0f64 / 4.0).sqrt()), "{n}");
    }

    #[test]
    fn error_norm_weighs_each_component_by_the_larger_state() {
        let tol = Tolerances {
            rtol: 1e-3,
            atol: 1e-6,
            groups: 1,
        };
        // weights 1e-6 + 1e-3·2 and 1e-6 + 1e-3·0.5
        let e = [2.001e-3, -1.002e-3];
        let n = tol.error_norm(&e, &[2.0, -0.5], &[1.0, 0.25], 2);
        assert!(close(n, ((1.0 + 4.0) / 2.0f64).sqrt()), "{n}");
        assert_eq!(tol.error_norm(&[], &[], &[], 0), 0.0);
    }

    #[test]
    fn no_weight_asks_for_less_than_the_rounding_of_the_largest_entry() {
        let tol = Tolerances {
            rtol: 1e-11,
            atol: 1e-12,
            groups: 1,
        };
        // a velocity through zero beside one of 1,000: its weight is 100ε·1,000, not
        // atol + rtol·0.002 ≈ 1.02e-12
        let e = [0.0, 3e-12];
        let floor = ROUNDING * f64::EPSILON * 1000.0;
        let n = tol.error_norm(&e, &[1000.0, 0.002], &[999.0, -0.001], 2);
        assert!(close(n, (3e-12 / floor) / 2.0f64.sqrt()), "{n}");
        // beside a largest entry of 1 the floor (2.2e-14) is below the weight
        let n = tol.error_norm(&e, &[1.0, 0.002], &[1.0, -0.001], 2);
        let w = 1e-12 + 1e-11 * 0.002;
        assert!(close(n, (3e-12 / w) / 2.0f64.sqrt()), "{n}");
    }

    #[test]
    fn the_rounding_floor_of_a_weight_comes_from_entries_of_its_own_kind() {
        let tol = Tolerances {
            rtol: 1e-11,
            atol: 1e-12,
            groups: 1,
        };
        // (q0, q1, qd0, qd1, λ): a position of 0.01 m beside a velocity of 1,000 and a
        // multiplier of 1e6; each weight's floor is 100ε times the largest of its kind
        let (y0, y1) = (
            [0.01, 0.002, 1000.0, 0.002, 1e6],
            [0.01, 0.002, 999.0, -0.001, 1e6],
        );
        let floor = |largest: f64| ROUNDING * f64::EPSILON * largest;
        let weight = |i: usize, largest: f64| {
            (1e-12 + 1e-11 * f64::abs(y0[i]).max(f64::abs(y1[i]))).max(floor(largest))
        };
        let e = [1e-13, 2e-13, 3e-13, 4e-13, 5e-10];
        let expected = [0.01, 0.01, 1000.0, 1000.0, 1e6]
            .iter()
            .enumerate()
            .map(|(i, &l)| (e[i] / weight(i, l)).powi(2))
            .sum::<f64>()
            / 5.0;
        let n = tol.error_norm(&e, &y0, &y1, 2);
        assert!(close(n, expected.sqrt()), "{n} against {}", expected.sqrt());
        // the position q1 keeps its own weight (atol + rtol·0.002), not 100ε·1,000
        assert!(weight(1, 0.01) < 1.1e-12 && floor(1000.0) > 2e-11);
        // one kind over the whole vector: the velocity's magnitude floors every weight
        let all = tol.error_norm(&e[..4], &y0[..4], &y1[..4], 4);
        let by_kind = tol.error_norm(&e[..4], &y0[..4], &y1[..4], 2);
        assert!(all < 0.1 * by_kind, "{all} {by_kind}");
        // the floor is said: the velocity qd1 (1e-12 + 1e-11·0.002 against 100ε·1,000) sits
        // on it; the positions alone do not
        assert!(tol.norm(&e, &y0, &y1, 2).floored);
        assert!(!tol.norm(&e[..2], &y0[..2], &y1[..2], 2).floored);
    }

    #[test]
    fn elementary_controller_scales_with_the_order_and_stays_in_bounds() {
        // an error 2^(k+1) asks for half the step, times the safety factor
        for k in 1..=5 {
            let err = 2f64.powi(k as i32 + 1);
            assert!(close(elementary_factor(err, k, 0.9, 0.2, 5.0), 0.45));
        }
        assert!(close(elementary_factor(1.0, 3, 0.9, 0.2, 5.0), 0.9));
        assert_eq!(elementary_factor(0.0, 2, 0.9, 0.2, 2.0), 2.0);
        assert_eq!(elementary_factor(1e30, 2, 0.9, 0.2, 2.0), 0.2);
        assert_eq!(elementary_factor(f64::INFINITY, 2, 0.9, 0.2, 2.0), 0.2);
        assert_eq!(elementary_factor(f64::NAN, 2, 0.9, 0.2, 2.0), 0.2);
        assert!(close(next_step(0.1, 8.0, 2, 1.0), 0.1 * 0.45));
        assert_eq!(next_step(0.1, 1e-12, 2, 2.0), 0.2);
    }

    #[test]
    fn pi_controller_is_hairers() {
        let mut pi = PiController::new(4, 0.04);
        let alpha = 0.2 - 0.75 * 0.04;
        // the first step remembers err_old = 1e-4
        let err = 0.5f64;
        let fac = (err.powf(alpha) / 1e-4f64.powf(0.04) / 0.9).clamp(0.1, 5.0);
        assert_eq!(
            pi.decide(0.01, err),
            Decision::Accept { h_next: 0.01 / fac }
        );
        // then err_old = 0.5: a smaller error grows the step less than without memory
        let err2 = 0.1f64;
        let fac2 = (err2.powf(alpha) / 0.5f64.powf(0.04) / 0.9).clamp(0.1, 5.0);
        assert_eq!(
            pi.decide(0.02, err2),
            Decision::Accept {
                h_next: 0.02 / fac2
            }
        );
        // a rejection: the elementary part only, shrinking at most 5-fold
        let Decision::Reject { h_next } = pi.decide(0.02, 3.0) else {
            panic!("an error of 3 is rejected")
        };
        assert!(close(h_next, 0.02 / (3f64.powf(alpha) / 0.9)));
        assert_eq!(
            pi.decide(0.02, 1e12),
            Decision::Reject { h_next: 0.02 / 5.0 }
        );
        // no growth right after a rejection, even for a tiny error
        assert_eq!(pi.decide(0.004, 1e-8), Decision::Accept { h_next: 0.004 });
        // growth is bounded by 10 per step
        let Decision::Accept { h_next } = pi.decide(0.004, 1e-12) else {
            panic!("a tiny error is accepted")
        };
        assert!(close(h_next, 0.04));
        pi.rejected_otherwise();
        assert_eq!(pi.decide(0.01, 1e-12), Decision::Accept { h_next: 0.01 });
    }

    #[test]
    fn predictive_controller_is_radau5s() {
        let mut c = Predictive::new(3);
        let expo = 0.25;
        // the quotient h/h_new, within [1/8, 5]
        assert!(close(c.quotient(0.5, 0.9), 0.5f64.powf(expo) / 0.9));
        assert_eq!(c.quotient(1e-30, 0.9), 0.125);
        assert_eq!(c.quotient(1e30, 0.9), 5.0);
        // first accepted step: the elementary quotient
        let q1 = c.quotient(0.5, 0.9);
        assert_eq!(c.accept(0.01, 0.5, q1), 0.01 / q1);
        // second: Gustafsson's correction, (h_acc/h)(err²/err_acc)^(1/(k+1))/0.9, when larger
        let q2 = c.quotient(0.8, 0.9);
        let gus = (0.01 / 0.02) * (0.8f64 * 0.8 / 0.5).powf(expo) / 0.9;
        assert!(gus < q2);
        assert_eq!(c.accept(0.02, 0.8, q2), 0.02 / q2);
        // an error that grew a lot since the last step: the prediction cuts harder
        let q3 = c.quotient(0.9, 0.9);
        let gus = (0.02 / 0.01) * (0.9f64 * 0.9 / 0.8).powf(expo) / 0.9;
        assert!(gus > q3);
        assert!(close(c.accept(0.01, 0.9, q3), 0.01 / gus));
        // a restart forgets the history
        c.restart();
        assert_eq!(c.accept(0.01, 0.9, q3), 0.01 / q3);
    }

    fn state(q: f64, qd: f64, qdd: f64) -> State {
        State {
            t: 0.0,
            q: vec![q],
            qd: vec![qd],
            qdd: vec![qdd],
            lambda: vec![],
        }
    }

    const WIDE: StepBounds = StepBounds {
        span: 10.0,
        h_max: f64::INFINITY,
        h_min: 0.0,
    };

    #[test]
    fn first_step_follows_hairer_norsett_wanner() {
        let tol = Tolerances {
            rtol: 1e-3,
            atol: 1e-6,
            groups: 1,
        };
        // y'' = −y from q = 1, qd = 0: y = (1, 0), f = (0, −1), weights (1.001e-3, 1e-6)
        let s = state(1.0, 0.0, -1.0);
        let d0 = (1.0 / 1.001e-3) / 2f64.sqrt();
        let d1 = (1.0 / 1e-6) / 2f64.sqrt();
        let h0 = 0.01 * d0 / d1;
        // after the Euler step (1, −h0): f changes by (−h0, 0)/h0 = (−1, 0)
        let d2 = (1.0 / 1.001e-3) / 2f64.sqrt();
        let h1 = (0.01 / d1.max(d2)).powf(1.0 / 5.0);
        let h = initial_step(&s, tol, 4, WIDE, |_, q, _, a| {
            a[0] = -q[0];
            true
        });
        assert!(close(h, (100.0 * h0).min(h1)), "{h}");
        // order 1: h1 = (0.01/d1)^(1/2) is now the smaller one
        let h = initial_step(&s, tol, 1, WIDE, |_, q, _, a| {
            a[0] = -q[0];
            true
        });
        let h1 = (0.01 / d1).sqrt();
        assert!(h1 < 100.0 * h0 && close(h, h1), "{h}");
    }

    #[test]
    fn first_step_respects_its_bounds_and_a_failed_trial() {
        let tol = Tolerances {
            rtol: 1e-6,
            atol: 1e-8,
            groups: 1,
        };
        let s = state(0.0, 0.0, 0.0);
        // a state at rest: the trial step is 1e-6, f does not change: h = max(1e-9, 1e-6)
        let h = initial_step(&s, tol, 2, WIDE, |_, _, _, a| {
            a[0] = 0.0;
            true
        });
        assert_eq!(h, 1e-6);
        let b = StepBounds {
            span: 10.0,
            h_max: f64::INFINITY,
            h_min: 1e-3,
        };
        assert_eq!(initial_step(&s, tol, 2, b, |_, _, _, _| true), 1e-3);
        // a failed trial evaluation: the trial step itself
        let s = state(1.0, 1.0, 1.0);
        let h = initial_step(&s, tol, 2, WIDE, |_, _, _, _| false);
        assert_eq!(h, 0.01);
        let b = StepBounds {
            span: 1e-4,
            h_max: f64::INFINITY,
            h_min: 0.0,
        };
        assert_eq!(initial_step(&s, tol, 2, b, |_, _, _, _| false), 1e-4);
        let b = StepBounds {
            span: 10.0,
            h_max: 1e-5,
            h_min: 0.0,
        };
        let h = initial_step(&s, tol, 2, b, |_, _, _, a| {
            a[0] = 1.0;
            true
        });
        assert_eq!(h, 1e-5);
    }
}
