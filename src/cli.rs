//! The command-line front end shared by the per-system programs in `examples/`:
//!
//! ```text
//! --scheme NAME   euler, rk4, dopri5, newmark, hht, gen-alpha, bdf, radau3, radau5, midpoint
//! --t-end T       end time (s)
//! --h H           fixed step (s); without it the scheme controls its step by --rtol/--atol
//! --rtol R --atol A
//! --dt DT         output every DT seconds (default: every step)
//! --constraints M auto, index3, projection, partitioning, baumgarte:ALPHA,BETA
//!                 (constrained models; default auto)
//! --out DIR       write DIR/trajectory.csv
//! --quiet         print nothing but errors
//! ```

use crate::{
    ConstraintMethod, ConstraintOptions, Model, Options, Output, Scheme, SimError, Simulation,
    Stats, StepControl, Trajectory,
};
use clap::Parser;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// How to run a simulation from the command line.
#[derive(Parser, Debug, Clone)]
pub struct RunArgs {
    /// integration scheme: euler, rk4, dopri5, newmark, hht, gen-alpha, bdf, radau3, radau5,
    /// midpoint
    #[arg(long, default_value = "dopri5")]
    pub scheme: String,
    /// end time (s); each program has its own default
    #[arg(long)]
    pub t_end: Option<f64>,
    /// fixed step (s); without it, the scheme controls its step with --rtol and --atol
    #[arg(long)]
    pub h: Option<f64>,
    /// relative tolerance of adaptive steps
    #[arg(long, default_value_t = 1e-6)]
    pub rtol: f64,
    /// absolute tolerance of adaptive steps (default rtol/100)
    #[arg(long)]
    pub atol: Option<f64>,
    /// output every DT seconds (default: every step)
    #[arg(long)]
    pub dt: Option<f64>,
    /// write DIR/trajectory.csv
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// constraint method of constrained models: auto, index3, projection, partitioning or
    /// baumgarte:ALPHA,BETA (1/s)
    #[arg(long, default_value = "auto", value_parser = parse_constraint_method)]
    pub constraints: ConstraintMethod,
    /// print nothing but errors
    #[arg(long)]
    pub quiet: bool,
}

/// What a run gives: the outputs, the work, the wall time.
pub struct RunReport {
    pub scheme: Scheme,
    pub trajectory: Trajectory,
    pub stats: Stats,
    pub cpu: Duration,
}

impl RunReport {
    /// max |E(t) − E(0)| relative to max(|E(0)|, max kinetic energy).
    pub fn energy_error(&self) -> Option<f64> {
        let drift = self.trajectory.energy_drift()?;
        let scale = self
            .trajectory
            .energy
            .iter()
            .map(|e| e.kinetic.abs())
            .fold(self.trajectory.energy[0].total().abs(), f64::max);
        Some(if scale > 0.0 { drift / scale } else { drift })
    }
}

/// Why a run could not be made.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(
        "unknown scheme `{0}`: use euler, rk4, dopri5, newmark, hht, gen-alpha, bdf, radau3, radau5 or midpoint"
    )]
    UnknownScheme(String),
    #[error("{0}")]
    Simulation(Box<SimError>),
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// `auto`, `index3`, `projection`, `partitioning` or `baumgarte:ALPHA,BETA`.
pub fn parse_constraint_method(s: &str) -> Result<ConstraintMethod, String> {
    let bad = || {
        format!(
            "unknown constraint method `{s}`: use auto, index3, projection, partitioning or baumgarte:ALPHA,BETA"
        )
    };
    Ok(match s {
        "auto" => ConstraintMethod::Auto,
        "index3" => ConstraintMethod::Index3,
        "projection" => ConstraintMethod::Projection,
        "partitioning" => ConstraintMethod::Partitioning,
        _ => {
            let rest = s.strip_prefix("baumgarte:").ok_or_else(bad)?;
            let (a, b) = rest.split_once(',').ok_or_else(bad)?;
            ConstraintMethod::Baumgarte {
                alpha: a.trim().parse().map_err(|_| bad())?,
                beta: b.trim().parse().map_err(|_| bad())?,
            }
        }
    })
}

impl RunArgs {
    /// The options these arguments describe, with `t_end` as the default end time.
    pub fn options(&self, t_end: f64) -> Options {
        let t_end = self.t_end.unwrap_or(t_end);
        let step = match self.h {
            Some(h) => StepControl::Fixed { h },
            None => StepControl::Adaptive {
                rtol: self.rtol,
                atol: self.atol.unwrap_or(self.rtol * 1e-2),
                h0: None,
            },
        };
        let output = match self.dt {
            Some(dt) => Output::Every { dt },
            None => Output::Steps,
        };
        Options {
            t_end,
            step,
            output,
            constraints: ConstraintOptions {
                method: self.constraints,
                ..ConstraintOptions::default()
            },
            ..Options::default()
        }
    }

    /// Runs `model` as asked, prints a summary unless `--quiet`, writes the CSV if `--out`.
    pub fn run<M: Model + 'static>(
        &self,
        model: M,
        default_t_end: f64,
    ) -> Result<RunReport, RunError> {
        let scheme = Scheme::from_name(&self.scheme)
            .ok_or_else(|| RunError::UnknownScheme(self.scheme.clone()))?;
        let name = model.info().name;
        let start = Instant::now();
        let options = self.options(default_t_end);
        let t_end = options.t_end;
        let fail = |e| RunError::Simulation(Box::new(e));
        let mut sim = Simulation::new(model, scheme, options).map_err(fail)?;
        if let (Some(a), false) = (sim.assembly(), self.quiet) {
            println!("{a}");
        }
        crate::Integrator::integrate_to(&mut sim, t_end).map_err(fail)?;
        let (trajectory, stats) = sim.finish();
        let report = RunReport {
            scheme,
            trajectory,
            stats,
            cpu: start.elapsed(),
        };
        if let Some(dir) = &self.out {
            let path = dir.join("trajectory.csv");
            let io = |source| RunError::Io {
                path: path.clone(),
                source,
            };
            std::fs::create_dir_all(dir).map_err(io)?;
            let file = std::fs::File::create(&path).map_err(io)?;
            report
                .trajectory
                .write_csv(std::io::BufWriter::new(file))
                .map_err(io)?;
            if !self.quiet {
                println!("wrote {}", path.display());
            }
        }
        if !self.quiet {
            let t_end = report.trajectory.t.last().copied().unwrap_or(0.0);
            println!(
                "{name} with {} to t = {t_end} s in {:.3?}:",
                scheme.name(),
                report.cpu
            );
            println!("{}", report.stats);
            if let Some(e) = report.energy_error() {
                println!("energy error: {e:.3e} (max |E − E₀|, relative)");
            }
        }
        Ok(report)
    }
}
