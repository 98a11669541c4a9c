//! Many runs of one model: parameter studies, Monte-Carlo runs, scheme comparisons — on
//! every core of one machine, or as a Slurm job array.
//!
//! A [`Plan`] (TOML) says which runs to make: a grid, a Latin hypercube, Monte-Carlo draws
//! with a seed, or a list from a CSV file, over parameters of the model, initial coordinates
//! and velocities (those a run does not vary start as its model starts them, its varied
//! parameters set: a parameter may set the start), and simulation settings (scheme,
//! tolerances, step, end time). A
//! [`Sweep`] makes them in parallel (a rayon pool, one run per thread at a time, the next
//! run taken as soon as a thread is free) and writes one row per run to a CSV table as the
//! runs finish, in run order: the run's values, the [`Metrics`] the user chose (a closure
//! over the model and the trajectory), the work (steps, evaluations, Newton iterations, CPU
//! time) — or, for a run that failed, the typed failure by name and message and the time it
//! reached. Memory stays flat in the number of runs: a run's trajectory lives while its
//! metrics are computed, and rows are written as they come (held back only until the runs
//! before them are written).
//!
//! The folder of a sweep holds `plan.toml` (the plan, with the simulation settings it ran
//! with; a list design's reads its runs from the folder's `runs.csv`), `runs.csv` (the run
//! list), `results.csv` (the table) and, for Slurm,
//! `manifest.json`, `sweep.sbatch`, `parts/` and `logs/`. A sweep started again in the
//! same folder skips the runs its table already has (a row cut short by a kill is dropped
//! and run again); a folder that holds another sweep is refused.
//!
//! On a cluster (see [`slurm`]): `--slurm` writes the run list, the manifest and an sbatch
//! script of a job array whose task k runs shard k (a contiguous block of runs) into
//! `parts/part-K-of-N.csv`; [`merge`] checks that every run is present, lists the missing
//! ones and the array tasks to submit again, and writes `results.csv` in run order.
//!
//! The per-system programs do all of this from the command line ([`crate::cli`]):
//!
//! ```text
//! cargo run --release --example dpend -- --sweep plan.toml --out sweep     # every core
//! cargo run --release --example dpend -- --sweep plan.toml --out sweep --slurm
//! sbatch sweep/sweep.sbatch
//! cargo run --release --example dpend -- --sweep sweep/plan.toml --out sweep --merge
//! ```
//!
//! The table reads directly in pandas (`pd.read_csv("sweep/results.csv")`) and polars; with
//! the `parquet` feature a complete sweep or merge also writes `results.parquet`
//! (`pd.read_parquet`, `pl.read_parquet`), typed columns and nulls for empty fields.

#[cfg(feature = "parquet")]
pub mod parquet;
mod plan;
pub mod slurm;
mod table;

pub use plan::{Design, DesignKind, Plan, RunList, SimulationSpec, SlurmSpec, Value, Variable};
pub use table::{MergeReport, merge};

use crate::charts::in_identity_chart;
use crate::{ConstraintMethod, Integrator, LANES, Trajectory};
use crate::{Model, Options, Output, Parameters, Scheme, SimError, Simulation, StepControl};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Why a sweep could not be planned, run or merged.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error("sweep plan: {0}")]
    Plan(String),
    #[error(
        "sweep plan: `{name}` is neither a parameter of {model} ({params}), an initial coordinate or velocity (q0[i], qd0[i], q0.NAME, qd0.NAME with i < {nq} or NAME one of {dofs}) nor a setting (scheme, t_end, h, rtol, atol)"
    )]
    UnknownVariable {
        name: String,
        model: String,
        params: String,
        nq: usize,
        dofs: String,
    },
    #[error("sweep plan: `{name}` = {value} of run {run}: {reason}")]
    BadValue {
        name: String,
        value: String,
        run: usize,
        reason: String,
    },
    #[error("run {run} ({values}): invalid parameters: {reason}")]
    InvalidParameters {
        run: usize,
        values: String,
        reason: String,
    },
    #[error("{}: {reason}", path.display())]
    Table { path: PathBuf, reason: String },
    #[error("cannot read or write {}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "{} holds another sweep (its runs.csv differs from this plan's runs): choose another folder, or delete it to start again",
        dir.display()
    )]
    OtherSweep { dir: PathBuf },
    #[error(
        "{} holds this sweep's runs made with other settings (its plan.toml differs in [simulation]: scheme or its parameters, the start (t0, q0, qd0), t_end, h, rtol, atol or dt): run it with the settings of plan.toml to resume, or choose another folder",
        dir.display()
    )]
    OtherSettings { dir: PathBuf },
    #[error("shard `{0}`: write INDEX/COUNT with INDEX < COUNT, such as 0/3")]
    Shard(String),
    #[error(
        "{missing} of {runs} runs are missing (listed in {}); submit the array tasks {tasks} again (`sbatch --array={tasks} {}`), then merge again",
        list.display(), script.display()
    )]
    Missing {
        missing: usize,
        runs: usize,
        list: PathBuf,
        tasks: String,
        script: PathBuf,
    },
    #[error("cannot start the sweep's threads: {0}")]
    Threads(String),
}

/// The quantities each run reports, by name: a closure over the model (at the run's
/// parameters, its charts as the run left them) and the run's trajectory.
pub struct Metrics<M> {
    names: Vec<String>,
    #[allow(clippy::type_complexity)]
    f: Box<dyn Fn(&M, &Trajectory) -> Vec<f64> + Sync>,
}

impl<M: Model> Metrics<M> {
    /// `names.len()` quantities computed by `f` (a run whose `f` returns another number of
    /// values is a failed row that says so).
    pub fn new<S: Into<String>>(
        names: impl IntoIterator<Item = S>,
        f: impl Fn(&M, &Trajectory) -> Vec<f64> + Sync + 'static,
    ) -> Metrics<M> {
        Metrics {
            names: names.into_iter().map(Into::into).collect(),
            f: Box::new(f),
        }
    }

    /// The time of the last output (`t_last`: not `t_end`, the name of the setting a plan may
    /// vary, whose column it would have doubled), each coordinate and velocity there
    /// (`q_end.NAME`, `qd_end.NAME`) and the energy drift max |E(t) − E(0)| relative to max(|E(0)|, max
    /// kinetic energy) (`energy_drift`; NaN if energy was not recorded): the metrics of the
    /// per-system programs' sweeps. A rotation joint's angles and their rates are read in the
    /// identity chart, the one initial states are given in, whatever chart each run ended in
    /// ([`crate::charts::in_identity_chart`]), so that runs compare.
    pub fn final_state(model: &M) -> Metrics<M> {
        let dofs = model.info().dofs;
        let mut names = vec!["t_last".to_string()];
        names.extend(dofs.iter().map(|d| format!("q_end.{d}")));
        names.extend(dofs.iter().map(|d| format!("qd_end.{d}")));
        names.push("energy_drift".into());
        Metrics::new(names, |model: &M, tr: &Trajectory| {
            let mut v = Vec::with_capacity(2 * tr.nq() + 2);
            let last = tr.len().saturating_sub(1);
            v.push(tr.t.last().copied().unwrap_or(f64::NAN));
            if tr.is_empty() {
                v.extend(std::iter::repeat_n(f64::NAN, 2 * tr.nq()));
            } else {
                let (mut q, mut qd) = (tr.q(last).to_vec(), tr.qd(last).to_vec());
                let joints = tr.joint_names.len();
                for (j, joint) in model.info().rotation_joints.iter().enumerate().take(joints) {
                    in_identity_chart(joint, &tr.chart(last, j), &mut q, &mut qd);
                }
                v.extend_from_slice(&q);
                v.extend_from_slice(&qd);
            }
            v.push(tr.relative_energy_drift().unwrap_or(f64::NAN));
            v
        })
    }

    pub fn names(&self) -> &[String] {
        &self.names
    }
}

/// What a run's variable sets.
#[derive(Clone, Debug, PartialEq)]
enum Target {
    Param(String),
    Q0(usize),
    Qd0(usize),
    Scheme,
    TEnd,
    H,
    Rtol,
    Atol,
}

/// The simulation settings every run starts from.
#[derive(Clone, Debug)]
struct Base {
    scheme: Scheme,
    h: Option<f64>,
    rtol: f64,
    atol: Option<f64>,
    options: Options,
}

impl Base {
    /// `options` (the caller's, its step control read as h or rtol/atol) with the plan's
    /// `[simulation]` settings on top.
    fn new(scheme: Scheme, options: Options, spec: &SimulationSpec) -> Result<Base, SweepError> {
        let (mut h, mut rtol, mut atol) = match options.step {
            StepControl::Fixed { h } => (Some(h), 1e-6, None),
            StepControl::Adaptive { rtol, atol, .. } => (None, rtol, Some(atol)),
        };
        let mut base_scheme = scheme;
        if let Some(name) = &spec.scheme {
            // the caller's scheme of that name keeps its parameters
            if name != scheme.name() {
                base_scheme = scheme_named(name).map_err(SweepError::Plan)?;
            }
        }
        if let Some(wanted) = &spec.scheme_parameters {
            let have = scheme_parameters(&base_scheme);
            if have.as_deref() != Some(wanted.as_str()) {
                return Err(SweepError::Plan(format!(
                    "the plan runs {} with the parameters {wanted}, this program with {}: run the sweep with the scheme it was made with",
                    base_scheme.name(),
                    have.unwrap_or_else(|| "none".into())
                )));
            }
        }
        let mut options = options;
        if let Some(t) = spec.t0 {
            options.t0 = t;
        }
        if spec.q0.is_some() {
            options.q0.clone_from(&spec.q0);
        }
        if spec.qd0.is_some() {
            options.qd0.clone_from(&spec.qd0);
        }
        if let Some(t) = spec.t_end {
            options.t_end = t;
        }
        if spec.h.is_some() {
            h = spec.h;
        }
        if let Some(r) = spec.rtol {
            rtol = r;
            // as on the command line: atol follows rtol unless given
            atol = None;
            if spec.h.is_none() {
                h = None;
            }
        }
        if spec.atol.is_some() {
            atol = spec.atol;
        }
        if let Some(dt) = spec.dt {
            options.output = Output::Every { dt };
        }
        if let Some(n) = spec.max_steps {
            options.max_steps = n;
        }
        if let Some(c) = &spec.constraints {
            options.constraints.method =
                ConstraintMethod::from_name(c).map_err(SweepError::Plan)?;
        }
        Ok(Base {
            scheme: base_scheme,
            h,
            rtol,
            atol,
            options,
        })
    }
}

/// The parameters of a scheme that has some, as `plan.toml` records them.
fn scheme_parameters(scheme: &Scheme) -> Option<String> {
    match scheme {
        Scheme::Newmark(p) => Some(format!("{p:?}")),
        Scheme::Hht(p) => Some(format!("{p:?}")),
        Scheme::GenAlpha(p) => Some(format!("{p:?}")),
        Scheme::Bdf(p) => Some(format!("{p:?}")),
        _ => None,
    }
}

fn scheme_named(name: &str) -> Result<Scheme, String> {
    Scheme::from_name(name).ok_or_else(|| {
        format!(
            "unknown scheme `{name}`: use euler, rk4, rkc, dopri5, newmark, hht, gen-alpha, bdf, radau3, radau5 or midpoint"
        )
    })
}

/// One contiguous block of the runs: shard `index` of `count` holds runs
/// `index·n/count .. (index+1)·n/count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// `INDEX/COUNT`, such as `0/3`.
    pub fn parse(s: &str) -> Result<Shard, SweepError> {
        let bad = || SweepError::Shard(s.to_string());
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        Shard { index, count }.checked()
    }

    /// The shard if its index is below its count (the fields are public: a shard made by
    /// hand, with a 1-based array task number, is checked too).
    pub fn checked(self) -> Result<Shard, SweepError> {
        if self.index < self.count {
            Ok(self)
        } else {
            Err(SweepError::Shard(format!("{}/{}", self.index, self.count)))
        }
    }

    /// The runs of this shard among `n`.
    pub fn range(self, n: usize) -> std::ops::Range<usize> {
        // in u128: index·n wraps usize for counts near its largest value
        let at = |k: usize| (k as u128 * n as u128 / self.count.max(1) as u128) as usize;
        at(self.index)..at(self.index + 1)
    }

    /// Its table's file name in `parts/`.
    pub fn file_name(self) -> String {
        format!("part-{}-of-{}.csv", self.index, self.count)
    }
}

/// What a sweep (or one shard of it) did.
#[derive(Clone, Debug)]
pub struct Summary {
    /// the runs this call was responsible for (all, or the shard's)
    pub runs: usize,
    /// runs already in the table when it started (a resumed sweep), not run again
    pub skipped: usize,
    /// runs made now, and of those the ones that failed (a typed failure, or a panic in user
    /// code)
    pub ran: usize,
    pub failed: usize,
    /// stopped before every run was made (the stop flag); run again to resume
    pub stopped: bool,
    pub wall: Duration,
    /// CPU time of the runs made now, summed over threads
    pub cpu: Duration,
    pub threads: usize,
    /// of the runs made, those made four at a time on the lanes of the batch functions
    /// ([`Sweep::ensembles`])
    pub on_lanes: usize,
    /// the table written
    pub table: PathBuf,
}

/// A model (made by a factory, once per run), the simulation settings and the metrics; runs a
/// [`RunList`] into a folder.
pub struct Sweep<'a, M: Model> {
    make: Box<dyn Fn() -> M + Sync + 'a>,
    base: Base,
    plan: Plan,
    metrics: Metrics<M>,
    targets: Vec<Target>,
    threads: Option<usize>,
    progress: bool,
    stop: Option<&'a AtomicBool>,
    ensembles: bool,
}

/// The most runs per ensemble when a sweep's runs share the lanes of the batch functions
/// ([`Sweep::ensembles`]): taken from the list together by one thread (fewer when the
/// threads would otherwise wait: a thread's share of the runs, at least four).
const ENSEMBLE_RUNS: usize = 16;

impl<'a, M: Model + 'static> Sweep<'a, M> {
    /// The sweep of `plan` over models made by `make`, each run starting from `scheme` and
    /// `options` with the plan's `[simulation]` settings on top; the metrics are
    /// [`Metrics::final_state`] until [`Sweep::metrics`] sets others. Checks every variable's
    /// name against the model.
    pub fn new(
        make: impl Fn() -> M + Sync + 'a,
        plan: &Plan,
        scheme: Scheme,
        options: Options,
    ) -> Result<Sweep<'a, M>, SweepError> {
        let model = make();
        let base = Base::new(scheme, options, &plan.simulation)?;
        let metrics = Metrics::final_state(&model);
        let mut sweep = Sweep {
            make: Box::new(make),
            base,
            plan: plan.clone(),
            metrics,
            targets: Vec::new(),
            threads: None,
            progress: false,
            stop: None,
            ensembles: true,
        };
        if plan.sweep.design != DesignKind::List {
            let names: Vec<String> = plan.vary.iter().map(|v| v.name.clone()).collect();
            sweep.targets = targets(&model, &names)?;
            // the settings every run starts from, checked once rather than failing every row
            // (unless the runs set them: a varied setting replaces the base's)
            let settings = [
                Target::Scheme,
                Target::TEnd,
                Target::H,
                Target::Rtol,
                Target::Atol,
            ];
            if !sweep.targets.iter().any(|t| settings.contains(t)) {
                let b = &sweep.base;
                let mut start = b.options.clone();
                start.step = StepControl::from_settings(b.h, b.rtol, b.atol);
                start
                    .validate(&b.scheme, M::NQ, model.info().has_tangents)
                    .map_err(|e| {
                        SweepError::Plan(format!("the settings every run starts from: {e}"))
                    })?;
            }
        }
        Ok(sweep)
    }

    /// The quantities each run reports.
    pub fn metrics(mut self, metrics: Metrics<M>) -> Self {
        self.metrics = metrics;
        self
    }

    /// Threads (default: rayon's, the number of cores or `RAYON_NUM_THREADS`).
    pub fn threads(mut self, threads: usize) -> Self {
        self.threads = Some(threads.max(1));
        self
    }

    /// A progress bar on standard error (runs done and failed, ETA), when it is a terminal.
    pub fn progress(mut self, on: bool) -> Self {
        self.progress = on;
        self
    }

    /// When `stop` becomes true, no further run starts; the runs in progress finish and are
    /// written (Ctrl-C in the per-system programs).
    pub fn stop_flag(mut self, stop: &'a AtomicBool) -> Self {
        self.stop = Some(stop);
        self
    }

    /// Whether runs that differ only in their start and parameters (`q0…`, `qd0…` and
    /// parameters varied, no setting) of a model with `option batch;` run four at a time on
    /// the lanes of its batch functions ([`crate::simulate_ensemble_each`]: the same runs,
    /// each its own model, steps and failure, to the rounding of the batch functions, which
    /// may rarely flip an adaptive step's acceptance and so move a run's steps and final
    /// state by its tolerance) where an ensemble runs the sweep's scheme and model (DOPRI5,
    /// RK4 or explicit Euler, open loops); on by default. The `cpu_s` of such a run is its share
    /// of its ensemble's CPU time (the ensemble's divided by its runs).
    pub fn ensembles(mut self, on: bool) -> Self {
        self.ensembles = on;
        self
    }

    /// Whether this sweep's runs go through ensembles ([`Sweep::ensembles`]), with `targets`
    /// the variables of its plan.
    fn in_ensembles(&self, targets: &[Target]) -> bool {
        if !(self.ensembles && M::BATCH_GENERATED && crate::lanes::simd_available()) {
            return false;
        }
        if !targets
            .iter()
            .all(|t| matches!(t, Target::Q0(_) | Target::Qd0(_) | Target::Param(_)))
        {
            return false;
        }
        crate::ensemble_supported::<M>(&self.base.scheme).is_ok()
    }

    /// The table's columns: `run`, `status` (ok, failed), `failure` (the failure's kind),
    /// `message`, `t_reached`, the variables, the metrics, then `steps`, `rejected`,
    /// `evaluations` (M and h, forward dynamics), `newton_iterations`, `cpu_s`.
    pub fn columns(&self, runs: &RunList) -> Vec<String> {
        let mut c: Vec<String> = ["run", "status", "failure", "message", "t_reached"]
            .map(String::from)
            .into();
        c.extend(runs.names.iter().cloned());
        c.extend(self.metrics.names.iter().cloned());
        c.extend(
            [
                "steps",
                "rejected",
                "evaluations",
                "newton_iterations",
                "cpu_s",
            ]
            .map(String::from),
        );
        c
    }

    /// Writes `dir/plan.toml` (the plan with the simulation settings the runs start from) and
    /// `dir/runs.csv`, or checks that the folder holds this sweep already.
    pub fn prepare(&self, dir: &Path, runs: &RunList) -> Result<(), SweepError> {
        // a metric named like a variable or a fixed column would double it in the table
        let columns = self.columns(runs);
        for (i, c) in columns.iter().enumerate() {
            if columns[..i].contains(c) {
                return Err(SweepError::Plan(format!(
                    "the table would have two columns `{c}` (a metric named like a variable or like one of the table's own columns): rename the metric"
                )));
            }
        }
        std::fs::create_dir_all(dir).map_err(|source| SweepError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        let list = dir.join("runs.csv");
        let text = runs.to_csv();
        let resumed = match std::fs::read_to_string(&list) {
            Ok(old) if old == text => true,
            Ok(_) => {
                return Err(SweepError::OtherSweep {
                    dir: dir.to_path_buf(),
                });
            }
            Err(_) => {
                replace(&list, &text)?;
                false
            }
        };
        let plan = dir.join("plan.toml");
        let text = self.effective_plan().to_toml();
        match std::fs::read_to_string(&plan) {
            Ok(old) if old == text => {}
            // the same runs with other settings would mix two sweeps in one table
            Ok(_) if resumed => {
                return Err(SweepError::OtherSettings {
                    dir: dir.to_path_buf(),
                });
            }
            _ => replace(&plan, &text)?,
        }
        Ok(())
    }

    /// The plan with `[simulation]` filled in with the settings the runs start from, so that
    /// array tasks read everything from it.
    fn effective_plan(&self) -> Plan {
        let mut p = self.plan.clone();
        let b = &self.base;
        let s = &mut p.simulation;
        s.scheme = Some(b.scheme.name().to_string());
        s.scheme_parameters = scheme_parameters(&b.scheme);
        // the start, where the caller set one: array tasks read it from here too
        s.t0 = Some(b.options.t0);
        s.q0.clone_from(&b.options.q0);
        s.qd0.clone_from(&b.options.qd0);
        s.t_end = Some(b.options.t_end);
        s.h = b.h;
        s.rtol = Some(b.rtol);
        s.atol = b.atol;
        s.dt = match b.options.output {
            Output::Every { dt } => Some(dt),
            _ => None,
        };
        s.max_steps = Some(b.options.max_steps);
        if p.sweep.design == DesignKind::List {
            // the list as the folder holds it: its runs.csv (the file named in the plan lies
            // beside the plan, not in the folder the array tasks read)
            p.sweep.file = Some(PathBuf::from("runs.csv"));
        }
        s.constraints = Some(match b.options.constraints.method {
            ConstraintMethod::Baumgarte { alpha, beta } => format!("baumgarte:{alpha},{beta}"),
            m => m.name().to_string(),
        });
        p
    }

    /// Runs every run into `dir/results.csv` (after [`Sweep::prepare`]), skipping those the
    /// table has.
    /// With the `parquet` feature, a sweep with every run in its table also writes
    /// `dir/results.parquet` (the module `parquet`).
    pub fn run(&self, dir: &Path, runs: &RunList) -> Result<Summary, SweepError> {
        self.prepare(dir, runs)?;
        let table = dir.join("results.csv");
        let summary = self.run_range(runs, 0..runs.len(), &table)?;
        #[cfg(feature = "parquet")]
        if !summary.stopped {
            parquet::write(&table, &dir.join("results.parquet"))?;
        }
        Ok(summary)
    }

    /// Runs one shard into `dir/parts/part-K-of-N.csv` (the folder prepared by `--slurm`,
    /// [`Sweep::write_slurm`]), skipping the runs its part has.
    pub fn run_shard(
        &self,
        dir: &Path,
        runs: &RunList,
        shard: Shard,
    ) -> Result<Summary, SweepError> {
        let shard = shard.checked()?;
        self.prepare(dir, runs)?;
        let parts = dir.join("parts");
        std::fs::create_dir_all(&parts).map_err(|source| SweepError::Io {
            path: parts.clone(),
            source,
        })?;
        self.run_range(
            runs,
            shard.range(runs.len()),
            &parts.join(shard.file_name()),
        )
    }

    fn run_range(
        &self,
        runs: &RunList,
        range: std::ops::Range<usize>,
        path: &Path,
    ) -> Result<Summary, SweepError> {
        let targets = if self.plan.sweep.design == DesignKind::List {
            targets(&(self.make)(), &runs.names)?
        } else {
            self.targets.clone()
        };
        let columns = self.columns(runs);
        let mut table = table::Journal::open(path, &columns, runs.len())?;
        let pending: Vec<usize> = range.clone().filter(|&i| !table.has(i)).collect();
        let skipped = range.len() - pending.len();
        let pool = {
            let mut b = rayon::ThreadPoolBuilder::new();
            if let Some(n) = self.threads {
                // no more threads than runs to make (a thread per run at most; tens of
                // thousands asked were started, each with its stack, for four runs)
                b = b.num_threads(n.min(pending.len().max(1)));
            }
            b.build().map_err(|e| SweepError::Threads(e.to_string()))?
        };
        let threads = pool.current_num_threads();
        let bar = self.progress_bar(pending.len(), skipped);
        let start = Instant::now();
        let next = AtomicUsize::new(0);
        let ensembles = self.in_ensembles(&targets);
        let (tx, rx) = mpsc::channel::<(usize, Row)>();
        let mut failed = 0;
        let mut cpu = Duration::ZERO;
        let mut written = 0;
        let mut on_lanes = 0;
        let mut io_error = None;
        std::thread::scope(|s| {
            s.spawn(|| {
                let tx = tx; // moved in: the channel closes when every worker is done
                pool.broadcast(|_| {
                    // a run at a time, or an ensemble's runs: up to ENSEMBLE_RUNS, fewer
                    // where that would leave threads without runs (at least a lane's four)
                    let share = pending.len().div_ceil(threads);
                    let chunk = if ensembles {
                        share.clamp(LANES, ENSEMBLE_RUNS)
                    } else {
                        1
                    };
                    loop {
                        if self.stop.is_some_and(|f| f.load(Ordering::SeqCst)) {
                            break;
                        }
                        let k0 = next.fetch_add(chunk, Ordering::SeqCst);
                        if k0 >= pending.len() {
                            break;
                        }
                        let ks = k0..(k0 + chunk).min(pending.len());
                        let rows = if ensembles {
                            self.run_ensemble(&pending[ks.clone()], runs, &targets)
                        } else {
                            let i = pending[k0];
                            vec![self.run_one(i, &runs.rows[i], &runs.names, &targets)]
                        };
                        if ks.zip(rows).any(|row| tx.send(row).is_err()) {
                            break;
                        }
                    }
                });
            });
            // rows are written in run order: a row waits until those before it are written
            let mut held = std::collections::BTreeMap::new();
            for (k, row) in rx {
                held.insert(k, row);
                while let Some(row) = held.remove(&written) {
                    failed += usize::from(row.failed);
                    on_lanes += usize::from(row.on_lanes);
                    cpu += row.cpu;
                    if io_error.is_none() {
                        io_error = table.append(&row.fields).err();
                    }
                    written += 1;
                    if let Some(bar) = &bar {
                        bar.inc(1);
                        bar.set_message(format!("{failed} failed"));
                    }
                }
            }
        });
        if let Some(bar) = bar {
            bar.finish_and_clear();
        }
        if let Some(e) = io_error {
            return Err(e);
        }
        Ok(Summary {
            runs: range.len(),
            skipped,
            ran: written,
            failed,
            stopped: written < pending.len(),
            wall: start.elapsed(),
            cpu,
            threads,
            on_lanes,
            table: path.to_path_buf(),
        })
    }

    fn progress_bar(&self, todo: usize, skipped: usize) -> Option<indicatif::ProgressBar> {
        use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
        if !self.progress || todo == 0 {
            return None;
        }
        let bar = ProgressBar::with_draw_target(Some(todo as u64), ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template(
            "{prefix}[{bar:30}] {pos}/{len} runs, {msg}, {elapsed} elapsed, ETA {eta}",
        ) {
            bar.set_style(style.progress_chars("=> "));
        }
        if skipped > 0 {
            bar.set_prefix(format!("{skipped} done before; "));
        }
        bar.set_message("0 failed");
        Some(bar)
    }

    /// One run, whatever happens in it, as a row.
    fn run_one(&self, i: usize, values: &[Value], names: &[String], targets: &[Target]) -> Row {
        let clock = cpu_time::ThreadTime::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            self.simulate(i, values, names, targets)
        }))
        .unwrap_or_else(panicked);
        row_of(
            i,
            values,
            outcome,
            clock.elapsed(),
            self.metrics.names.len(),
        )
    }

    /// The runs `indices` of `runs` as one ensemble ([`Sweep::ensembles`]), whatever happens
    /// in them, as rows in their order.
    fn run_ensemble(&self, indices: &[usize], runs: &RunList, targets: &[Target]) -> Vec<Row> {
        let nm = self.metrics.names.len();
        // each run's settings, as `run_one` makes them (a panic in the model's factory is
        // that run's row); the runs whose settings stand become members
        let (mut members, mut shared, mut in_ensemble, mut rows) =
            (Vec::new(), None, Vec::new(), Vec::new());
        for &i in indices {
            let clock = cpu_time::ThreadTime::now();
            let settings = catch_unwind(AssertUnwindSafe(|| {
                let mut model = (self.make)();
                self.settings(&mut model, i, &runs.rows[i], &runs.names, targets)
                    .map(|s| (model, s))
            }));
            let refused = match settings {
                Ok(Ok((model, (scheme, options)))) => {
                    let member = crate::Member {
                        q0: options.q0.clone(),
                        qd0: options.qd0.clone(),
                        inputs: Default::default(),
                    };
                    members.push((model, member));
                    shared.get_or_insert((scheme, options));
                    in_ensemble.push(rows.len());
                    rows.push(None);
                    continue;
                }
                Ok(Err(e)) => invalid_run(e),
                Err(panic) => panicked(panic),
            };
            rows.push(Some(row_of(i, &runs.rows[i], refused, clock.elapsed(), nm)));
        }
        if let Some((scheme, options)) = shared {
            let clock = cpu_time::ThreadTime::now();
            let made = catch_unwind(AssertUnwindSafe(|| {
                crate::simulate_ensemble_each(scheme, &options, members)
            }));
            let Ok(Ok(report)) = made else {
                // the ensemble itself failed or user code panicked in it: each of its runs
                // made one at a time, so that each row says what is its own
                for j in in_ensemble {
                    let i = indices[j];
                    rows[j] = Some(self.run_one(i, &runs.rows[i], &runs.names, targets));
                }
                return rows.into_iter().flatten().collect();
            };
            // a run made on lanes: one that took a step (not one whose start was refused)
            let on_lanes: Vec<bool> = (report.runs.iter())
                .map(|r| match r {
                    Ok(_) => true,
                    Err(e) => e.stats.steps + e.stats.rejected_error + e.stats.rejected_newton > 0,
                })
                .collect();
            // each run's metrics, a panic in them that run's own
            let outcomes: Vec<Outcome> = (report.runs.into_iter())
                .zip(report.models)
                .map(|r| match r {
                    // (a run that reached its end has its model)
                    (Ok((traj, stats)), model) => catch_unwind(AssertUnwindSafe(|| {
                        let model = model.unwrap_or_else(|| (self.make)());
                        self.finished(model, traj, stats, options.t_end)
                    }))
                    .unwrap_or_else(panicked),
                    (Err(e), _) => failed_run(e, options.t0),
                })
                .collect();
            // each run its share of the ensemble's time
            let cpu = clock.elapsed() / outcomes.len().max(1) as u32;
            for ((j, o), on_lanes) in in_ensemble.into_iter().zip(outcomes).zip(on_lanes) {
                let i = indices[j];
                let mut row = row_of(i, &runs.rows[i], o, cpu, nm);
                row.on_lanes = on_lanes;
                rows[j] = Some(row);
            }
        }
        rows.into_iter().flatten().collect()
    }

    /// The outcome of a run that reached its end: its metrics, checked.
    fn finished(&self, model: M, traj: Trajectory, stats: crate::Stats, t_end: f64) -> Outcome {
        let metrics = (self.metrics.f)(&model, &traj);
        if metrics.len() != self.metrics.names.len() {
            return Outcome::Failed {
                kind: "Metrics".into(),
                message: format!(
                    "the metrics closure returned {} values for {} names",
                    metrics.len(),
                    self.metrics.names.len()
                ),
                t: t_end,
                stats: Some(stats),
            };
        }
        Outcome::Done {
            t: traj.t.last().copied().unwrap_or(t_end),
            metrics,
            stats,
        }
    }
}

/// A run's outcome as a row of the table, its CPU time `cpu`, with `nm` metrics.
fn row_of(i: usize, values: &[Value], outcome: Outcome, cpu: Duration, nm: usize) -> Row {
    {
        let mut fields = vec![i.to_string()];
        let (failed, stats) = match outcome {
            Outcome::Done { t, metrics, stats } => {
                fields.extend(["ok".into(), String::new(), String::new(), num(t)]);
                fields.extend(values.iter().map(Value::to_string));
                fields.extend(metrics.iter().map(|&x| num(x)));
                (false, Some(stats))
            }
            Outcome::Failed {
                kind,
                message,
                t,
                stats,
            } => {
                fields.extend(["failed".into(), kind, message, num(t)]);
                fields.extend(values.iter().map(Value::to_string));
                fields.extend(std::iter::repeat_n(String::new(), nm));
                (true, stats)
            }
        };
        match stats {
            Some(s) => fields.extend([
                s.steps.to_string(),
                (s.rejected_error + s.rejected_newton).to_string(),
                (s.dynamics + s.forward_dynamics).to_string(),
                s.newton_iterations.to_string(),
            ]),
            None => fields.extend(std::iter::repeat_n(String::new(), 4)),
        }
        fields.push(format!("{:.6}", cpu.as_secs_f64()));
        Row {
            fields,
            failed,
            cpu,
            on_lanes: false,
        }
    }
}

impl<'a, M: Model + 'static> Sweep<'a, M> {
    fn simulate(
        &self,
        i: usize,
        values: &[Value],
        names: &[String],
        targets: &[Target],
    ) -> Outcome {
        let mut model = (self.make)();
        let (scheme, options) = match self.settings(&mut model, i, values, names, targets) {
            Ok(s) => s,
            Err(e) => return invalid_run(e),
        };
        let t0 = options.t0;
        let t_end = options.t_end;
        let failed = |e: SimError| failed_run(e, t0);
        let mut sim = match Simulation::new(model, scheme, options) {
            Ok(sim) => sim,
            Err(e) => return failed(e),
        };
        if let Err(e) = sim.integrate_to(t_end) {
            return failed(e);
        }
        let (model, traj, stats) = sim.finish_with_model();
        self.finished(model, traj, stats, t_end)
    }

    /// The run's model parameters (set on `model`), scheme and options.
    fn settings(
        &self,
        model: &mut M,
        run: usize,
        values: &[Value],
        names: &[String],
        targets: &[Target],
    ) -> Result<(Scheme, Options), SweepError> {
        let b = &self.base;
        let (mut scheme, mut options) = (b.scheme, b.options.clone());
        let (mut h, mut rtol, mut atol) = (b.h, b.rtol, b.atol);
        let mut params = model.params().clone();
        let mut start = Vec::new();
        for (j, (target, value)) in targets.iter().zip(values).enumerate() {
            let bad = |reason: &str| SweepError::BadValue {
                name: names[j].clone(),
                value: value.to_string(),
                run,
                reason: reason.to_string(),
            };
            if let Target::Scheme = target {
                scheme = match value {
                    Value::Text(s) => scheme_named(s).map_err(|e| bad(&e))?,
                    Value::Num(_) => return Err(bad("a scheme is a name")),
                };
                continue;
            }
            let Value::Num(x) = *value else {
                return Err(bad("not a number"));
            };
            match target {
                Target::Param(name) => params.set(name, x).map_err(|e| bad(&e.to_string()))?,
                // set on the start of the run's model, once its parameters are set
                Target::Q0(k) => start.push((true, *k, x)),
                Target::Qd0(k) => start.push((false, *k, x)),
                Target::TEnd => options.t_end = x,
                Target::H => h = Some(x),
                Target::Rtol => {
                    rtol = x;
                    h = None;
                    atol = atol.filter(|_| targets.contains(&Target::Atol));
                }
                Target::Atol => atol = Some(x),
                Target::Scheme => {}
            }
        }
        model
            .set_params(params)
            .map_err(|e| SweepError::InvalidParameters {
                run,
                values: names
                    .iter()
                    .zip(values)
                    .zip(targets)
                    .filter(|(_, t)| matches!(t, Target::Param(_)))
                    .map(|((n, v), _)| format!("{n} = {v}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                reason: e.to_string(),
            })?;
        if !start.is_empty() {
            // the coordinates not varied as the run's model starts them (its parameters may
            // set its start) or as the base options give them
            let (mut q, mut qd) = (vec![0.0; M::NQ], vec![0.0; M::NQ]);
            model.initial_state(&mut q, &mut qd);
            if let Some(given) = &options.q0 {
                q.clone_from(given);
            }
            if let Some(given) = &options.qd0 {
                qd.clone_from(given);
            }
            for (position, k, x) in start {
                if position { q[k] = x } else { qd[k] = x }
            }
            options.q0 = Some(q);
            options.qd0 = Some(qd);
        }
        options.step = StepControl::from_settings(h, rtol, atol);
        Ok((scheme, options))
    }
}

/// A run whose settings were refused.
fn invalid_run(e: SweepError) -> Outcome {
    Outcome::Failed {
        kind: "InvalidRun".into(),
        message: e.to_string(),
        t: f64::NAN,
        stats: None,
    }
}

/// A run that failed: where, and the work done (t₀ when nothing was recorded).
fn failed_run(e: SimError, t0: f64) -> Outcome {
    Outcome::Failed {
        kind: failure_kind(&e),
        message: e.kind.to_string(),
        t: if e.trajectory.is_empty() { t0 } else { e.t },
        stats: Some(*e.stats),
    }
}

/// A run whose user code panicked.
fn panicked(panic: Box<dyn std::any::Any + Send>) -> Outcome {
    let what = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_default();
    Outcome::Failed {
        kind: "Panic".into(),
        message: format!("user code panicked: {what}"),
        t: f64::NAN,
        stats: None,
    }
}

/// A run's result before it becomes a row.
#[derive(Clone)]
enum Outcome {
    Done {
        t: f64,
        metrics: Vec<f64>,
        stats: crate::Stats,
    },
    Failed {
        kind: String,
        message: String,
        t: f64,
        stats: Option<crate::Stats>,
    },
}

/// A row of the table, with what the summary counts.
struct Row {
    fields: Vec<String>,
    failed: bool,
    cpu: Duration,
    /// made in an ensemble ([`Sweep::ensembles`])
    on_lanes: bool,
}

/// Writes `text` to `path` through a file beside it renamed over it: array tasks preparing the
/// same folder at once never read a half-written plan or run list.
fn replace(path: &Path, text: &str) -> Result<(), SweepError> {
    let io = |source| SweepError::Io {
        path: path.to_path_buf(),
        source,
    };
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&tmp, text).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(io)
}

/// Numbers as Rust's shortest text that reads back to the same `f64` (`NaN`, `inf`).
fn num(x: f64) -> String {
    format!("{x:?}")
}

/// The failure's variant name (`StepTooSmall`, `NonFinite`, …).
fn failure_kind(e: &SimError) -> String {
    let debug = format!("{:?}", e.kind);
    debug
        .split(|c: char| !c.is_alphanumeric())
        .next()
        .unwrap_or("")
        .to_string()
}

/// What each variable name sets, checked against the model.
fn targets<M: Model>(model: &M, names: &[String]) -> Result<Vec<Target>, SweepError> {
    let info = model.info();
    let params = <M::Params as Parameters>::NAMES;
    names
        .iter()
        .map(|name| {
            let unknown = || SweepError::UnknownVariable {
                name: name.clone(),
                model: info.name.to_string(),
                params: params.join(", "),
                nq: M::NQ,
                dofs: info.dofs.join(", "),
            };
            let coordinate = |rest: &str| -> Option<usize> {
                if let Some(i) = rest.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
                    return i.parse().ok().filter(|&i| i < M::NQ);
                }
                let dof = rest.strip_prefix('.')?;
                info.dofs.iter().position(|d| *d == dof)
            };
            Ok(match name.as_str() {
                "scheme" => Target::Scheme,
                "t_end" => Target::TEnd,
                "h" => Target::H,
                "rtol" => Target::Rtol,
                "atol" => Target::Atol,
                n if params.contains(&n) => Target::Param(n.to_string()),
                n => {
                    if let Some(rest) = n.strip_prefix("qd0") {
                        Target::Qd0(coordinate(rest).ok_or_else(unknown)?)
                    } else if let Some(rest) = n.strip_prefix("q0") {
                        Target::Q0(coordinate(rest).ok_or_else(unknown)?)
                    } else {
                        return Err(unknown());
                    }
                }
            })
        })
        .collect()
}
