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
//! --scene NAME    the scene to run (programs whose model has several)
//! --out DIR       write DIR/trajectory.csv, coordinates.svg, energy.svg, animation.html
//!                 (offline, in any browser) and motion.gltf (Blender, glTF viewers)
//! --quiet         print nothing but errors
//! ```
//!
//! Runs longer than about a second show a progress bar (on standard error); every run ends
//! with a summary table: steps, evaluations, energy error, CPU time.
//!
//! ```text
//! cargo run --release --example dpend -- --scheme radau5 --rtol 1e-10 --t-end 20 --out out
//! ```

use crate::plot::{Chart, Series, line_chart};
use crate::{
    ConstraintMethod, ConstraintOptions, Model, Options, Output, Scheme, SimError, Simulation,
    Stats, StepControl, Trajectory,
};
use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
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
    /// write DIR/trajectory.csv, coordinates.svg, energy.svg, animation.html and motion.gltf
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// constraint method of constrained models: auto, index3, projection, partitioning or
    /// baumgarte:ALPHA,BETA (1/s)
    #[arg(long, default_value = "auto", value_parser = parse_constraint_method)]
    pub constraints: ConstraintMethod,
    /// print nothing but errors
    #[arg(long)]
    pub quiet: bool,
    /// the scene to run, for programs whose model has several (each program lists its own)
    #[arg(long)]
    pub scene: Option<String>,
}

/// What a run gives: the outputs, the work, the time.
pub struct RunReport {
    pub scheme: Scheme,
    pub trajectory: Trajectory,
    pub stats: Stats,
    /// CPU time of the calling thread over the run (set-up, start, steps; not the outputs
    /// written after it), wall time where the thread's clock cannot be read
    pub cpu: Duration,
    /// whether the model's generated power of non-conservative effects is identically zero
    /// (no damper, friction or driving effect) and no effort written in Rust was evaluated:
    /// then E(t) − E(0) measures the scheme's error; otherwise it also holds the work those
    /// effects did
    pub conservative: bool,
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
    #[error("unknown scene `{given}`: this program has {known}")]
    UnknownScene { given: String, known: String },
    #[error("cannot draw or export {path}: {reason}")]
    Plot { path: PathBuf, reason: String },
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
            // poses for the animation and the glTF file
            frames: self.out.is_some(),
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
        let info = model.info();
        // a program with several scenes picks the model by --scene; any other must refuse it
        if let Some(scene) = &self.scene {
            if *scene != info.scene {
                let known: &[&str] = if info.scene.is_empty() {
                    &[]
                } else {
                    &[info.scene]
                };
                return Err(self.unknown_scene(known));
            }
        }
        let name = info.name;
        let start = Instant::now();
        let cpu0 = cpu_time::ThreadTime::try_now().ok();
        let options = self.options(default_t_end);
        let (t0, t_end) = (options.t0, options.t_end);
        let fail = |e| RunError::Simulation(Box::new(e));
        let mut sim = Simulation::new(model, scheme, options).map_err(fail)?;
        if let (Some(a), false) = (sim.assembly(), self.quiet) {
            println!("{a}");
        }
        // step by step (no artificial stops), with a progress bar once the run passes a second
        let bar = ProgressBar::hidden();
        bar.set_length(100);
        bar.set_style(
            ProgressStyle::with_template("{prefix} [{bar:40}] {percent:>3}% {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar.set_prefix(format!("{name} ({})", scheme.name()));
        let mut shown = 0;
        while crate::Integrator::state(&sim).t < t_end {
            if let Err(e) = crate::Integrator::step(&mut sim) {
                bar.abandon();
                return Err(fail(e));
            }
            let t = crate::Integrator::state(&sim).t;
            let done = (100.0 * (t - t0) / (t_end - t0)).floor() as u64;
            if done > shown {
                shown = done;
                if bar.is_hidden() && !self.quiet && start.elapsed() > Duration::from_secs(1) {
                    bar.set_draw_target(ProgressDrawTarget::stderr());
                }
                bar.set_position(done);
                bar.set_message(format!("t = {t:.3} s"));
            }
        }
        bar.finish_and_clear();
        let (trajectory, stats) = sim.finish();
        // forces written in Rust (`mbs::WithEfforts`) may do work the model cannot tell
        let conservative = stats.user_efforts == 0
            && info
                .ops
                .iter()
                .any(|(f, ops)| *f == "power" && ops.flops() == 0);
        let report = RunReport {
            scheme,
            trajectory,
            stats,
            cpu: cpu0
                .and_then(|t| t.try_elapsed().ok())
                .unwrap_or_else(|| start.elapsed()),
            conservative,
        };
        if let Some(dir) = &self.out {
            self.write_outputs(dir, info, &report)?;
        }
        if !self.quiet {
            println!("{}", report.stats);
            println!("{}", report.summary(name));
        }
        Ok(report)
    }

    /// `DIR/trajectory.csv`, `coordinates.svg` (q over time), `energy.svg`, `animation.html`
    /// and `motion.gltf`.
    fn write_outputs(
        &self,
        dir: &Path,
        info: &crate::ModelInfo,
        report: &RunReport,
    ) -> Result<(), RunError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| RunError::Io {
                path: path.clone(),
                source,
            }
        };
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let tr = &report.trajectory;
        let path = dir.join("trajectory.csv");
        let file = std::fs::File::create(&path).map_err(io(&path))?;
        tr.write_csv(std::io::BufWriter::new(file))
            .map_err(io(&path))?;
        let mut written = vec![path];
        let chart = |title: &str, y: &str| Chart {
            title: title.to_string(),
            x_label: "t (s)".into(),
            y_label: y.into(),
            log_x: false,
            log_y: false,
            ..Chart::default()
        };
        let coordinates: Vec<Series> = (0..tr.nq())
            .map(|k| Series {
                name: tr.dof_names[k].clone(),
                points: (0..tr.len()).map(|i| (tr.t[i], tr.q(i)[k])).collect(),
            })
            .collect();
        let mut plots = vec![(
            "coordinates.svg",
            chart("coordinates", "q (m or rad)"),
            coordinates,
        )];
        if tr.energy.len() == tr.len() && !tr.is_empty() {
            let e = |f: fn(&crate::Energy) -> f64, name: &str| Series {
                name: name.into(),
                points: (0..tr.len()).map(|i| (tr.t[i], f(&tr.energy[i]))).collect(),
            };
            plots.push((
                "energy.svg",
                chart("energy", "E (J)"),
                vec![
                    e(|e| e.kinetic, "kinetic"),
                    e(|e| e.potential, "potential"),
                    e(|e| e.total(), "total"),
                ],
            ));
        }
        for (file, chart, series) in plots {
            let path = dir.join(file);
            line_chart(&path, &chart, &series).map_err(|e| RunError::Plot {
                path: path.clone(),
                reason: e.to_string(),
            })?;
            written.push(path);
        }
        let export = |path: PathBuf, e: crate::anim::ExportError| RunError::Plot {
            path,
            reason: e.to_string(),
        };
        let path = dir.join("animation.html");
        crate::anim::write_html(&path, info, tr).map_err(|e| export(path.clone(), e))?;
        written.push(path);
        let path = dir.join("motion.gltf");
        crate::gltf::write_gltf(&path, info, tr).map_err(|e| export(path.clone(), e))?;
        written.push(path);
        if !self.quiet {
            for p in written {
                println!("wrote {}", p.display());
            }
        }
        Ok(())
    }

    /// The error for a `--scene` this program does not have.
    pub fn unknown_scene(&self, known: &[&str]) -> RunError {
        RunError::UnknownScene {
            given: self.scene.clone().unwrap_or_default(),
            known: if known.is_empty() {
                "no scenes".into()
            } else {
                format!("the scenes {}", known.join(", "))
            },
        }
    }
}

impl RunReport {
    /// One-line table of the run: steps, evaluations, energy error (or, for a model with
    /// dissipative or driving effects, the energy change), CPU time.
    pub fn summary(&self, name: &str) -> String {
        let t_end = self.trajectory.t.last().copied().unwrap_or(0.0);
        let energy = self
            .energy_error()
            .map_or("—".to_string(), |e| format!("{e:.2e}"));
        let note = if self.conservative || self.energy_error().is_none() {
            ""
        } else {
            "\n(ΔE includes the work of the model's dissipative or driving effects: not an error)"
        };
        format!(
            "{:<28} {:>10} {:>9} {:>9} {:>12} {:>12} {:>10}\n{:<28} {:>10} {:>9} {:>9} {:>12} {:>12} {:>10}{note}",
            "model",
            "scheme",
            "t_end",
            "steps",
            "evaluations",
            "max|ΔE|/E",
            "CPU",
            name,
            self.scheme.name(),
            format!("{t_end}"),
            self.stats.steps,
            self.stats.evaluations(),
            energy,
            format!("{:.1?}", self.cpu)
        )
    }
}
