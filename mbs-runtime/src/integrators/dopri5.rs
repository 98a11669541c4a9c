//! Dormand–Prince 5(4) (Dormand & Prince 1980) on y = (q, qd): seven stages, first same as
//! last (six evaluations per step), error estimated by the embedded order-4 solution, step
//! chosen by Hairer's PI controller (β = 0.04, `step_control::PiController`), dense output
//! by the order-4 continuous extension of Shampine (1986), as in Hairer's DOPRI5 (its
//! coefficients computed at the first output inside a step, so that steps without one do
//! not pay for them). Stability
//! interval on the negative real axis ≈ 3.3; not for stiff problems. With a fixed step it
//! checks h·ρ against its stability region every 16 steps, as RK4 does (`explicit.rs`),
//! and stops with `UnstableStep` rather than amplify the fastest mode into garbage.
//!
//! Stiffness detection (Hairer & Wanner, Solving ODEs II, IV.2, as in Hairer's DOPRI5): stages
//! 6 and 7 are both at t + h, so h‖k₇ − k₆‖/‖y₇ − y₆‖ estimates h·|λ| of the dominant
//! eigenvalue for free. When it exceeds 3.25 (the edge of the stability region) on 15 accepted
//! steps in a row, the step is held by stability rather than accuracy: the run is recorded as
//! stiff in `Stats` (`stiff_detections`, `stiff_from`), and running out of steps afterwards is
//! reported as `Failure::LikelyStiff`. Six non-stiff steps in a row reset the count. Hairer's
//! code tests every 1000th step and then each step while it suspects stiffness; the test costs
//! no evaluation, so here it runs at every accepted step.

use super::explicit::StabilityWatch;
use super::problem::Problem;
use super::step_control::{Decision, ErrorNorm, PiController};
use super::stepper::{Control, Staged};
use super::{Attempt, State, Step, Stepper};
use crate::error::Failure;

const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// b − b̂: the error estimate's weights
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// dense output weights (Shampine)
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

pub(crate) struct Dopri5 {
    n: usize,
    /// stage derivatives (velocity part kv, acceleration part ka); stage 0 is qd0, qdd0,
    /// and stage s's velocities are kv[s] (stage 7's the new state's)
    kv: [Vec<f64>; 7],
    ka: [Vec<f64>; 7],
    /// the last stage's positions (stage 7's: the new state's)
    q: Vec<f64>,
    err: Vec<f64>,
    /// stage 6's positions (its velocities are kv[5]), for the stiffness test
    q6: Vec<f64>,
    /// accepted steps in a row with h·λ > 3.25, and without since the last such step
    stiff_run: usize,
    nonstiff_run: usize,
    /// step control: Hairer's PI controller
    pi: PiController,
    /// dense output of the last accepted step: 5 coefficient vectors for q and for qd,
    /// computed at its first interpolation (`pending`: the step's size until then), so that
    /// a run without outputs inside its steps never computes them
    cont_q: [Vec<f64>; 5],
    cont_v: [Vec<f64>; 5],
    pending: Option<f64>,
    /// the time the step of those coefficients started from
    cont_from: f64,
    /// with a fixed step: the largest |λ| against the stability region (as RK4's)
    watch: StabilityWatch,
    /// the last error test
    test: ErrorNorm,
}

/// DOPRI5's stability radius with a fixed step, the edge of |R(z)| ≤ 1 (R(z) = Σ₀⁵ zᵏ/k! +
/// z⁶/600, the propagated order-5 solution): on the negative real axis hλ = −3.3066; on the
/// imaginary axis |R(ihω)| exceeds 1 from hω = 0.997 (then by little at first: 0.16 % a
/// period at 1.2, 10 % at 2, and the amplitude doubles every period at 2.93).
fn limit(oscillating: bool) -> f64 {
    if oscillating { 0.997 } else { 3.306 }
}

impl Dopri5 {
    pub fn new(n: usize) -> Dopri5 {
        let z = || vec![0.0; n];
        let s7 = || [z(), z(), z(), z(), z(), z(), z()];
        let s5 = || [z(), z(), z(), z(), z()];
        Dopri5 {
            test: ErrorNorm::default(),
            n,
            kv: s7(),
            ka: s7(),
            q: z(),
            err: vec![0.0; 2 * n],
            q6: z(),
            stiff_run: 0,
            nonstiff_run: 0,
            pi: PiController::new(4, 0.04),
            cont_q: s5(),
            cont_v: s5(),
            pending: None,
            cont_from: f64::NAN,
            watch: StabilityWatch::new(n),
        }
    }
}

impl Stepper for Dopri5 {
    fn last_test(&self) -> ErrorNorm {
        self.test
    }

    fn attempt(&mut self, step: Step<'_>) -> Result<Attempt, Failure> {
        let Step(p, cur, h, ctl, next) = step;
        self.begin(p, cur, h, ctl)?;
        for s in 1..7 {
            let (c, _, _) = self.point(p, cur, h, s)?;
            let r = p.accel(cur.t + c * h, &self.q, &self.kv[s], &mut self.ka[s]);
            if let Err(e) = r {
                return self.stage_failed(e, ctl, h);
            }
        }
        self.complete(Step(p, cur, h, ctl, next))
    }

    fn staged(&mut self) -> Option<&mut dyn Staged> {
        Some(self)
    }

    fn interpolate(&mut self, prev: &State, cur: &State, t: f64, out: &mut State) {
        // only between the acceptance of a step and the next attempt, from that step's start
        debug_assert_eq!(prev.t.to_bits(), self.cont_from.to_bits());
        if let Some(h) = self.pending.take() {
            // the step from `prev` just accepted, whose end the stages still hold (`cur` may
            // have been moved since: a closed loop's projection)
            self.dense(&prev.q, &prev.qd, h);
        }
        let h = cur.t - prev.t;
        let th = if h == 0.0 { 1.0 } else { (t - prev.t) / h };
        let th1 = 1.0 - th;
        out.t = t;
        for i in 0..self.n {
            let [c1, c2, c3, c4, c5] = &self.cont_q;
            out.q[i] = c1[i] + th * (c2[i] + th1 * (c3[i] + th * (c4[i] + th1 * c5[i])));
            let [d1, d2, d3, d4, d5] = &self.cont_v;
            out.qd[i] = d1[i] + th * (d2[i] + th1 * (d3[i] + th * (d4[i] + th1 * d5[i])));
            // qdd: derivative of the velocity polynomial in θ, divided by h
            let dp = d2[i]
                + (1.0 - 2.0 * th) * d3[i]
                + (2.0 * th - 3.0 * th * th) * d4[i]
                + (2.0 * th - 6.0 * th * th + 4.0 * th * th * th) * d5[i];
            out.qdd[i] = if h == 0.0 { cur.qdd[i] } else { dp / h };
        }
        super::lerp_lambda(prev, cur, t, out);
    }
}

impl Staged for Dopri5 {
    fn stages(&self) -> usize {
        6
    }

    fn begin(
        &mut self,
        p: &mut Problem,
        cur: &State,
        h: f64,
        ctl: &Control,
    ) -> Result<(), Failure> {
        if ctl.adaptive.is_none() && ctl.stability_check {
            self.watch.check(p, cur, h, "DOPRI5", limit)?;
        }
        self.pending = None;
        self.kv[0].copy_from_slice(&cur.qd);
        self.ka[0].copy_from_slice(&cur.qdd);
        Ok(())
    }

    fn point(
        &mut self,
        _p: &Problem,
        cur: &State,
        h: f64,
        s: usize,
    ) -> Result<(f64, &[f64], &[f64]), Failure> {
        // y + h Σⱼ A[s][j] kⱼ, summed from 0 in the order of j for each component, in one pass
        // over the components (the stage's terms unrolled, the components in vector
        // registers); the velocities go straight into kv[s]
        let (kv, v) = self.kv.split_at_mut(s);
        let (ka, q, v) = (&self.ka, &mut self.q, &mut v[0][..]);
        match s {
            1 => combine::<1>(kv, ka, cur, h, q, v),
            2 => combine::<2>(kv, ka, cur, h, q, v),
            3 => combine::<3>(kv, ka, cur, h, q, v),
            4 => combine::<4>(kv, ka, cur, h, q, v),
            5 => combine::<5>(kv, ka, cur, h, q, v),
            _ => combine::<6>(kv, ka, cur, h, q, v),
        }
        if s == 5 {
            self.q6.copy_from_slice(&self.q);
        }
        Ok((C[s], &self.q, &self.kv[s]))
    }

    fn accel_mut(&mut self, s: usize) -> &mut [f64] {
        &mut self.ka[s]
    }

    fn stage_failed(&mut self, e: Failure, ctl: &Control, h: f64) -> Result<Attempt, Failure> {
        Attempt::after_stage_failure(e, ctl.adaptive.is_some(), h, &mut self.pi)
    }

    fn complete(&mut self, step: Step<'_>) -> Result<Attempt, Failure> {
        let Step(p, cur, h, ctl, next) = step;
        let n = self.n;
        // stage 7 is at (q1, qd1): the new state, first same as last
        next.q.copy_from_slice(&self.q);
        next.qd.copy_from_slice(&self.kv[6]);
        next.qdd.copy_from_slice(&self.ka[6]);
        let Some(tol) = ctl.adaptive else {
            if ctl.stability_check {
                self.watch.after(p, (cur, next, h), "DOPRI5", limit)?;
            }
            (self.pending, self.cont_from) = (Some(h), cur.t);
            self.watch.accepted(cur, next);
            return Ok(Attempt::Accepted { h_next: h });
        };
        // the stages as slices of n, so that the loop over the components has no bounds to
        // check and runs in vector registers
        let kv: [&[f64]; 7] = std::array::from_fn(|s| &self.kv[s][..n]);
        let ka: [&[f64]; 7] = std::array::from_fn(|s| &self.ka[s][..n]);
        let (eq, ev) = self.err[..2 * n].split_at_mut(n);
        for i in 0..n {
            let (mut sq, mut sv) = (0.0, 0.0);
            for s in 0..7 {
                sq += E[s] * kv[s][i];
                sv += E[s] * ka[s][i];
            }
            eq[i] = h * sq;
            ev[i] = h * sv;
        }
        // the state's positions and velocities as the norm's blocks, where they are
        let norm = tol.norm_of_blocks([
            (eq, &cur.q[..n], &next.q[..n]),
            (ev, &cur.qd[..n], &next.qd[..n]),
            (&[], &[], &[]),
        ]);
        self.test = norm;
        match self.pi.decide(h, norm.value) {
            Decision::Accept { h_next } => {
                (self.pending, self.cont_from) = (Some(h), cur.t);
                self.stiffness_test(p, cur.t, h);
                Ok(Attempt::Accepted { h_next })
            }
            Decision::Reject { h_next } => Ok(Attempt::RejectedError { h_next }),
        }
    }
}

/// h·|λ| beyond which a step is held by DOPRI5's stability region (its real interval ≈ 3.3)
const STIFF_H_LAMBDA: f64 = 3.25;
/// accepted steps in a row past it that make a run stiff, and that clear the suspicion
const STIFF_STEPS: usize = 15;
const NONSTIFF_STEPS: usize = 6;

impl Dopri5 {
    /// Hairer's test on the step just accepted from t: h·|λ| ≈ h‖k₇ − k₆‖/‖y₇ − y₆‖.
    fn stiffness_test(&mut self, p: &mut Problem, t: f64, h: f64) {
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..self.n {
            let dv = self.kv[6][i] - self.kv[5][i];
            let da = self.ka[6][i] - self.ka[5][i];
            let dq = self.q[i] - self.q6[i];
            num += dv * dv + da * da;
            den += dq * dq + dv * dv;
        }
        if !(den > 0.0) {
            return;
        }
        if h * (num / den).sqrt() > STIFF_H_LAMBDA {
            self.nonstiff_run = 0;
            self.stiff_run += 1;
            if self.stiff_run == STIFF_STEPS {
                p.stats.stiff_detections += 1;
                p.stats.stiff_from.get_or_insert(t + h);
            }
        } else {
            self.nonstiff_run += 1;
            if self.nonstiff_run == NONSTIFF_STEPS {
                self.stiff_run = 0;
            }
        }
    }

    /// Coefficients of the continuous extension of the step of size h just accepted from
    /// (q0, qd0), to the new state its last stage holds (q, kv[6]).
    fn dense(&mut self, q0: &[f64], qd0: &[f64], h: f64) {
        for i in 0..self.n {
            for (y0, y1, k, c) in [
                (q0[i], self.q[i], &self.kv, &mut self.cont_q),
                (qd0[i], self.kv[6][i], &self.ka, &mut self.cont_v),
            ] {
                let diff = y1 - y0;
                let bspl = h * k[0][i] - diff;
                c[0][i] = y0;
                c[1][i] = diff;
                c[2][i] = bspl;
                c[3][i] = diff - h * k[6][i] - bspl;
                c[4][i] = h * (0..7).map(|s| D[s] * k[s][i]).sum::<f64>();
            }
        }
    }
}

/// Stage `S`'s point: q = q₀ + h Σⱼ A[S][j] kvⱼ and v = qd₀ + h Σⱼ A[S][j] kaⱼ over the first
/// `S` stages, each sum from 0 in the order of j.
#[inline(always)]
fn combine<const S: usize>(
    kv: &[Vec<f64>],
    ka: &[Vec<f64>],
    cur: &State,
    h: f64,
    q: &mut [f64],
    v: &mut [f64],
) {
    let n = q.len();
    let a = &A[S];
    for (out, y, k) in [(q, &cur.q, kv), (v, &cur.qd, ka)] {
        let (y, k): (&[f64], [&[f64]; S]) = (&y[..n], std::array::from_fn(|j| &k[j][..n]));
        for (i, out) in out.iter_mut().enumerate() {
            let mut x = 0.0;
            for j in 0..S {
                x += a[j] * k[j][i];
            }
            *out = y[i] + h * x;
        }
    }
}
