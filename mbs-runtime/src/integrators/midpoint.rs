//! The implicit midpoint rule on y = (q, qd): y₁ = y₀ + h f((y₀ + y₁)/2), order 2, symmetric
//! (time-reversible) and A-stable, with no numerical damping; on linear and canonical
//! Hamiltonian systems it is symplectic and keeps the energy bounded over long runs.
//! With a = the acceleration at the midpoint, q_m = q₀ + h/2 qd₀ + h²/4 a,
//! qd_m = qd₀ + h/2 a, and Newton solves τ(t + h/2, q_m, qd_m, a) = 0 with the iteration
//! matrix M + (h/2)·C_t + (h²/4)·K_t; then q₁ = q₀ + h qd₀ + h²/2 a, qd₁ = qd₀ + h a, and qdd₁
//! from M qdd = h at the new state (one more evaluation, so that outputs are consistent).

use super::at::{Affine, Weights};
use super::newton::AccelNewton;
use super::problem::Problem;
use super::{Attempt, Control, State, Step, Stepper};
use crate::charts::Recentring;
use crate::error::Failure;

pub(crate) struct Midpoint {
    n: usize,
    qhat: Vec<f64>,
    vhat: Vec<f64>,
    a: Vec<f64>,
    newton: AccelNewton,
}

impl Midpoint {
    pub fn new(n: usize) -> Midpoint {
        let z = || vec![0.0; n];
        Midpoint {
            n,
            qhat: z(),
            vhat: z(),
            a: z(),
            newton: AccelNewton::new(n),
        }
    }
}

impl Stepper for Midpoint {
    fn newton_largest(&self) -> Option<(usize, usize)> {
        self.newton.largest
    }

    fn start(&mut self, _p: &mut Problem, s: &State, _ctl: &Control) -> Result<(), Failure> {
        self.a.copy_from_slice(&s.qdd);
        Ok(())
    }

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
        for i in 0..self.n {
            self.qhat[i] = cur.q[i] + 0.5 * h * cur.qd[i];
            self.vhat[i] = cur.qd[i];
        }
        // the previous midpoint acceleration is the better guess
        let step = Affine {
            t: cur.t + 0.5 * h,
            qhat: &self.qhat,
            vhat: &self.vhat,
            w: Weights {
                beta: 0.25 * h * h,
                gamma: 0.5 * h,
            },
        };
        let r = self.newton.solve(p, step, &mut self.a, &ctl.newton);
        if let Err(f) = r {
            return Ok(f.reject(h));
        }
        for i in 0..self.n {
            next.q[i] = cur.q[i] + h * cur.qd[i] + 0.5 * h * h * self.a[i];
            next.qd[i] = cur.qd[i] + h * self.a[i];
        }
        p.accel(cur.t + h, &next.q, &next.qd, &mut next.qdd)?;
        Ok(Attempt::Accepted { h_next: h })
    }
}
