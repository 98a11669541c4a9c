//! The tables of a sweep: a CSV file written one row at a time (the journal a restarted
//! sweep reads to skip what is done), and the merge of a job array's parts.

use super::{Shard, SweepError, slurm};
use std::fs::{File, OpenOptions};
use std::path::{Path, PathBuf};

/// A table being written: its header, the runs it holds, the file open for appending.
pub(super) struct Journal {
    path: PathBuf,
    done: Vec<bool>,
    out: csv::Writer<File>,
}

impl Journal {
    /// Opens `path` for appending after the rows it has (a row cut short by a kill is
    /// removed), or creates it with `columns` as its header. A table with other columns is
    /// another sweep's.
    pub(super) fn open(
        path: &Path,
        columns: &[String],
        runs: usize,
    ) -> Result<Journal, SweepError> {
        let io = |source| SweepError::Io {
            path: path.to_path_buf(),
            source,
        };
        let bad = |reason: String| SweepError::Table {
            path: path.to_path_buf(),
            reason,
        };
        let mut done = vec![false; runs];
        if path.exists() {
            let bytes = complete_lines(path)?;
            let keep = bytes.len();
            let f = OpenOptions::new().write(true).open(path).map_err(io)?;
            f.set_len(keep as u64).map_err(io)?;
            let mut r = csv::Reader::from_reader(bytes.as_slice());
            let header = header(&mut r).map_err(bad)?;
            if keep > 0 && header != columns {
                return Err(bad(format!(
                    "its columns ({}) are not this sweep's ({}): choose another folder",
                    header.join(", "),
                    columns.join(", ")
                )));
            }
            for rec in r.records() {
                let rec = rec.map_err(|e| bad(e.to_string()))?;
                match rec.get(0).and_then(|s| s.parse::<usize>().ok()) {
                    Some(i) if i < runs => done[i] = true,
                    _ => return Err(bad(format!("row `{}` names no run", rec.as_slice()))),
                }
            }
        }
        let file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(io)?;
        let empty = file.metadata().map_err(io)?.len() == 0;
        let mut out = csv::Writer::from_writer(file);
        if empty {
            out.write_record(columns).map_err(|e| bad(e.to_string()))?;
            out.flush().map_err(io)?;
        }
        Ok(Journal {
            path: path.to_path_buf(),
            done,
            out,
        })
    }

    pub(super) fn has(&self, run: usize) -> bool {
        self.done[run]
    }

    /// Writes one row and flushes it: a kill loses at most the rows not yet written.
    pub(super) fn append(&mut self, fields: &[String]) -> Result<(), SweepError> {
        self.out.write_record(fields).map_err(|e| self.error(e))?;
        self.out.flush().map_err(|source| SweepError::Io {
            path: self.path.clone(),
            source,
        })
    }

    fn error(&self, e: csv::Error) -> SweepError {
        SweepError::Table {
            path: self.path.clone(),
            reason: e.to_string(),
        }
    }
}

/// A table's column names.
fn header(r: &mut csv::Reader<&[u8]>) -> Result<Vec<String>, String> {
    let h = r.headers().map_err(|e| e.to_string())?;
    Ok(h.iter().map(String::from).collect())
}

/// The complete lines of a table: a task killed while writing leaves its last row out.
fn complete_lines(path: &Path) -> Result<Vec<u8>, SweepError> {
    let mut bytes = std::fs::read(path).map_err(|source| SweepError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let keep = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    bytes.truncate(keep);
    Ok(bytes)
}

/// What [`merge`] wrote.
#[derive(Clone, Debug)]
pub struct MergeReport {
    pub runs: usize,
    pub failed: usize,
    pub parts: usize,
    pub table: PathBuf,
}

/// Merges the parts of a job array (`dir/parts/part-K-of-N.csv`, N from `dir/manifest.json`)
/// into `dir/results.csv` in run order, one part in memory at a time. Every run of
/// `dir/runs.csv` must be present once: otherwise the missing runs are listed in
/// `dir/missing.csv` (run, shard), nothing is merged, and the error names the array tasks to
/// submit again. With the `parquet` feature
/// it also writes `dir/results.parquet`.
pub fn merge(dir: &Path) -> Result<MergeReport, SweepError> {
    let manifest = slurm::Manifest::read(dir)?;
    let n = manifest.runs;
    let tasks = manifest.tasks;
    if tasks == 0 || tasks > n.max(1) {
        return Err(SweepError::Table {
            path: dir.join("manifest.json"),
            reason: format!(
                "tasks = {tasks} for {n} runs: a job array has 1 to {} tasks (write the array again with `--slurm`)",
                n.max(1)
            ),
        });
    }
    let table = dir.join("results.csv");
    let tmp = dir.join("results.csv.partial");
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| SweepError::Io { path, source }
    };
    let mut out = csv::Writer::from_path(&tmp).map_err(|e| SweepError::Table {
        path: tmp.clone(),
        reason: e.to_string(),
    })?;
    out.write_record(&manifest.columns)
        .map_err(|e| SweepError::Table {
            path: tmp.clone(),
            reason: e.to_string(),
        })?;
    let status = manifest.columns.iter().position(|c| c == "status");
    let mut missing: Vec<(usize, usize)> = Vec::new();
    let mut failed = 0;
    for k in 0..tasks {
        let shard = Shard {
            index: k,
            count: tasks,
        };
        let range = shard.range(n);
        let path = dir.join("parts").join(shard.file_name());
        let mut next = range.start;
        if path.exists() {
            let bad = |reason: String| SweepError::Table {
                path: path.clone(),
                reason,
            };
            let text = complete_lines(&path)?;
            let mut r = csv::Reader::from_reader(text.as_slice());
            if header(&mut r).map_err(bad)? != manifest.columns {
                return Err(bad("its columns are not the manifest's".into()));
            }
            for rec in r.records() {
                let rec = rec.map_err(|e| bad(e.to_string()))?;
                let run: usize = rec
                    .get(0)
                    .and_then(|s| s.parse().ok())
                    .ok_or_else(|| bad(format!("row `{}` names no run", rec.as_slice())))?;
                if !range.contains(&run) || run < next {
                    return Err(bad(format!(
                        "run {run} is out of order or not of this shard (runs {}..{})",
                        range.start, range.end
                    )));
                }
                missing.extend((next..run).map(|i| (i, k)));
                next = run + 1;
                if status.and_then(|s| rec.get(s)) == Some("failed") {
                    failed += 1;
                }
                out.write_record(&rec).map_err(|e| bad(e.to_string()))?;
            }
        }
        missing.extend((next..range.end).map(|i| (i, k)));
    }
    out.flush().map_err(io(&tmp))?;
    drop(out);
    if !missing.is_empty() {
        let _ = std::fs::remove_file(&tmp);
        let list = dir.join("missing.csv");
        let mut text = String::from("run,shard\n");
        for (i, k) in &missing {
            text.push_str(&format!("{i},{k}\n"));
        }
        std::fs::write(&list, text).map_err(io(&list))?;
        let mut shards: Vec<usize> = missing.iter().map(|&(_, k)| k).collect();
        shards.dedup();
        return Err(SweepError::Missing {
            missing: missing.len(),
            runs: n,
            list,
            tasks: shards
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(","),
            script: dir.join(slurm::SCRIPT),
        });
    }
    let _ = std::fs::remove_file(dir.join("missing.csv"));
    std::fs::rename(&tmp, &table).map_err(io(&table))?;
    #[cfg(feature = "parquet")]
    super::parquet::write(&table, &dir.join("results.parquet"))?;
    Ok(MergeReport {
        runs: n,
        failed,
        parts: tasks,
        table,
    })
}
