//! Controller tuning: the PD gains of an arm's joint (with gravity compensation) that bring it
//! from hanging to 1 rad, chosen by an optimiser (argmin) for a quick, well-damped settling at
//! a moderate effort:
//!
//! J(kp, kd) = ∫₀³ t·(q − q*)² dt + w ∫₀³ τ² dt,   τ = −kp (q − q*) − kd q̇ (the feedback
//! torque),   w = 1e-4
//!
//! (the weight t penalises error that lingers, as the ITSE criterion does; the effort term
//! keeps the gains finite). Two ways: L-BFGS with the exact gradient, from the gains marked
//! `sensitive` and `mbs::Sensitivities` (dJ/dp from ∂q/∂p and ∂q̇/∂p along the motion), and
//! Nelder–Mead without derivatives. Prints iterations, simulations, time, the gains and the
//! settling time (last exit from ±2 % of the step) before and after, and writes
//! `tune.svg` (the responses) and `tune_convergence.svg` (the best J against simulations) in
//! `--out DIR` (default the current folder).
//!
//! ```text
//! cargo run --release --example tune -- [--out DIR]
//! ```

use argmin::core::{CostFunction, Error, Executor, Gradient, State};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::neldermead::NelderMead;
use argmin::solver::quasinewton::LBFGS;
use mbs::plot::{Chart, Series, line_chart};
use mbs::{
    Model, Options, Output, Parameters, Scheme, Sensitivities, StepControl, Trajectory, simulate,
};
use std::cell::{Cell, RefCell};
use std::time::Instant;

mbs::multibody! {
    /// A 1 m, 2 kg arm hanging from a hinge, a PD torque driving it to `target` on top of a
    /// torque that compensates gravity (m g l/2 sin a).
    pub model PdArm {
        param kp = 20.0 sensitive; param kd = 2.0 sensitive; param target = 1.0;
        option tangents;
        dof a = 0.0;
        body arm { mass = 2.0; inertia = (0.17, 0.01, 0.17); }
        TOG[arm] = Trotz(a) * Tdisp(0, -0.5, 0);
        gravity(0, -9.81, 0);
        torque(arm, axis = z, -kp * (a - target) - kd * qd[0] + 2.0 * 9.81 * 0.5 * sin(a));
    }
}

const T_END: f64 = 3.0;
const DT: f64 = 0.01;
const W: f64 = 1e-4;
const START: [f64; 2] = [20.0, 2.0];

fn options() -> Options {
    Options {
        t_end: T_END,
        step: StepControl::Adaptive {
            rtol: 1e-8,
            atol: 1e-10,
            h0: None,
        },
        output: Output::Every { dt: DT },
        ..Options::default()
    }
}

fn arm(gains: &[f64]) -> Result<PdArm, Error> {
    let mut model = PdArm::default();
    let mut p = model.params().clone();
    p.set("kp", gains[0])
        .map_err(|e| Error::msg(e.to_string()))?;
    p.set("kd", gains[1])
        .map_err(|e| Error::msg(e.to_string()))?;
    model.set_params(p).map_err(|e| Error::msg(e.to_string()))?;
    Ok(model)
}

/// J and, from a trajectory of the model with sensitivities, dJ/d(kp, kd), by the trapezoidal
/// rule over the outputs.
fn criterion(tr: &Trajectory, gains: &[f64], sensitivities: bool) -> (f64, [f64; 2]) {
    let target = PdArm::default().params().target;
    let (mut j, mut g) = (0.0, [0.0; 2]);
    for i in 0..tr.len() {
        let w = if i == 0 || i + 1 == tr.len() {
            0.5 * DT
        } else {
            DT
        };
        let (t, q, v) = (tr.t[i], tr.q(i)[0], tr.qd(i)[0]);
        let e = q - target;
        let tau = -gains[0] * e - gains[1] * v;
        j += w * (t * e * e + W * tau * tau);
        if sensitivities {
            for (p, gp) in g.iter_mut().enumerate() {
                let (sq, sv) = (tr.q(i)[1 + p], tr.qd(i)[1 + p]);
                // dτ/dp: the explicit dependence on the gain, and through q and q̇
                let explicit = if p == 0 { -e } else { -v };
                let dtau = explicit - gains[0] * sq - gains[1] * sv;
                *gp += w * (2.0 * t * e * sq + 2.0 * W * tau * dtau);
            }
        }
    }
    (j, g)
}

/// Settling time: the last time |q − q*| exceeds 2 % of the step.
fn settling(tr: &Trajectory) -> f64 {
    let target = PdArm::default().params().target;
    (0..tr.len())
        .rev()
        .find(|&i| (tr.q(i)[0] - target).abs() > 0.02 * target)
        .map_or(0.0, |i| tr.t[(i + 1).min(tr.len() - 1)])
}

struct Tuning {
    runs: Cell<usize>,
    /// J of every simulation, for the convergence plot
    log: RefCell<Vec<f64>>,
}

impl CostFunction for Tuning {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, Error> {
        self.runs.set(self.runs.get() + 1);
        let (tr, _) = simulate(arm(p)?, Scheme::Dopri5, options())?;
        let j = criterion(&tr, p, false).0;
        self.log.borrow_mut().push(j);
        Ok(j)
    }
}

impl Gradient for Tuning {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, p: &Vec<f64>) -> Result<Vec<f64>, Error> {
        self.runs.set(self.runs.get() + 1);
        let (tr, _) = simulate(Sensitivities::new(arm(p)?)?, Scheme::Dopri5, options())?;
        let (j, gradient) = criterion(&tr, p, true);
        self.log.borrow_mut().push(j);
        Ok(gradient.to_vec())
    }
}

fn main() -> Result<(), Error> {
    let out = std::env::args()
        .skip_while(|a| a != "--out")
        .nth(1)
        .map_or_else(|| std::path::PathBuf::from("."), std::path::PathBuf::from);
    std::fs::create_dir_all(&out)
        .map_err(|e| Error::msg(format!("cannot create {}: {e}", out.display())))?;

    // the exact gradient against central differences, once
    let (tr, _) = simulate(Sensitivities::new(arm(&START)?)?, Scheme::Dopri5, options())?;
    let exact = criterion(&tr, &START, true).1;
    let j_at = |g: [f64; 2]| -> Result<f64, Error> {
        let (tr, _) = simulate(arm(&g)?, Scheme::Dopri5, options())?;
        Ok(criterion(&tr, &g, false).0)
    };
    for p in 0..2 {
        let e = 1e-5 * START[p];
        let (mut up, mut down) = (START, START);
        up[p] += e;
        down[p] -= e;
        let diff = (j_at(up)? - j_at(down)?) / (2.0 * e);
        println!(
            "dJ/d{}: {:.8e} exact, {diff:.8e} by central differences",
            ["kp", "kd"][p],
            exact[p]
        );
    }

    let (before, _) = simulate(arm(&START)?, Scheme::Dopri5, options())?;
    println!(
        "\nstart: kp = {}, kd = {}: J = {:.5e}, settles (±2 %) at {:.2} s",
        START[0],
        START[1],
        criterion(&before, &START, false).0,
        settling(&before)
    );
    println!(
        "\n{:>26} {:>6} {:>12} {:>9} {:>9} {:>9} {:>12} {:>9}",
        "method", "iters", "simulations", "time", "kp", "kd", "J", "settles"
    );
    let mut series = vec![Series {
        name: format!("start: kp = {}, kd = {}", START[0], START[1]),
        points: (0..before.len())
            .map(|i| (before.t[i], before.q(i)[0]))
            .collect(),
    }];
    let mut convergence = Vec::new();
    let solvers: [(&str, bool); 2] = [
        ("L-BFGS, exact gradients", true),
        ("Nelder-Mead, no derivatives", false),
    ];
    for (name, gradient) in solvers {
        let problem = Tuning {
            runs: Cell::new(0),
            log: RefCell::new(Vec::new()),
        };
        let clock = Instant::now();
        let (best, iterations, runs, log) = if gradient {
            let solver = LBFGS::new(MoreThuenteLineSearch::new(), 5)
                .with_tolerance_grad(1e-9)?
                .with_tolerance_cost(1e-12)?;
            let run = Executor::new(problem, solver)
                .configure(|s| s.param(START.to_vec()).max_iters(100))
                .run()?;
            let runs = run.problem.problem.as_ref().map_or(0, |p| p.runs.get());
            let log = run.problem.problem.as_ref().map(|p| p.log.take());
            let best = run.state().get_best_param().cloned().unwrap_or_default();
            (best, run.state().get_iter(), runs, log.unwrap_or_default())
        } else {
            let simplex = vec![START.to_vec(), vec![24.0, 2.0], vec![20.0, 2.4]];
            let solver = NelderMead::new(simplex).with_sd_tolerance(1e-10)?;
            let run = Executor::new(problem, solver)
                .configure(|s| s.max_iters(1000))
                .run()?;
            let runs = run.problem.problem.as_ref().map_or(0, |p| p.runs.get());
            let log = run.problem.problem.as_ref().map(|p| p.log.take());
            let best = run.state().get_best_param().cloned().unwrap_or_default();
            (best, run.state().get_iter(), runs, log.unwrap_or_default())
        };
        let seconds = clock.elapsed().as_secs_f64();
        let (after, _) = simulate(arm(&best)?, Scheme::Dopri5, options())?;
        println!(
            "{:>26} {:>6} {:>12} {:>8.3}s {:>9.3} {:>9.3} {:>12.5e} {:>8.2}s",
            name,
            iterations,
            runs,
            seconds,
            best[0],
            best[1],
            criterion(&after, &best, false).0,
            settling(&after)
        );
        convergence.push(Series {
            name: name.to_string(),
            points: mbs::plot::best_so_far(&log),
        });
        series.push(Series {
            name: format!("{name}: kp = {:.1}, kd = {:.2}", best[0], best[1]),
            points: (0..after.len())
                .map(|i| (after.t[i], after.q(i)[0]))
                .collect(),
        });
    }
    let path = out.join("tune.svg");
    let chart = Chart {
        legend: mbs::plot::Legend::LowerRight,
        ..Chart::linear(
            "PD gains tuned for ∫ t e² dt + w ∫ τ² dt",
            "t (s)",
            "arm angle (rad)",
        )
    };
    line_chart(&path, &chart, &series).map_err(|e| Error::msg(e.to_string()))?;
    println!("\nresponses: {}", path.display());
    let path = out.join("tune_convergence.svg");
    let chart = Chart::linear("PD gains: best J so far", "simulations", "J");
    line_chart(&path, &chart, &convergence).map_err(|e| Error::msg(e.to_string()))?;
    println!("convergence plot: {}", path.display());
    Ok(())
}
