//! A sweep as a Slurm job array: the manifest and the sbatch script.
//!
//! `--slurm` (or [`Sweep::write_slurm`]) prepares the sweep's folder: `plan.toml`,
//! `runs.csv`, `manifest.json` (the model, the number of runs and of array tasks, the table's
//! columns, the command) and `sweep.sbatch`, a job array of `[slurm] tasks` tasks. Task k
//! runs shard k/N (N from the plan, not `SLURM_ARRAY_TASK_COUNT`, so that a resubmission of
//! some tasks only runs the same shards), on `cpus_per_task` threads, into
//! `parts/part-k-of-N.csv`, its log in `logs/`. A task started again skips the runs its part
//! has. After the array, [`merge`](super::merge) writes `results.csv`.
//!
//! On a real cluster, edit the `[slurm]` table of the plan: `partition`, `time` (per task:
//! the runs of one shard divided by its threads, with a margin), `mem_per_cpu`,
//! `cpus_per_task`, and `extra = ["--account=…"]` for what your site requires. The folder
//! must be on a file system the compute nodes share, and the program built for their
//! processors (a `--release` build on the login node usually is).

use super::{Plan, RunList, Sweep, SweepError};
use crate::Model;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The script's file name in the sweep's folder.
pub const SCRIPT: &str = "sweep.sbatch";
/// The manifest's file name.
pub const MANIFEST: &str = "manifest.json";

/// What the array tasks and the merge agree on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// the model (`ModelInfo::name`)
    pub model: String,
    pub runs: usize,
    /// array tasks, one shard each
    pub tasks: usize,
    /// the table's header
    pub columns: Vec<String>,
    /// the program and its arguments before the sweep's own
    pub command: Vec<String>,
    pub mbs_version: String,
}

impl Manifest {
    pub fn read(dir: &Path) -> Result<Manifest, SweepError> {
        let path = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&path).map_err(|source| SweepError::Io {
            path: path.clone(),
            source,
        })?;
        serde_json::from_str(&text).map_err(|e| SweepError::Table {
            path,
            reason: e.to_string(),
        })
    }
}

/// A word of a shell command, quoted.
fn quote(s: &str) -> String {
    if !s.is_empty()
        && s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"/._-=:,+@".contains(&b))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// The sbatch script of `plan` for the folder `dir` (absolute) and the program `command`.
pub fn script(plan: &Plan, dir: &Path, runs: usize, command: &[String]) -> String {
    let s = &plan.slurm;
    let d = dir.display().to_string();
    let mut t = String::from("#!/bin/bash\n");
    t.push_str("#SBATCH --job-name=mbs-sweep\n");
    t.push_str(&format!(
        "#SBATCH --array=0-{}\n",
        s.tasks.saturating_sub(1)
    ));
    t.push_str("#SBATCH --ntasks=1\n");
    t.push_str(&format!("#SBATCH --cpus-per-task={}\n", s.cpus_per_task));
    t.push_str(&format!("#SBATCH --time={}\n", s.time));
    t.push_str(&format!("#SBATCH --mem-per-cpu={}\n", s.mem_per_cpu));
    if let Some(p) = &s.partition {
        t.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    t.push_str(&format!("#SBATCH --output={d}/logs/task-%a.log\n"));
    for e in &s.extra {
        t.push_str(&format!("#SBATCH {e}\n"));
    }
    t.push_str(&format!(
        "#\n# {runs} runs in {} shards; task k writes parts/part-k-of-{}.csv in\n# {d}\n\
         # Afterwards merge the parts into results.csv:\n#   {} --sweep {} --out {} --merge\n\
         set -euo pipefail\n",
        s.tasks,
        s.tasks,
        command
            .iter()
            .map(|w| quote(w))
            .collect::<Vec<_>>()
            .join(" "),
        quote(&format!("{d}/plan.toml")),
        quote(&d),
    ));
    let mut words: Vec<String> = command.iter().map(|w| quote(w)).collect();
    words.extend([
        "--sweep".into(),
        quote(&format!("{d}/plan.toml")),
        "--out".into(),
        quote(&d),
        "--shard".into(),
        format!("\"$SLURM_ARRAY_TASK_ID/{}\"", s.tasks),
        "--threads".into(),
        format!("\"${{SLURM_CPUS_PER_TASK:-{}}}\"", s.cpus_per_task),
        "--quiet".into(),
    ]);
    t.push_str(&format!("exec {}\n", words.join(" ")));
    t
}

impl<M: Model + 'static> Sweep<'_, M> {
    /// Prepares `dir` for a job array: `plan.toml`, `runs.csv`, `manifest.json`,
    /// `sweep.sbatch` (for `command`, the program and its own arguments, which must accept
    /// the per-system programs' `--sweep`, `--out`, `--shard`, `--threads` and `--quiet`),
    /// `parts/` and `logs/`; returns the script's path.
    pub fn write_slurm(
        &self,
        dir: &Path,
        runs: &RunList,
        command: &[String],
    ) -> Result<PathBuf, SweepError> {
        if self.plan.slurm.tasks == 0 || self.plan.slurm.cpus_per_task == 0 {
            return Err(SweepError::Plan(
                "[slurm] tasks and cpus_per_task must be at least 1".into(),
            ));
        }
        if self.plan.slurm.tasks > runs.len().max(1) {
            return Err(SweepError::Plan(format!(
                "[slurm] tasks = {} is more than the sweep's {} runs: a task would have none; take at most {}",
                self.plan.slurm.tasks,
                runs.len(),
                runs.len().max(1)
            )));
        }
        self.prepare(dir, runs)?;
        let io = |path: PathBuf| move |source| SweepError::Io { path, source };
        let dir = std::path::absolute(dir).map_err(io(dir.to_path_buf()))?;
        for sub in ["parts", "logs"] {
            std::fs::create_dir_all(dir.join(sub)).map_err(io(dir.join(sub)))?;
        }
        let manifest = Manifest {
            model: (self.make)().info().name.to_string(),
            runs: runs.len(),
            tasks: self.plan.slurm.tasks,
            columns: self.columns(runs),
            command: command.to_vec(),
            mbs_version: env!("CARGO_PKG_VERSION").to_string(),
        };
        let path = dir.join(MANIFEST);
        let json = serde_json::to_string_pretty(&manifest).unwrap_or_default();
        std::fs::write(&path, json + "\n").map_err(io(path.clone()))?;
        let script_path = dir.join(SCRIPT);
        let text = script(&self.plan, &dir, runs.len(), command);
        std::fs::write(&script_path, text).map_err(io(script_path.clone()))?;
        Ok(script_path)
    }
}
