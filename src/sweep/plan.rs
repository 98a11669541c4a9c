//! The plan of a sweep (TOML) and the run list it expands to.

use super::SweepError;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};

/// A sweep: its design, the simulation settings every run starts from, the variables that
/// vary, and how a Slurm job array runs it.
///
/// ```toml
/// [sweep]
/// design = "monte-carlo"    # grid | lhs | monte-carlo | list
/// runs = 1000
/// seed = 7
///
/// [simulation]              # every field optional; the program's defaults otherwise
/// scheme = "dopri5"
/// t_end = 5.0
/// rtol = 1e-8
///
/// [[vary]]
/// name = "l"                # a parameter of the model
/// uniform = [0.9, 1.1]
///
/// [[vary]]
/// name = "q0[0]"            # an initial coordinate (or `qd0[i]`, `q0.NAME`, `qd0.NAME`)
/// normal = [1.5, 0.05]
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    pub sweep: Design,
    #[serde(default)]
    pub simulation: SimulationSpec,
    #[serde(default)]
    pub vary: Vec<Variable>,
    #[serde(default)]
    pub slurm: SlurmSpec,
}

/// How the runs are chosen.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Design {
    pub design: DesignKind,
    /// number of runs (Latin hypercube and Monte-Carlo)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runs: Option<usize>,
    /// seed of the random designs (ChaCha8: the same runs on every platform); default 0
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// `list`: a CSV file with one column per variable and one row per run (relative to
    /// the plan's folder)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DesignKind {
    /// every combination of the variables' `values` (or `range` and `count`), the last
    /// variable varying fastest
    Grid,
    /// Latin hypercube: `runs` strata per variable, one sample in each, strata paired at
    /// random (`uniform` or `log_uniform` variables)
    Lhs,
    /// `runs` independent draws (`uniform`, `log_uniform` or `normal` variables)
    MonteCarlo,
    /// the rows of `file`
    List,
}

impl DesignKind {
    fn name(self) -> &'static str {
        match self {
            DesignKind::Grid => "grid",
            DesignKind::Lhs => "lhs",
            DesignKind::MonteCarlo => "monte-carlo",
            DesignKind::List => "list",
        }
    }
}

/// The simulation settings of every run, as the per-system programs' options (`scheme`,
/// `t_end`, `h`, `rtol`, `atol`, `dt`, `max_steps`, `constraints`) and the start (`t0`, and
/// `q0`, `qd0` with one value per coordinate, where they differ from the model's); a run's
/// variables may override `scheme`, `t_end`, `h`, `rtol` and `atol`, and its `q0…`, `qd0…`
/// entries.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scheme: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t0: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub q0: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub qd0: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_end: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub h: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dt: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_steps: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constraints: Option<String>,
    /// the parameters of `scheme` (Newmark's β and γ, HHT's α, generalized-α's, BDF's
    /// highest order), as the sweep folder's `plan.toml` records them: a program whose scheme
    /// of that name has others is refused, so that no run of the table is made with others
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scheme_parameters: Option<String>,
}

/// One varied quantity: a parameter of the model (its name), an initial coordinate or
/// velocity (`q0[i]`, `qd0[i]`, `q0.NAME`, `qd0.NAME`) or a simulation setting (`scheme`,
/// `t_end`, `h`, `rtol`, `atol`), with its values (grid) or its distribution (random designs).
/// As on the command line, a run that varies `rtol` and not `atol` has atol = rtol/100, and
/// one that varies `rtol` runs with step control even if `[simulation]` gives `h`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Variable {
    pub name: String,
    /// grid: the values, numbers or (for `scheme`) names
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values: Option<Vec<Value>>,
    /// grid: `count` values evenly spaced from `range[0]` to `range[1]`
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<usize>,
    /// random designs: uniform on [lo, hi]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uniform: Option<[f64; 2]>,
    /// random designs: log-uniform on [lo, hi] (lo > 0), for stiffnesses and tolerances
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_uniform: Option<[f64; 2]>,
    /// Monte-Carlo: normal with [mean, standard deviation]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 2]>,
}

/// How `--slurm` writes the job array's script (every field optional).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlurmSpec {
    /// array tasks, each running one contiguous shard of the runs (default 4)
    #[serde(default = "default_tasks")]
    pub tasks: usize,
    /// cores per task: each task runs its shard on this many threads (default 1)
    #[serde(default = "default_cpus")]
    pub cpus_per_task: usize,
    /// `--time` of each task (default `01:00:00`)
    #[serde(default = "default_time")]
    pub time: String,
    /// `--mem-per-cpu` (default `1G`)
    #[serde(default = "default_mem")]
    pub mem_per_cpu: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub partition: Option<String>,
    /// further `#SBATCH` options, written as given (`--account=…`, `--qos=…`)
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub extra: Vec<String>,
}

fn default_tasks() -> usize {
    4
}
fn default_cpus() -> usize {
    1
}
fn default_time() -> String {
    "01:00:00".into()
}
fn default_mem() -> String {
    "1G".into()
}

impl Default for SlurmSpec {
    fn default() -> Self {
        SlurmSpec {
            tasks: default_tasks(),
            cpus_per_task: default_cpus(),
            time: default_time(),
            mem_per_cpu: default_mem(),
            partition: None,
            extra: Vec::new(),
        }
    }
}

/// A value of a variable: a number, or a name (a scheme).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Value {
    Num(f64),
    Text(String),
}

impl fmt::Display for Value {
    /// Numbers in Rust's shortest form that reads back to the same `f64`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Num(x) => write!(f, "{x:?}"),
            Value::Text(s) => f.write_str(s),
        }
    }
}

impl Value {
    /// A field of a CSV file: a number if it reads as one.
    pub fn parse(s: &str) -> Value {
        match s.trim().parse::<f64>() {
            Ok(x) => Value::Num(x),
            Err(_) => Value::Text(s.trim().to_string()),
        }
    }
}

/// The runs of a sweep: one row of values per run, in the order of `names`.
#[derive(Clone, Debug, PartialEq)]
pub struct RunList {
    pub names: Vec<String>,
    pub rows: Vec<Vec<Value>>,
}

impl RunList {
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The list as CSV: a `run` column (0, 1, …) and one column per variable.
    pub fn to_csv(&self) -> String {
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut header = vec!["run".to_string()];
        header.extend(self.names.iter().cloned());
        let _ = w.write_record(&header);
        for (i, row) in self.rows.iter().enumerate() {
            let mut rec = vec![i.to_string()];
            rec.extend(row.iter().map(Value::to_string));
            let _ = w.write_record(&rec);
        }
        String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
    }

    /// Reads [`RunList::to_csv`]'s text back (runs numbered 0, 1, … in order).
    pub fn from_csv(text: &str, path: &Path) -> Result<RunList, SweepError> {
        let bad = |reason: String| SweepError::Table {
            path: path.to_path_buf(),
            reason,
        };
        let mut r = csv::Reader::from_reader(text.as_bytes());
        let header = r.headers().map_err(|e| bad(e.to_string()))?.clone();
        if header.get(0) != Some("run") {
            return Err(bad("the first column must be `run`".into()));
        }
        let names: Vec<String> = header.iter().skip(1).map(String::from).collect();
        let mut rows = Vec::new();
        for (i, rec) in r.records().enumerate() {
            let rec = rec.map_err(|e| bad(e.to_string()))?;
            if rec.get(0).and_then(|s| s.parse::<usize>().ok()) != Some(i) {
                return Err(bad(format!("row {} is not run {i}", i + 1)));
            }
            rows.push(rec.iter().skip(1).map(Value::parse).collect());
        }
        Ok(RunList { names, rows })
    }
}

/// `message` with each number quoted in backticks that is written out longer than a user
/// would type it written as `error::short` writes it: the TOML reader quotes a value of the wrong
/// type as `f64`'s Display writes it, 1e308 as 309 digits.
fn numbers_shortened(message: &str) -> String {
    let mut parts: Vec<String> = message.split('`').map(str::to_string).collect();
    for part in parts.iter_mut().skip(1).step_by(2) {
        if part.len() > 15
            && let Ok(x) = part.parse::<f64>()
        {
            *part = crate::error::short(x);
        }
    }
    parts.join("`")
}

impl Plan {
    /// Reads a plan from TOML text; unknown keys are errors.
    pub fn from_toml(text: &str) -> Result<Plan, SweepError> {
        toml::from_str(text).map_err(|e| SweepError::Plan(numbers_shortened(&e.to_string())))
    }

    /// Reads a plan file.
    pub fn load(path: &Path) -> Result<Plan, SweepError> {
        let text = std::fs::read_to_string(path).map_err(|source| SweepError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Plan::from_toml(&text).map_err(|e| match e {
            SweepError::Plan(reason) => SweepError::Plan(format!("{}: {reason}", path.display())),
            e => e,
        })
    }

    /// The plan as TOML.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    /// The runs this plan describes (`dir`: where a `list` design's file is looked for).
    pub fn runs(&self, dir: &Path) -> Result<RunList, SweepError> {
        let design = self.sweep.design;
        let names: Vec<String> = self.vary.iter().map(|v| v.name.clone()).collect();
        for (i, n) in names.iter().enumerate() {
            if names[..i].contains(n) {
                return Err(SweepError::Plan(format!("variable `{n}` is varied twice")));
            }
        }
        let need_runs = || {
            self.sweep
                .runs
                .filter(|&n| n > 0 && n <= MAX_RUNS)
                .ok_or_else(|| {
                    SweepError::Plan(format!(
                        "a {} design needs `runs = N` (0 < N ≤ {MAX_RUNS}) in [sweep]",
                        design.name()
                    ))
                })
        };
        let mut rng = ChaCha8Rng::seed_from_u64(self.sweep.seed.unwrap_or(0));
        let rows = match design {
            DesignKind::Grid => {
                let axes = self
                    .vary
                    .iter()
                    .map(Variable::grid_values)
                    .collect::<Result<Vec<_>, _>>()?;
                let runs = axes
                    .iter()
                    .try_fold(1usize, |n, a| n.checked_mul(a.len()))
                    .filter(|&n| n <= MAX_RUNS);
                if runs.is_none() {
                    let counts: Vec<String> = axes.iter().map(|a| a.len().to_string()).collect();
                    return Err(SweepError::Plan(format!(
                        "the grid has {} runs, more than {MAX_RUNS}: take fewer values per variable, or a Latin hypercube (design = \"lhs\")",
                        counts.join(" × ")
                    )));
                }
                grid(&axes)
            }
            DesignKind::MonteCarlo => {
                let n = need_runs()?;
                let dists = self
                    .vary
                    .iter()
                    .map(|v| v.distribution(design))
                    .collect::<Result<Vec<_>, _>>()?;
                (0..n)
                    .map(|_| dists.iter().map(|d| Value::Num(d.draw(&mut rng))).collect())
                    .collect()
            }
            DesignKind::Lhs => {
                let n = need_runs()?;
                let dists = self
                    .vary
                    .iter()
                    .map(|v| v.distribution(design))
                    .collect::<Result<Vec<_>, _>>()?;
                latin_hypercube(&dists, n, &mut rng)
            }
            DesignKind::List => {
                if !self.vary.is_empty() {
                    return Err(SweepError::Plan(
                        "a list design takes its variables from its file's header: remove the [[vary]] tables".into(),
                    ));
                }
                let file = self.sweep.file.as_ref().ok_or_else(|| {
                    SweepError::Plan("a list design needs `file = \"runs.csv\"` in [sweep]".into())
                })?;
                let path = dir.join(file);
                let text = std::fs::read_to_string(&path).map_err(|source| SweepError::Io {
                    path: path.clone(),
                    source,
                })?;
                return list(&text, &path);
            }
        };
        Ok(RunList { names, rows })
    }
}

/// A distribution of a random design.
#[derive(Clone, Copy, Debug)]
enum Dist {
    Uniform(f64, f64),
    LogUniform(f64, f64),
    Normal(f64, f64),
}

impl Dist {
    /// The value at u ∈ [0, 1) of the uniform or log-uniform distribution (its inverse CDF).
    fn at(self, u: f64) -> f64 {
        match self {
            Dist::Uniform(lo, hi) => between(lo, hi, u),
            Dist::LogUniform(lo, hi) => (lo.ln() + u * (hi.ln() - lo.ln())).exp(),
            Dist::Normal(..) => unreachable!("a Latin hypercube refuses normal variables"),
        }
    }

    fn draw(self, rng: &mut ChaCha8Rng) -> f64 {
        match self {
            Dist::Normal(mean, sd) => Normal::new(mean, sd).map_or(mean, |n| n.sample(rng)),
            _ => self.at(rng.random::<f64>()),
        }
    }
}

impl Variable {
    fn set_fields(&self) -> Vec<&'static str> {
        let mut f = Vec::new();
        for (name, set) in [
            ("values", self.values.is_some()),
            ("range", self.range.is_some()),
            ("count", self.count.is_some()),
            ("uniform", self.uniform.is_some()),
            ("log_uniform", self.log_uniform.is_some()),
            ("normal", self.normal.is_some()),
        ] {
            if set {
                f.push(name);
            }
        }
        f
    }

    fn grid_values(&self) -> Result<Vec<Value>, SweepError> {
        let bad = |what: &str| {
            SweepError::Plan(format!(
                "variable `{}` of a grid design needs {what}",
                self.name
            ))
        };
        match (
            &self.values,
            self.range,
            self.count,
            self.set_fields().len(),
        ) {
            (Some(v), None, None, 1) if !v.is_empty() => Ok(v.clone()),
            (None, Some([a, b]), Some(n), 2)
                if (1..=MAX_RUNS).contains(&n) && a.is_finite() && b.is_finite() =>
            {
                Ok((0..n)
                    .map(|i| {
                        let s = if n == 1 {
                            0.0
                        } else {
                            i as f64 / (n - 1) as f64
                        };
                        Value::Num(if i + 1 == n { b } else { between(a, b, s) })
                    })
                    .collect())
            }
            _ => Err(bad(&format!(
                "either `values = [...]` (not empty) or `range = [from, to]` with `count = N` (1 ≤ N ≤ {MAX_RUNS})"
            ))),
        }
    }

    fn distribution(&self, design: DesignKind) -> Result<Dist, SweepError> {
        let allowed = if design == DesignKind::Lhs {
            "`uniform = [lo, hi]` or `log_uniform = [lo, hi]`"
        } else {
            "`uniform = [lo, hi]`, `log_uniform = [lo, hi]` or `normal = [mean, sd]`"
        };
        let bad = |why: &str| {
            SweepError::Plan(format!(
                "variable `{}` of a {} design needs one of {allowed}{why}",
                self.name,
                design.name()
            ))
        };
        if self.set_fields().len() != 1 {
            return Err(bad(""));
        }
        let finite = |[a, b]: [f64; 2]| a.is_finite() && b.is_finite();
        match (self.uniform, self.log_uniform, self.normal) {
            (Some(r), _, _) if finite(r) && r[0] <= r[1] => Ok(Dist::Uniform(r[0], r[1])),
            (_, Some(r), _) if finite(r) && 0.0 < r[0] && r[0] <= r[1] => {
                Ok(Dist::LogUniform(r[0], r[1]))
            }
            (_, _, Some(r)) if design != DesignKind::Lhs && finite(r) && r[1] >= 0.0 => {
                Ok(Dist::Normal(r[0], r[1]))
            }
            (Some(_), _, _) => Err(bad(" with lo ≤ hi, both finite")),
            (_, Some(_), _) => Err(bad(" with 0 < lo ≤ hi, both finite")),
            (_, _, Some(_)) if design == DesignKind::Lhs => Err(bad(" (not `normal`)")),
            _ => Err(bad(" with a finite mean and sd ≥ 0")),
        }
    }
}

/// a + s (b − a), or weighted, a (1 − s) + b s, where b − a overflows (bounds near
/// ±f64::MAX, which gave NaN and infinities no one wrote).
fn between(a: f64, b: f64, s: f64) -> f64 {
    let d = b - a;
    if d.is_finite() {
        a + s * d
    } else {
        a * (1.0 - s) + b * s
    }
}

/// The most runs a plan may make: 10⁸ (the run list is held in memory and written to
/// `runs.csv`; a grid of 10¹² runs aborted allocating it).
const MAX_RUNS: usize = 100_000_000;

/// Every combination, the last axis varying fastest.
fn grid(axes: &[Vec<Value>]) -> Vec<Vec<Value>> {
    let n: usize = axes.iter().map(Vec::len).product();
    (0..n)
        .map(|mut k| {
            let mut row = vec![Value::Num(0.0); axes.len()];
            for (j, axis) in axes.iter().enumerate().rev() {
                row[j] = axis[k % axis.len()].clone();
                k /= axis.len();
            }
            row
        })
        .collect()
}

/// n strata per variable, one uniform sample inside each, strata shuffled per variable.
fn latin_hypercube(dists: &[Dist], n: usize, rng: &mut ChaCha8Rng) -> Vec<Vec<Value>> {
    let mut rows = vec![Vec::with_capacity(dists.len()); n];
    for d in dists {
        let mut strata: Vec<usize> = (0..n).collect();
        // Fisher–Yates
        for i in (1..n).rev() {
            strata.swap(i, rng.random_range(0..=i));
        }
        for (row, &s) in rows.iter_mut().zip(&strata) {
            let u = (s as f64 + rng.random::<f64>()) / n as f64;
            row.push(Value::Num(d.at(u)));
        }
    }
    rows
}

/// A list design's file: a header of variable names, one run per row.
/// A list file's runs; a file whose first column is `run` is a sweep folder's run list
/// ([`RunList::to_csv`]: a `run` column of the user's would double the table's own).
fn list(text: &str, path: &Path) -> Result<RunList, SweepError> {
    if text.split(['\n', ',']).next().map(str::trim) == Some("run") {
        return RunList::from_csv(text, path);
    }
    let bad = |reason: String| SweepError::Table {
        path: path.to_path_buf(),
        reason,
    };
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let names: Vec<String> = r
        .headers()
        .map_err(|e| bad(e.to_string()))?
        .iter()
        .map(|s| s.trim().to_string())
        .collect();
    if names.is_empty() || names.iter().any(String::is_empty) {
        return Err(bad("the header must name every column".into()));
    }
    let mut rows = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(|e| bad(e.to_string()))?;
        rows.push(rec.iter().map(Value::parse).collect());
    }
    if rows.is_empty() {
        return Err(bad("no runs: the file has a header and no rows".into()));
    }
    Ok(RunList { names, rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(text: &str) -> Plan {
        Plan::from_toml(text).unwrap()
    }

    #[test]
    fn grid_runs_every_combination_last_fastest() {
        let p = plan(
            "[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"a\"\nvalues = [1, 2]\n\
             [[vary]]\nname = \"scheme\"\nvalues = [\"dopri5\", \"radau5\", \"bdf\"]\n",
        );
        let r = p.runs(Path::new(".")).unwrap();
        assert_eq!(r.len(), 6);
        assert_eq!(
            r.rows[1],
            vec![Value::Num(1.0), Value::Text("radau5".into())]
        );
        assert_eq!(
            r.rows[3],
            vec![Value::Num(2.0), Value::Text("dopri5".into())]
        );
        let lin =
            plan("[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"k\"\nrange = [0, 1]\ncount = 5\n")
                .runs(Path::new("."))
                .unwrap();
        let v: Vec<String> = lin.rows.iter().map(|r| r[0].to_string()).collect();
        assert_eq!(v, ["0.0", "0.25", "0.5", "0.75", "1.0"]);
    }

    #[test]
    fn latin_hypercube_has_one_sample_per_stratum() {
        let p = plan(
            "[sweep]\ndesign = \"lhs\"\nruns = 50\nseed = 3\n[[vary]]\nname = \"a\"\nuniform = [2, 4]\n\
             [[vary]]\nname = \"k\"\nlog_uniform = [1e2, 1e6]\n",
        );
        let r = p.runs(Path::new(".")).unwrap();
        for (j, (lo, hi, log)) in [(2.0f64, 4.0f64, false), (1e2, 1e6, true)]
            .into_iter()
            .enumerate()
        {
            let mut hit = vec![0; 50];
            for row in &r.rows {
                let Value::Num(x) = row[j] else { panic!() };
                let u = if log {
                    (x.ln() - lo.ln()) / (hi.ln() - lo.ln())
                } else {
                    (x - lo) / (hi - lo)
                };
                hit[(u * 50.0).floor() as usize] += 1;
            }
            assert!(hit.iter().all(|&h| h == 1), "{hit:?}");
        }
        // the same seed gives the same runs, another seed others
        assert_eq!(r, p.runs(Path::new(".")).unwrap());
        let mut q = p.clone();
        q.sweep.seed = Some(4);
        assert_ne!(r, q.runs(Path::new(".")).unwrap());
    }

    #[test]
    fn monte_carlo_draws_follow_their_distribution() {
        let p = plan(
            "[sweep]\ndesign = \"monte-carlo\"\nruns = 20000\n[[vary]]\nname = \"m\"\nnormal = [3, 0.5]\n",
        );
        let r = p.runs(Path::new(".")).unwrap();
        let x: Vec<f64> = r
            .rows
            .iter()
            .map(|r| match r[0] {
                Value::Num(x) => x,
                _ => f64::NAN,
            })
            .collect();
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64).sqrt();
        // 20,000 draws: the mean within 4 standard errors, the sd within 3 %
        assert!((mean - 3.0).abs() < 4.0 * 0.5 / (20000f64).sqrt(), "{mean}");
        assert!((sd / 0.5 - 1.0).abs() < 0.03, "{sd}");
    }

    #[test]
    fn bad_plans_say_what_to_write() {
        let e = |t: &str| {
            Plan::from_toml(t)
                .and_then(|p| p.runs(Path::new(".")))
                .unwrap_err()
                .to_string()
        };
        assert!(
            e("[sweep]\ndesign = \"lhs\"\n[[vary]]\nname = \"a\"\nuniform = [0, 1]\n")
                .contains("runs = N")
        );
        assert!(
            e("[sweep]\ndesign = \"lhs\"\nruns = 3\n[[vary]]\nname = \"a\"\nnormal = [0, 1]\n")
                .contains("not `normal`")
        );
        assert!(
            e("[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"a\"\nuniform = [0, 1]\n")
                .contains("values = [...]")
        );
        assert!(e("[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"a\"\nvalues = [1]\n[[vary]]\nname = \"a\"\nvalues = [2]\n").contains("varied twice"));
        assert!(e("[sweep]\ndesign = \"grid\"\nrns = 3\n").contains("rns"));
        assert!(e("[sweep]\ndesign = \"sobol\"\n").contains("sobol"));
        // more runs than memory holds (these aborted allocating the run list)
        let axis =
            |name: &str| format!("[[vary]]\nname = \"{name}\"\nrange = [0, 1]\ncount = 100000\n");
        let grid = format!("[sweep]\ndesign = \"grid\"\n{}{}", axis("a"), axis("b"));
        assert!(e(&grid).contains("100000 × 100000 runs, more than 100000000"));
        let one = "[sweep]\ndesign = \"grid\"\n[[vary]]\nname = \"a\"\nrange = [0, 1]\ncount = 1000000000000\n";
        assert!(e(one).contains("1 ≤ N ≤ 100000000"));
        let mc = "[sweep]\ndesign = \"monte-carlo\"\nruns = 1000000000000\n[[vary]]\nname = \"a\"\nuniform = [0, 1]\n";
        assert!(e(mc).contains("0 < N ≤ 100000000"));
    }

    #[test]
    fn run_lists_read_back_exactly() {
        let p = plan(
            "[sweep]\ndesign = \"monte-carlo\"\nruns = 30\nseed = 9\n[[vary]]\nname = \"a\"\nuniform = [0, 1]\n\
             [[vary]]\nname = \"q0[1]\"\nnormal = [0.1, 1e-3]\n",
        );
        let r = p.runs(Path::new(".")).unwrap();
        assert_eq!(
            RunList::from_csv(&r.to_csv(), Path::new("runs.csv")).unwrap(),
            r
        );
        assert_eq!(Plan::from_toml(&p.to_toml()).unwrap(), p);
    }
}
