//! Parameter identification: fit the sprung arm's bar length l, mass m and shoulder stiffness
//! k1 (`models/src/sprung_arm.rs`, the three parameters it marks `sensitive`) to a measured
//! motion by least squares, three ways, with argmin:
//!
//! - Gauss–Newton (with a line search) with the exact Jacobian of the residuals, S(tᵢ) = ∂q(tᵢ)/∂p integrated with
//!   the motion (`mbs::Sensitivities`: one run gives residuals and Jacobian);
//! - L-BFGS with the exact gradient 2 Σ S(tᵢ)ᵀ rᵢ from the same runs;
//! - Nelder–Mead, derivative-free (one plain run per cost).
//!
//! The "measurement" is the motion at the true parameters sampled every 50 ms over 2 s, with
//! Gaussian noise of 1 mrad (seeded). From a start near the truth and one far from it, prints
//! iterations, simulations, time, the parameters found and the cost reached by each method, and
//! writes the convergence plot (best cost against simulations) to `identify.svg` (in `--out
//! DIR`, default the current folder).
//!
//! ```text
//! cargo run --release --example identify -- [--out DIR]
//! ```

use argmin::core::{CostFunction, Error, Executor, Gradient, Jacobian, Operator, State};
use argmin::solver::gaussnewton::GaussNewtonLS;
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::neldermead::NelderMead;
use argmin::solver::quasinewton::LBFGS;
use mbs::plot::{Chart, Series, line_chart};
use mbs::{
    DMatrix, Model, Options, Output, Parameters, Scheme, Sensitivities, StepControl, simulate,
};
use mbs_models::sprung_arm::SprungArm;
use nalgebra::DVector;
use std::cell::RefCell;
use std::time::Instant;

const DT: f64 = 0.05;
const T_END: f64 = 2.0;
const TRUE: [f64; 3] = [0.8, 1.5, 40.0];
/// A start near the truth, and one far from it
const NEAR: [f64; 3] = [0.75, 1.6, 37.0];
const FAR: [f64; 3] = [0.65, 1.9, 30.0];

fn options() -> Options {
    Options {
        t_end: T_END,
        step: StepControl::Adaptive {
            rtol: 1e-9,
            atol: 1e-11,
            h0: None,
        },
        output: Output::Every { dt: DT },
        ..Options::default()
    }
}

fn model_at(p: &[f64]) -> Result<SprungArm, Error> {
    let mut model = SprungArm::default();
    let mut params = model.params().clone();
    for (name, &v) in SprungArm::SENSITIVE.iter().zip(p) {
        params.set(name, v).map_err(|e| Error::msg(e.to_string()))?;
    }
    model
        .set_params(params)
        .map_err(|e| Error::msg(e.to_string()))?;
    Ok(model)
}

/// Gaussian noise from a seeded xorshift generator (Box–Muller).
fn noise(n: usize, sigma: f64) -> Vec<f64> {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut uniform = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let (u1, u2) = (uniform().max(1e-300), uniform());
            sigma * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        })
        .collect()
}

/// The least-squares problem: the measured q at the output times, and a log of every
/// simulation's cost for the convergence plot.
struct Fit {
    measured: Vec<f64>,
    log: RefCell<Vec<f64>>,
    /// the last run with sensitivities
    last: RefCell<Option<Residuals>>,
    /// L-BFGS and Nelder–Mead ask for the cost alone: with sensitivities (L-BFGS, whose
    /// gradient at the same point follows) or without
    exact: bool,
}

impl Fit {
    fn new(measured: &[f64], exact: bool) -> Fit {
        Fit {
            measured: measured.to_vec(),
            log: RefCell::new(Vec::new()),
            last: RefCell::new(None),
            exact,
        }
    }
}

/// What one run at p gives: the residuals q(tᵢ; p) − q_measured(tᵢ) and, from a run with
/// sensitivities, their Jacobian ∂q(tᵢ)/∂p (rows: samples × coordinates).
struct Residuals {
    p: Vec<f64>,
    r: Vec<f64>,
    jacobian: Option<DMatrix<f64>>,
}

impl Fit {
    fn residuals(&self, p: &[f64], jacobian: bool) -> Result<Residuals, Error> {
        let model = model_at(p)?;
        let n = SprungArm::NQ;
        let (r, j) = if jacobian {
            let (tr, _) = simulate(Sensitivities::new(model)?, Scheme::Dopri5, options())?;
            let rows = tr.len() * n;
            let r: Vec<f64> = (0..rows)
                .map(|row| tr.q(row / n)[row % n] - self.measured[row])
                .collect();
            let j = DMatrix::from_fn(rows, p.len(), |row, c| {
                Sensitivities::<SprungArm>::dq_dp(&tr, row / n, c)[row % n]
            });
            (r, Some(j))
        } else {
            let (tr, _) = simulate(model, Scheme::Dopri5, options())?;
            let r = (0..tr.len() * n)
                .map(|row| tr.q(row / n)[row % n] - self.measured[row])
                .collect();
            (r, None)
        };
        self.log.borrow_mut().push(r.iter().map(|x| x * x).sum());
        Ok(Residuals {
            p: p.to_vec(),
            r,
            jacobian: j,
        })
    }

    /// The residuals and Jacobian at p, from the last run with sensitivities when it was at p
    /// (the solvers ask for both at the same point).
    fn with_jacobian(&self, p: &[f64]) -> Result<(Vec<f64>, DMatrix<f64>), Error> {
        let mut last = self.last.borrow_mut();
        let fresh = match &*last {
            Some(res) if res.p == p => None,
            _ => Some(self.residuals(p, true)?),
        };
        if let Some(res) = fresh {
            *last = Some(res);
        }
        let res = last.as_ref().ok_or_else(|| Error::msg("no run"))?;
        let j = res
            .jacobian
            .clone()
            .ok_or_else(|| Error::msg("no Jacobian"))?;
        Ok((res.r.clone(), j))
    }
}

impl CostFunction for Fit {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, Error> {
        let r = if self.exact {
            self.with_jacobian(p)?.0
        } else {
            self.residuals(p, false)?.r
        };
        Ok(r.iter().map(|x| x * x).sum())
    }
}

impl Gradient for Fit {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, p: &Vec<f64>) -> Result<Vec<f64>, Error> {
        let (r, j) = self.with_jacobian(p)?;
        let g = j.transpose() * DVector::from_vec(r) * 2.0;
        Ok(g.iter().copied().collect())
    }
}

impl Operator for Fit {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
        Ok(DVector::from_vec(self.with_jacobian(p.as_slice())?.0))
    }
}

impl Jacobian for Fit {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
        Ok(self.with_jacobian(p.as_slice())?.1)
    }
}

/// One method's result: its name, iterations, the costs of its simulations, the time and the
/// parameters it ends with.
struct Outcome {
    name: &'static str,
    iterations: u64,
    log: Vec<f64>,
    seconds: f64,
    best: Vec<f64>,
}

/// The three methods from `start`.
fn fit_from(measured: &[f64], start: [f64; 3]) -> Result<Vec<Outcome>, Error> {
    let mut out = Vec::new();
    let log = |fit: Option<&Fit>| fit.map(|f| f.log.borrow().clone()).unwrap_or_default();

    // Gauss–Newton with a line search, the exact Jacobian from the sensitivities
    let clock = Instant::now();
    let solver = GaussNewtonLS::new(MoreThuenteLineSearch::new());
    let run = Executor::new(Fit::new(measured, true), solver)
        .configure(|s| s.param(DVector::from_vec(start.to_vec())).max_iters(50))
        .run()?;
    out.push(Outcome {
        name: "Gauss-Newton, exact Jacobian",
        iterations: run.state().get_iter(),
        log: log(run.problem.problem.as_ref()),
        seconds: clock.elapsed().as_secs_f64(),
        best: run
            .state()
            .get_best_param()
            .map(|p| p.iter().copied().collect())
            .unwrap_or_default(),
    });

    // L-BFGS, exact gradients from the same runs
    let clock = Instant::now();
    let solver = LBFGS::new(MoreThuenteLineSearch::new(), 5)
        .with_tolerance_grad(1e-10)?
        .with_tolerance_cost(1e-14)?;
    let run = Executor::new(Fit::new(measured, true), solver)
        .configure(|s| s.param(start.to_vec()).max_iters(100))
        .run()?;
    out.push(Outcome {
        name: "L-BFGS, exact gradients",
        iterations: run.state().get_iter(),
        log: log(run.problem.problem.as_ref()),
        seconds: clock.elapsed().as_secs_f64(),
        best: run.state().get_best_param().cloned().unwrap_or_default(),
    });

    // Nelder–Mead, no derivatives: a simplex of the start and 10 % along each parameter
    let mut simplex = vec![start.to_vec()];
    for j in 0..3 {
        let mut v = start.to_vec();
        v[j] *= 1.1;
        simplex.push(v);
    }
    let clock = Instant::now();
    let solver = NelderMead::new(simplex).with_sd_tolerance(1e-12)?;
    let run = Executor::new(Fit::new(measured, false), solver)
        .configure(|s| s.max_iters(2000))
        .run()?;
    out.push(Outcome {
        name: "Nelder-Mead, no derivatives",
        iterations: run.state().get_iter(),
        log: log(run.problem.problem.as_ref()),
        seconds: clock.elapsed().as_secs_f64(),
        best: run.state().get_best_param().cloned().unwrap_or_default(),
    });
    Ok(out)
}

fn main() -> Result<(), Error> {
    let out = std::env::args()
        .skip_while(|a| a != "--out")
        .nth(1)
        .map_or_else(|| std::path::PathBuf::from("."), std::path::PathBuf::from);
    std::fs::create_dir_all(&out)
        .map_err(|e| Error::msg(format!("cannot create {}: {e}", out.display())))?;
    let (truth, _) = simulate(model_at(&TRUE)?, Scheme::Dopri5, options())?;
    let mut measured: Vec<f64> = truth.q_data.clone();
    for (m, e) in measured.iter_mut().zip(noise(truth.q_data.len(), 1e-3)) {
        *m += e;
    }
    println!(
        "fitting {} to {} samples of q (every {DT} s over {T_END} s, noise 1 mrad); truth {TRUE:?}",
        SprungArm::SENSITIVE.join(", "),
        truth.len()
    );
    let mut series = Vec::new();
    for (label, start) in [("near", NEAR), ("far", FAR)] {
        println!(
            "
from {start:?} ({label}):"
        );
        println!(
            "{:>28} {:>6} {:>12} {:>9}  {:<30} {:>10}",
            "method", "iters", "simulations", "time", "parameters found", "cost"
        );
        for o in fit_from(&measured, start)? {
            let best_cost = o.log.iter().copied().fold(f64::INFINITY, f64::min);
            println!(
                "{:>28} {:>6} {:>12} {:>8.3}s  {:<30} {:>10.3e}",
                o.name,
                o.iterations,
                o.log.len(),
                o.seconds,
                format!("{:.5?}", o.best),
                best_cost
            );
            series.push(Series {
                name: format!("{} ({label} start)", o.name),
                points: mbs::plot::best_so_far(&o.log),
            });
        }
    }
    let path = out.join("identify.svg");
    let chart = Chart {
        title: "Identification of l, m, k1: least-squares cost".into(),
        x_label: "simulations".into(),
        y_label: "best cost so far (rad²)".into(),
        log_y: true,
        size: (900, 560),
        ..Chart::default()
    };
    line_chart(&path, &chart, &series).map_err(|e| Error::msg(e.to_string()))?;
    println!(
        "
convergence plot: {}",
        path.display()
    );
    Ok(())
}
