//! The command-line front end shared by the per-system programs in `examples/`:
//!
//! ```text
//! --scheme NAME   euler, rk4, rkc, dopri5, newmark, hht, gen-alpha, bdf, radau3, radau5, midpoint
//! --t-end T       end time (s)
//! --h H           fixed step (s); without it the scheme controls its step by --rtol/--atol
//! --rtol R --atol A
//! --max-steps N   attempted steps before the run gives up (default 1000000)
//! --dt DT         output every DT seconds (default: every step)
//! --constraints M auto, index3, index2, projection, partitioning, baumgarte:ALPHA,BETA
//!                 (constrained models; default auto)
//! --global-error  rtol bounds the error of the trajectory, not of a step: the run is
//!                 repeated at tighter tolerances until the estimate is within it
//! --scene NAME    the scene to run (programs whose model has several)
//! --out DIR       write DIR/trajectory.csv (every output, written as the run goes),
//!                 coordinates.svg, energy.svg, animation.html (offline, in any browser),
//!                 motion.gltf (Blender, glTF viewers) and stats.json
//! --quiet         print nothing but errors
//!
//! --sweep PLAN    run the plan's many runs into --out DIR instead of one (mbs::sweep):
//!                 DIR/results.csv, a row per run; run again to resume
//!   --threads N   threads (default: every core)
//!   --slurm       write DIR/sweep.sbatch, a Slurm job array, and run nothing
//!   --shard K/N   run shard K of N into DIR/parts/ (what an array task runs)
//!   --merge       merge the parts into DIR/results.csv, or list the missing runs
//! ```
//!
//! Runs longer than about a second show a progress bar (on standard error); every run ends
//! with a summary table: steps, evaluations, energy error, CPU time.
//!
//! A run that fails (a typed [`SimError`]) or is stopped with Ctrl-C still writes what it
//! computed until then — the CSV up to the last output, the plots, the animation and the
//! work counters — says so on standard error and returns [`RunError::Stopped`], so the
//! program exits with a non-zero status. A second Ctrl-C ends the program at once.
//!
//! Memory stays flat in the number of steps: the CSV is written as the outputs come, and
//! only a thinned series is kept for the summary, the plots, the animation and the glTF file
//! (at most [`FRAMES_PER_SECOND`] outputs per simulated second and [`MAX_KEPT`] in all).
//!
//! ```text
//! cargo run --release --example dpend -- --scheme radau5 --rtol 1e-10 --t-end 20 --out out
//! ```

use crate::plot::{Chart, Series, line_chart};
use crate::{
    ConstraintMethod, ConstraintOptions, CsvWriter, Failure, FlooredTolerance, GlobalControl,
    GlobalReport, HeldBy, HeldMost, Inputs, Model, NearChangePoint, Options, Output, Scheme,
    SimError, Simulation, Stats, StepControl, Trajectory, error::short, simulate_global,
};
/// `RunArgs::parse()` needs this trait in scope: programs can name it without depending on
/// clap themselves (`use mbs::cli::Parser;`).
pub use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::Once;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// At most this many outputs per simulated second are kept in memory for the summary, the
/// plots, the animation and the glTF file (the CSV has every output).
pub const FRAMES_PER_SECOND: f64 = 60.0;
/// At most this many outputs in all are kept in memory (plus the last one).
pub const MAX_KEPT: usize = 6000;

/// How to run a simulation from the command line. Numbers may be negative (`--t-end -1`,
/// `--rtol -1e-6`): the option check then says what is wrong with them.
#[derive(Parser, Debug, Clone)]
pub struct RunArgs {
    /// integration scheme: euler, rk4, rkc, dopri5, newmark, hht, gen-alpha, bdf, radau3, radau5,
    /// midpoint
    #[arg(long, default_value = "dopri5")]
    pub scheme: String,
    /// end time (s); each program has its own default
    #[arg(long, allow_hyphen_values = true)]
    pub t_end: Option<f64>,
    /// fixed step (s); without it, the scheme controls its step with --rtol and --atol
    #[arg(long, allow_hyphen_values = true)]
    pub h: Option<f64>,
    /// relative tolerance of adaptive steps
    #[arg(long, allow_hyphen_values = true, default_value_t = 1e-6)]
    pub rtol: f64,
    /// absolute tolerance of adaptive steps (default rtol/100)
    #[arg(long, allow_hyphen_values = true)]
    pub atol: Option<f64>,
    /// attempted steps (accepted and rejected) before the run gives up
    #[arg(long, default_value_t = Options::default().max_steps)]
    pub max_steps: usize,
    /// output every DT seconds (default: every step)
    #[arg(long, allow_hyphen_values = true)]
    pub dt: Option<f64>,
    /// write DIR/trajectory.csv, coordinates.svg, energy.svg, animation.html, motion.gltf and
    /// stats.json (also, up to where it stopped, for a run that fails or is stopped by Ctrl-C)
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// constraint method of constrained models: auto, index3, index2, projection, partitioning or
    /// baumgarte:ALPHA,BETA (1/s)
    #[arg(long, default_value = "auto", value_parser = parse_constraint_method)]
    pub constraints: ConstraintMethod,
    /// make --rtol/--atol bound the error of the whole trajectory: run again at tighter local
    /// tolerances until the estimated global error is within them (`mbs::simulate_global`;
    /// adaptive steps, models without inputs)
    #[arg(long, conflicts_with = "h")]
    pub global_error: bool,
    /// print nothing but errors
    #[arg(long)]
    pub quiet: bool,
    /// the scene to run, for programs whose model has several (each program lists its own)
    #[arg(long)]
    pub scene: Option<String>,
    /// run the sweep of this plan (TOML, see `mbs::sweep`) into --out DIR instead of one run:
    /// every run on every core, a row per run in DIR/results.csv; run again to resume
    #[arg(long, value_name = "PLAN.toml")]
    pub sweep: Option<PathBuf>,
    /// with --sweep: run only shard INDEX/COUNT of the runs into DIR/parts/ (a Slurm array
    /// task)
    #[arg(long, value_name = "INDEX/COUNT", requires = "sweep")]
    pub shard: Option<String>,
    /// with --sweep: write the run list, a manifest and DIR/sweep.sbatch, a Slurm job array
    /// (the plan's `[slurm]` table), and run nothing
    #[arg(long, requires = "sweep", conflicts_with_all = ["shard", "merge"])]
    pub slurm: bool,
    /// with --sweep: merge the array tasks' parts into DIR/results.csv, or list the missing
    /// runs
    #[arg(long, requires = "sweep", conflicts_with = "shard")]
    pub merge: bool,
    /// with --sweep: threads (default: every core, or RAYON_NUM_THREADS)
    #[arg(long, requires = "sweep")]
    pub threads: Option<usize>,
}

/// The globally controlled runs of a model `--global-error` asks for.
type GlobalRunner<'a> =
    dyn Fn(Scheme, &Options) -> Result<(Trajectory, Stats, GlobalReport), SimError> + 'a;

/// What `--sweep` did.
#[derive(Debug)]
pub enum SweepReport {
    /// the runs (all, or a shard's) were made
    Ran(crate::sweep::Summary),
    /// `--slurm`: the folder is ready and this is the script to submit
    Prepared { script: PathBuf, runs: usize },
    /// `--merge`: the parts were merged
    Merged(crate::sweep::MergeReport),
}

/// What a run gives: the outputs, the work, the time.
#[derive(Debug)]
pub struct RunReport {
    pub scheme: Scheme,
    /// the outputs, thinned to at most [`FRAMES_PER_SECOND`] per simulated second and
    /// [`MAX_KEPT`] in all, always with the first and the last (every output of a run with
    /// fewer); `--out` writes every output to the CSV file
    pub trajectory: Trajectory,
    /// outputs the run produced (the CSV's rows)
    pub outputs: usize,
    /// the most outputs held in memory at once (the driver's unwritten ones and the thinned
    /// series): bounded whatever the number of steps
    pub peak_held: usize,
    pub stats: Stats,
    /// CPU time of the calling thread over the run (set-up, start, steps; not the outputs
    /// written after it), wall time where the thread's clock cannot be read
    pub cpu: Duration,
    /// whether the model's generated power of non-conservative effects is identically zero
    /// (no damper, friction or driving effect) and no effort written in Rust was evaluated:
    /// then E(t) − E(0) measures the scheme's error; otherwise it also holds the work those
    /// effects did
    pub conservative: bool,
    /// max |E(t) − E(0)| and the scale of energies over every output (not the thinned ones)
    energy: Option<(f64, f64)>,
    /// with `--global-error`: the runs made and the estimate of the returned one (`stats` is
    /// then the work of every run)
    pub global: Option<GlobalReport>,
}

impl RunReport {
    /// max |E(t) − E(0)| over every output, relative to max(|E(0)|, max kinetic energy).
    pub fn energy_error(&self) -> Option<f64> {
        let (drift, scale) = self.energy?;
        Some(if scale > 0.0 { drift / scale } else { drift })
    }
}

/// Why a run could not be made or did not reach its end.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(
        "unknown scheme `{0}`: use euler, rk4, rkc, dopri5, newmark, hht, gen-alpha, bdf, radau3, radau5 or midpoint"
    )]
    UnknownScheme(String),
    /// the run could not start (options, parameters, a consistent start); nothing was written
    #[error("{}", failure_text(.0))]
    Simulation(Box<SimError>),
    /// the run stopped before its end, by a typed failure (`failure`) or by Ctrl-C (`None`);
    /// what it computed until then is in `report` and was written with `--out`
    #[error("{}", stopped_text(.failure.as_deref(), .report))]
    Stopped {
        failure: Option<Box<SimError>>,
        report: Box<RunReport>,
    },
    #[error("unknown scene `{given}`: this program has {known}")]
    UnknownScene { given: String, known: String },
    #[error(
        "--global-error repeats the run from the same start, which a model with inputs driven by Rust code cannot: run it without --global-error"
    )]
    GlobalWithInputs,
    #[error("{0}")]
    Sweep(#[from] crate::sweep::SweepError),
    #[error("this program makes one run at a time: it does not offer --sweep")]
    SweepNotOffered,
    #[error("--sweep needs --out DIR: the folder of the sweep's plan, run list and table")]
    SweepWithoutOut,
    #[error(
        "this program's model has inputs driven by Rust code, which a sweep cannot copy to its threads; run it once at a time, or write the sweep with mbs::sweep"
    )]
    SweepWithInputs,
    #[error("cannot draw or export {path}: {reason}")]
    Plot { path: PathBuf, reason: String },
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

fn stopped_text(failure: Option<&SimError>, report: &RunReport) -> String {
    match failure {
        Some(e) => failure_text(e),
        None => format!(
            "interrupted (Ctrl-C) at t = {} s",
            short(report.trajectory.t.last().copied().unwrap_or(f64::NAN))
        ),
    }
}

/// The runtime's message of a failure, with advice in the command line's flags where the
/// runtime names its Rust API (`StepControl::Fixed`, `max_steps`, …): for programs that run
/// with [`RunArgs`]' options but report a failure of their own runs.
pub fn failure_text(e: &SimError) -> String {
    let flag = |name: &str| -> Option<&'static str> {
        Some(match name {
            "t_end" => "--t-end",
            "h" => "--h",
            "rtol" => "--rtol",
            "atol" => "--atol",
            "max_steps" => "--max-steps",
            "output.dt" => "--dt",
            "constraints.method" => "--constraints",
            _ => return None,
        })
    };
    let at = format!("(at t = {}, h = {})", short(e.t), short(e.h));
    match &e.kind {
        Failure::InvalidOption {
            name: "step",
            value,
            ..
        } => format!(
            "{value} has no error estimate to control its step: give a fixed step, e.g. --h 1e-3, or use an adaptive scheme (--scheme dopri5, radau5, bdf)"
        ),
        Failure::InvalidOption {
            name,
            value,
            reason,
        } => match flag(name) {
            Some(f) => format!("{f} {value} is invalid: {reason}"),
            None => e.to_string(),
        },
        Failure::TooMuchWork {
            max_steps,
            held_most,
            cause,
            floored,
        } => format!(
            "more than {max_steps} steps {at}: {}{}{}",
            cause.advice("--max-steps", "--rtol", "a larger --h", "--scheme "),
            FlooredTolerance::clause(floored, "--rtol"),
            HeldMost::clause(held_most)
        ),
        Failure::StepTooSmall {
            h_min,
            held_by,
            jump: Some(order),
            near_change_point,
            ..
        } if !held_by.as_ref().is_some_and(|b| b.ran_away()) => format!(
            "the step fell below {h_min:e} s {at}: {}{}",
            HeldBy::not_smooth(held_by, *order, "--atol"),
            NearChangePoint::clause(near_change_point)
        ),
        Failure::StepTooSmall {
            h_min,
            held_by,
            near_change_point,
            ..
        } => {
            let near = NearChangePoint::clause(near_change_point);
            match held_by.as_ref().and_then(|b| b.fix("--atol", "--rtol")) {
                Some(fix) => format!("the step fell below {h_min:e} s {at}: {fix}{near}"),
                None => format!(
                    "the step fell below {h_min:e} s {at}: the solution may be singular or too stiff for the scheme (try --scheme radau5 or bdf){}{near}",
                    held_by
                        .as_ref()
                        .map(|b| format!("; {}", b.held()))
                        .unwrap_or_default()
                ),
            }
        }
        Failure::NewtonDiverged {
            fixed: true,
            iterations,
            correction,
            largest,
            ..
        } => format!(
            "Newton did not converge in {iterations} iterations at the fixed step (last correction {correction:.2e}{}) {at}: take a smaller step, e.g. --h {:.1e}, or an adaptive one (no --h)",
            largest
                .as_ref()
                .map(|c| format!(", largest in {c}"))
                .unwrap_or_default(),
            shorten(0.25 * e.h)
        ),
        Failure::UnstableStep {
            scheme,
            rho,
            h_rho,
            limit,
            h_stable,
            at_end,
        } => format!(
            "{} {at}: take --h {:.1e} or smaller, or an implicit scheme (--scheme radau5)",
            crate::error::unstable_text(scheme, *rho, *h_rho, *limit, *at_end),
            shorten(*h_stable)
        ),
        Failure::ClosureFailed {
            what,
            constraint,
            residual,
            iterations,
        } => format!(
            "Newton could not close constraint `{constraint}` by moving {what} (|Φ| = {residual:.2e} after {iterations} iterations) {at}: the step left the constraints farther than Newton reaches from there; at a fixed step take a smaller one, e.g. --h {:.1e}, or adaptive steps (no --h), which retry it smaller (with adaptive steps it failed at h_min: near a singular configuration of the loop)",
            shorten(0.25 * e.h)
        ),
        Failure::ConstraintDrift {
            constraint,
            value,
            tolerance,
            closed_by_scheme,
        } => format!(
            "constraint `{constraint}` drifted to |Φ| = {value:.2e}, beyond {tolerance:.1e} {at}: {}",
            if *closed_by_scheme {
                "the scheme closes it at index 3 or 2 by Newton, to the constraint tolerance on its predicted Φ, and the new state landed beyond the drift tolerance: keep that well above the constraint tolerance, or use --constraints projection"
            } else {
                "use --constraints projection, index3 or partitioning, or larger baumgarte:ALPHA,BETA"
            }
        ),
        // an undamped member of the Newmark family asked to control its step at index 3
        // or 2: a fixed step, or a member with damping (it is among the schemes that can)
        Failure::ConstraintsUnsupported { scheme, method, .. }
            if method.ends_with("with adaptive steps") =>
        {
            format!(
                "{scheme} cannot integrate constraints by {method}: without numerical damping the multipliers and the accelerations oscillate from step to step, which defeats the error estimate; give a fixed step (--h 1e-3), use --constraints projection, or --scheme gen-alpha or hht"
            )
        }
        Failure::ConstraintsUnsupported { scheme, method, .. } => format!(
            "{scheme} cannot integrate constraints by {method}: use --constraints projection (any scheme), or --constraints index3 or index2 with --scheme gen-alpha, hht, newmark, radau3 or radau5"
        ),
        _ => e.to_string(),
    }
}

/// A step a little below `h` with two significant digits (advice users can type).
fn shorten(h: f64) -> f64 {
    if h <= 0.0 || !h.is_finite() {
        return h;
    }
    let scale = 10f64.powi(h.log10().floor() as i32 - 1);
    (h / scale).floor() * scale
}

/// The lines a sweep prints when it ends.
fn sweep_summary(s: &crate::sweep::Summary) -> String {
    let mut text = format!(
        "{} runs: {} made now ({} failed), {} done before; {:.2} s wall, {:.2} s CPU on {} threads; table {}",
        s.runs,
        s.ran,
        s.failed,
        s.skipped,
        s.wall.as_secs_f64(),
        s.cpu.as_secs_f64(),
        s.threads,
        s.table.display()
    );
    if s.on_lanes > 0 {
        text.push_str(&format!(
            "\n{} of them four at a time on the lanes of the model's batch functions",
            s.on_lanes
        ));
    }
    if s.stopped {
        text.push_str("\nstopped before every run was made: the same command resumes it");
    }
    text
}

/// `auto`, `index3`, `index2`, `projection`, `partitioning` or `baumgarte:ALPHA,BETA`
/// ([`ConstraintMethod::from_name`]).
pub fn parse_constraint_method(s: &str) -> Result<ConstraintMethod, String> {
    ConstraintMethod::from_name(s)
}

/// Runs in progress in this process, and whether Ctrl-C asked them to stop.
static RUNNING: AtomicUsize = AtomicUsize::new(0);
static INTERRUPTED: AtomicBool = AtomicBool::new(false);
static HANDLER: Once = Once::new();

/// Ctrl-C during a run asks it to stop after the step in progress; a second one, or one
/// outside a run, ends the program (status 130). A program that installed its own handler
/// keeps it (then runs are not stopped between steps).
fn watch_ctrl_c() {
    HANDLER.call_once(|| {
        let _ = ctrlc::set_handler(|| {
            if RUNNING.load(Ordering::SeqCst) == 0 || INTERRUPTED.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
        });
    });
}

/// Counts a run as in progress while it lives.
struct Running;

impl Running {
    fn start() -> Running {
        watch_ctrl_c();
        if RUNNING.fetch_add(1, Ordering::SeqCst) == 0 {
            INTERRUPTED.store(false, Ordering::SeqCst);
        }
        Running
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        RUNNING.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Where a run's outputs go as they come: every one to the CSV file (with `--out`), a thinned
/// series to memory, and the energy extremes over all of them.
struct Recorder {
    csv: Option<(PathBuf, CsvWriter<BufWriter<File>>)>,
    csv_error: Option<std::io::Error>,
    kept: Trajectory,
    t0: f64,
    keep_dt: f64,
    next_keep: f64,
    /// the last output when it was not kept (appended at the end)
    last: Trajectory,
    outputs: usize,
    peak_held: usize,
    /// E(t0), max |E − E(t0)|, max kinetic energy
    energy: Option<(f64, f64, f64)>,
    energy_everywhere: bool,
}

impl Recorder {
    fn new(csv: Option<(PathBuf, File)>, t0: f64, t_end: f64) -> Recorder {
        Recorder {
            csv: csv.map(|(path, file)| (path, CsvWriter::new(BufWriter::new(file)))),
            csv_error: None,
            kept: Trajectory::default(),
            t0,
            keep_dt: (1.0 / FRAMES_PER_SECOND).max((t_end - t0) / MAX_KEPT as f64),
            next_keep: f64::NEG_INFINITY,
            last: Trajectory::default(),
            outputs: 0,
            peak_held: 0,
            energy: None,
            energy_everywhere: true,
        }
    }

    /// Writes and sorts the outputs of `tr` (recorded since the last call).
    fn take(&mut self, tr: &Trajectory) {
        if self.outputs == 0 {
            for keep in [&mut self.kept, &mut self.last] {
                keep.dof_names.clone_from(&tr.dof_names);
                keep.frame_names.clone_from(&tr.frame_names);
                keep.constraint_names.clone_from(&tr.constraint_names);
                keep.joint_names.clone_from(&tr.joint_names);
                keep.input_names.clone_from(&tr.input_names);
            }
        }
        self.peak_held = self
            .peak_held
            .max(tr.len() + self.kept.len() + self.last.len());
        if let (Some((_, csv)), None) = (&mut self.csv, &self.csv_error) {
            if let Err(e) = csv.write(tr) {
                self.csv_error = Some(e);
            }
        }
        let with_energy = tr.energy.len() == tr.len();
        self.energy_everywhere &= with_energy;
        for i in 0..tr.len() {
            if with_energy {
                let e = tr.energy[i];
                let (e0, drift, kinetic) = self.energy.get_or_insert((e.total(), 0.0, 0.0));
                *drift = drift.max((e.total() - *e0).abs());
                *kinetic = kinetic.max(e.kinetic.abs());
            }
            let t = tr.t[i];
            self.last.clear_outputs();
            if t >= self.next_keep {
                self.kept.push_output(tr, i);
                let k = ((t - self.t0) / self.keep_dt).floor().max(0.0);
                self.next_keep = self.t0 + (k + 1.0) * self.keep_dt;
            } else {
                self.last.push_output(tr, i);
            }
        }
        self.outputs += tr.len();
    }

    /// The thinned series with the last output, and the CSV file's fate.
    fn finish(mut self) -> (Trajectory, Option<(f64, f64)>, Result<(), RunError>) {
        if !self.last.is_empty() {
            self.kept.push_output(&self.last, 0);
        }
        let energy = match (self.energy, self.energy_everywhere) {
            (Some((e0, drift, kinetic)), true) => Some((drift, kinetic.max(e0.abs()))),
            _ => None,
        };
        let csv = match self.csv {
            None => Ok(()),
            Some((path, csv)) => match self.csv_error {
                Some(source) => Err(RunError::Io { path, source }),
                None => csv
                    .finish(&self.kept)
                    .map(|_| ())
                    .map_err(|source| RunError::Io { path, source }),
            },
        };
        (self.kept, energy, csv)
    }
}

impl RunArgs {
    /// Parses the program's arguments with the program's own defaults, by field name:
    /// `RunArgs::parse_with_defaults(&[("scheme", "radau5"), ("rtol", "1e-8")])`; `--help`
    /// shows them. Exits with clap's message on bad arguments, like `RunArgs::parse()`.
    ///
    /// Panics if a name is not a field of [`RunArgs`].
    pub fn parse_with_defaults(defaults: &[(&'static str, &'static str)]) -> RunArgs {
        RunArgs::try_parse_with_defaults(std::env::args_os(), defaults).unwrap_or_else(|e| e.exit())
    }

    /// [`RunArgs::parse_with_defaults`] of the given arguments (the program's name first).
    pub fn try_parse_with_defaults<I, T>(
        args: I,
        defaults: &[(&'static str, &'static str)],
    ) -> Result<RunArgs, clap::Error>
    where
        I: IntoIterator<Item = T>,
        T: Into<std::ffi::OsString> + Clone,
    {
        use clap::{CommandFactory, FromArgMatches};
        let mut command = RunArgs::command();
        for &(name, value) in defaults {
            command = command.mut_arg(name, |a| a.default_value(value));
        }
        RunArgs::from_arg_matches(&command.try_get_matches_from(args)?)
    }

    /// The options these arguments describe, with `t_end` as the default end time.
    pub fn options(&self, t_end: f64) -> Options {
        let t_end = self.t_end.unwrap_or(t_end);
        let step = StepControl::from_settings(self.h, self.rtol, self.atol);
        let output = match self.dt {
            Some(dt) => Output::Every { dt },
            None => Output::Steps,
        };
        Options {
            t_end,
            step,
            output,
            max_steps: self.max_steps,
            // poses for the animation and the glTF file
            frames: self.out.is_some(),
            constraints: ConstraintOptions {
                method: self.constraints,
                ..ConstraintOptions::default()
            },
            ..Options::default()
        }
    }

    /// Runs `model` as asked, prints a summary unless `--quiet`, writes the outputs if
    /// `--out`. A run that fails or is stopped by Ctrl-C writes what it computed until then
    /// and returns [`RunError::Stopped`] with it.
    pub fn run<M: Model + Clone + 'static>(
        &self,
        model: M,
        default_t_end: f64,
    ) -> Result<RunReport, RunError> {
        if self.sweep.is_some() {
            return Err(RunError::SweepNotOffered);
        }
        if self.global_error {
            let copy = model.clone();
            let global = move |scheme: Scheme, options: &Options| {
                simulate_global(&copy, scheme, options, &GlobalControl::default())
            };
            return self.execute(model, default_t_end, Inputs::new(), Some(&global));
        }
        self.execute(model, default_t_end, Inputs::new(), None)
    }

    /// `--sweep PLAN.toml --out DIR`: the sweep of the plan over copies of `model`
    /// ([`crate::sweep`]), each run starting from these arguments' scheme and options with the
    /// plan's `[simulation]` on top, reporting [`Metrics::final_state`]; a summary on standard
    /// output unless `--quiet`, a progress bar on standard error. With `--shard`, one shard
    /// into `DIR/parts/`; with `--slurm`, the job array's files and nothing run; with
    /// `--merge`, the parts merged. Runs that fail are rows of the table, not errors; Ctrl-C
    /// starts no further run, and running the same command again resumes.
    ///
    /// [`Metrics::final_state`]: crate::sweep::Metrics::final_state
    pub fn sweep<M: Model + Clone + Sync + 'static>(
        &self,
        model: M,
        default_t_end: f64,
    ) -> Result<SweepReport, RunError> {
        use crate::sweep::{Plan, Shard, Sweep, merge};
        let plan_path = self.sweep.as_deref().ok_or(RunError::SweepWithoutOut)?;
        let dir = self.out.as_deref().ok_or(RunError::SweepWithoutOut)?;
        self.check_scene(model.info().scene)?;
        if self.merge {
            let m = merge(dir)?;
            if !self.quiet {
                println!(
                    "merged {} runs ({} failed) from {} parts into {}",
                    m.runs,
                    m.failed,
                    m.parts,
                    m.table.display()
                );
            }
            return Ok(SweepReport::Merged(m));
        }
        let scheme = Scheme::from_name(&self.scheme)
            .ok_or_else(|| RunError::UnknownScheme(self.scheme.clone()))?;
        let plan = Plan::load(plan_path)?;
        let runs = plan.runs(plan_path.parent().unwrap_or(Path::new(".")))?;
        let mut options = self.options(default_t_end);
        options.frames = false;
        watch_ctrl_c();
        let sweep = Sweep::new(|| model.clone(), &plan, scheme, options)?
            .progress(!self.quiet)
            .stop_flag(&INTERRUPTED);
        let sweep = match self.threads {
            Some(n) => sweep.threads(n),
            None => sweep,
        };
        if self.slurm {
            let exe = std::env::current_exe().map_err(|source| RunError::Io {
                path: PathBuf::from("the running program"),
                source,
            })?;
            let mut command = vec![exe.display().to_string()];
            if let Some(scene) = &self.scene {
                command.extend(["--scene".to_string(), scene.clone()]);
            }
            let script = sweep.write_slurm(dir, &runs, &command)?;
            if !self.quiet {
                println!(
                    "{} runs in {} array tasks: submit with `sbatch {}`, then merge with --merge",
                    runs.len(),
                    plan.slurm.tasks,
                    script.display()
                );
            }
            return Ok(SweepReport::Prepared {
                script,
                runs: runs.len(),
            });
        }
        let running = Running::start();
        let summary = match &self.shard {
            Some(s) => sweep.run_shard(dir, &runs, Shard::parse(s)?)?,
            None => sweep.run(dir, &runs)?,
        };
        drop(running);
        if !self.quiet {
            println!("{}", sweep_summary(&summary));
        }
        Ok(SweepReport::Ran(summary))
    }

    /// For a program's `main`: with `--sweep`, runs [`RunArgs::sweep`] on copies of `model` and
    /// ends the program (status 0; 130 when Ctrl-C stopped it before every run was made; 1
    /// with the error on standard error); without it, returns and the program goes on to its
    /// single run.
    pub fn sweep_if_asked<M: Model + Clone + Sync + 'static>(&self, model: &M, default_t_end: f64) {
        if self.sweep.is_none() {
            return;
        }
        let status = match self.sweep(model.clone(), default_t_end) {
            Ok(SweepReport::Ran(s)) if s.stopped => 130,
            Ok(_) => 0,
            Err(e) => {
                eprintln!("error: {e}");
                1
            }
        };
        std::process::exit(status);
    }

    /// [`RunArgs::run`] for a model with inputs u: driven by a function of time and sampled
    /// controllers ([`Inputs`]).
    pub fn run_with<M: Model + 'static>(
        &self,
        model: M,
        default_t_end: f64,
        inputs: Inputs,
    ) -> Result<RunReport, RunError> {
        if self.sweep.is_some() {
            return Err(RunError::SweepWithInputs);
        }
        if self.global_error {
            return Err(RunError::GlobalWithInputs);
        }
        self.execute(model, default_t_end, inputs, None)
    }

    /// One run, streamed step by step, or with `global` the globally controlled runs.
    fn execute<M: Model + 'static>(
        &self,
        model: M,
        default_t_end: f64,
        inputs: Inputs,
        global: Option<&GlobalRunner<'_>>,
    ) -> Result<RunReport, RunError> {
        let scheme = Scheme::from_name(&self.scheme)
            .ok_or_else(|| RunError::UnknownScheme(self.scheme.clone()))?;
        let info = model.info();
        self.check_scene(info.scene)?;
        let name = info.name;
        let running = Running::start();
        let start = Instant::now();
        let cpu0 = cpu_time::ThreadTime::try_now().ok();
        let options = self.options(default_t_end);
        let (t0, t_end) = (options.t0, options.t_end);
        // the options and the start are checked (and a loop's assembly shown) before any file
        // is written, also for the globally controlled runs, which start the same way
        let mut sim = Simulation::with_inputs(model, scheme, options.clone(), inputs)
            .map_err(|e| RunError::Simulation(Box::new(e)))?;
        if let (Some(a), false) = (sim.assembly(), self.quiet) {
            println!("{a}");
        }
        let csv = match &self.out {
            None => None,
            Some(dir) => {
                let io = |path: &Path| {
                    let path = path.to_path_buf();
                    move |source| RunError::Io { path, source }
                };
                std::fs::create_dir_all(dir).map_err(io(dir))?;
                let path = dir.join("trajectory.csv");
                let file = File::create(&path).map_err(io(&path))?;
                Some((path, file))
            }
        };
        let mut recorder = Recorder::new(csv, t0, t_end);
        let mut global_report = None;
        let (stats, failure, interrupted) = match global {
            Some(run) => {
                if !self.quiet {
                    println!(
                        "running {name} with {} to t = {t_end} s under global error control",
                        scheme.name()
                    );
                }
                drop(running);
                match run(scheme, &options) {
                    Ok((tr, _, report)) => {
                        recorder.take(&tr);
                        let work = report.work.clone();
                        if !self.quiet {
                            println!("{report}");
                        }
                        global_report = Some(report);
                        (work, None, false)
                    }
                    Err(mut e) => {
                        recorder.take(&e.trajectory);
                        e.trajectory.clear_outputs();
                        ((*e.stats).clone(), Some(Box::new(e)), false)
                    }
                }
            }
            None => {
                sim.drain_outputs(|tr| recorder.take(tr));
                if !self.quiet {
                    println!(
                        "running {name} with {} to t = {t_end} s (Ctrl-C stops it and keeps what was computed)",
                        scheme.name()
                    );
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
                let mut failure = None;
                let mut interrupted = false;
                while crate::Integrator::state(&sim).t < t_end {
                    if INTERRUPTED.load(Ordering::SeqCst) {
                        interrupted = true;
                        break;
                    }
                    if let Err(e) = crate::Integrator::step(&mut sim) {
                        failure = Some(Box::new(e));
                        break;
                    }
                    sim.drain_outputs(|tr| recorder.take(tr));
                    let t = crate::Integrator::state(&sim).t;
                    let done = (100.0 * (t - t0) / (t_end - t0)).floor() as u64;
                    if done > shown {
                        shown = done;
                        if bar.is_hidden()
                            && !self.quiet
                            && start.elapsed() > Duration::from_secs(1)
                        {
                            bar.set_draw_target(ProgressDrawTarget::stderr());
                        }
                        bar.set_position(done);
                        bar.set_message(format!("t = {t:.3} s"));
                    }
                }
                drop(running);
                if failure.is_some() || interrupted {
                    bar.abandon();
                } else {
                    bar.finish_and_clear();
                }
                let stats = match &mut failure {
                    Some(e) => {
                        // the outputs recorded in the failing call, and the work until the failure
                        recorder.take(&e.trajectory);
                        e.trajectory.clear_outputs();
                        (*e.stats).clone()
                    }
                    None => {
                        let (rest, stats) = sim.finish();
                        recorder.take(&rest);
                        stats
                    }
                };
                (stats, failure, interrupted)
            }
        };
        let (outputs, peak_held) = (recorder.outputs, recorder.peak_held);
        let (trajectory, energy, csv) = recorder.finish();
        // forces written in Rust (`mbs::WithEfforts`) may do work the model cannot tell
        // (the power's row, or the rows of its parts shared by the scenes: "power, …")
        let power = || {
            info.ops
                .iter()
                .filter(|(f, _)| f.split(',').next() == Some("power"))
        };
        let conservative = stats.user_efforts == 0
            && power().next().is_some()
            && power().all(|(_, ops)| ops.flops() == 0);
        let report = RunReport {
            scheme,
            trajectory,
            outputs,
            peak_held,
            stats,
            cpu: cpu0
                .and_then(|t| t.try_elapsed().ok())
                .unwrap_or_else(|| start.elapsed()),
            conservative,
            energy,
            global: global_report,
        };
        let stopped = failure.is_some() || interrupted;
        let status = match &failure {
            Some(e) => format!("failed: {}", failure_text(e)),
            None if interrupted => "interrupted (Ctrl-C)".to_string(),
            None => "completed".to_string(),
        };
        let written = match &self.out {
            Some(dir) => csv.and_then(|()| self.write_outputs(dir, info, &report, &status)),
            None => Ok(Vec::new()),
        };
        if stopped {
            // what was computed until the stop is written: say so, then report the stop
            let t = report.trajectory.t.last().copied().unwrap_or(t0);
            let why = if interrupted {
                "was interrupted"
            } else {
                "failed"
            };
            match &written {
                Ok(files) if !files.is_empty() => {
                    eprintln!(
                        "the run {why} at t = {} s; the {} outputs computed until then are written:",
                        short(t),
                        report.outputs
                    );
                    for p in files {
                        eprintln!("  {}", p.display());
                    }
                }
                Ok(_) => eprintln!("the run {why} at t = {t} s (--out DIR keeps its outputs)"),
                Err(e) => eprintln!("the run {why} at t = {t} s; its outputs: {e}"),
            }
            if !self.quiet {
                eprintln!("{}", report.stats);
                eprintln!("{}", report.summary(name));
            }
            return Err(RunError::Stopped {
                failure,
                report: Box::new(report),
            });
        }
        let written = written?;
        if !self.quiet {
            for p in written {
                println!("wrote {}", p.display());
            }
            println!("{}", report.stats);
            println!("{}", report.summary(name));
        }
        Ok(report)
    }

    /// `DIR/coordinates.svg` (q over time), `energy.svg`, `animation.html`, `motion.gltf` and
    /// `stats.json` (how the run ended, its outputs and work counters), from the thinned
    /// series; the CSV file, written as the run went, comes first in the list.
    fn write_outputs(
        &self,
        dir: &Path,
        info: &crate::ModelInfo,
        report: &RunReport,
        status: &str,
    ) -> Result<Vec<PathBuf>, RunError> {
        let tr = &report.trajectory;
        let mut written = vec![dir.join("trajectory.csv")];
        let path = dir.join("stats.json");
        let json = serde_json::json!({
            "status": status,
            "scheme": report.scheme.name(),
            "t": tr.t.last(),
            "outputs": report.outputs,
            "stats": report.stats,
        });
        std::fs::write(&path, format!("{json:#}\n")).map_err(|source| RunError::Io {
            path: path.clone(),
            source,
        })?;
        written.push(path);
        if tr.len() < 2 {
            // nothing to draw or play
            return Ok(written);
        }
        let chart = |title: &str, y: &str| Chart::linear(title, "t (s)", y);
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
        Ok(written)
    }

    /// A program with several scenes picks the model by `--scene`; any other must refuse
    /// it: the `--scene` asked, if any, must be the model's `scene`.
    fn check_scene(&self, scene: &str) -> Result<(), RunError> {
        match &self.scene {
            Some(asked) if asked != scene => {
                let known: &[&str] = if scene.is_empty() { &[] } else { &[scene] };
                Err(self.unknown_scene(known))
            }
            _ => Ok(()),
        }
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
            short(t_end),
            self.stats.steps,
            self.stats.evaluations(),
            energy,
            format!("{:.1?}", self.cpu)
        )
    }
}
