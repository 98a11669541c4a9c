//! A sweep as a Slurm job array, for real: a single-node Slurm (Debian's slurm-wlm and munge)
//! started on localhost by `tests/slurm/slurm_local.sh`, a 3-task array of a dpend sweep
//! made by the per-system program (`--sweep … --slurm`, `sbatch`, `--merge`), and the merged
//! table equal to the same sweep made locally.
//!
//! Without Slurm on the machine the test says so and passes, unless MBS_REQUIRE_SLURM=1 (set
//! by `.ci/run`, which installs Slurm when missing): then it fails.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

const PLAN: &str = r#"
[sweep]
design = "lhs"
runs = 60
seed = 4

[simulation]
t_end = 3.0
rtol = 1e-8

[[vary]]
name = "l"
uniform = [0.7, 1.4]

[[vary]]
name = "qd0[0]"
uniform = [-1.0, 1.0]

[slurm]
tasks = 3
time = "00:05:00"
mem_per_cpu = "200M"
"#;

fn run(cmd: &mut Command) -> Output {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{cmd:?}: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The table without its last column (CPU time).
fn without_cpu(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .map(|l| l[..l.rfind(',').unwrap()].to_string())
        .collect()
}

/// The cluster of one test, stopped when the test ends, however it ends.
struct Cluster {
    dir: PathBuf,
    script: PathBuf,
}

impl Cluster {
    fn start(dir: &Path) -> Cluster {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/slurm/slurm_local.sh");
        let cluster = Cluster {
            dir: dir.to_path_buf(),
            script,
        };
        run(Command::new("bash")
            .arg(&cluster.script)
            .arg("start")
            .arg(dir));
        cluster
    }

    fn conf(&self) -> PathBuf {
        self.dir.join("slurm.conf")
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new("bash")
            .arg(&self.script)
            .arg("stop")
            .arg(&self.dir)
            .output();
    }
}

fn have_slurm() -> bool {
    ["sbatch", "squeue", "slurmctld", "slurmd", "munged"]
        .iter()
        .all(|p| {
            Command::new("sh")
                .args(["-c", &format!("command -v {p} || test -x /usr/sbin/{p}")])
                .output()
                .is_ok_and(|o| o.status.success())
        })
}

#[cfg(unix)]
#[test]
fn a_slurm_job_array_gives_the_table_of_the_local_sweep() {
    if !have_slurm() {
        assert!(
            std::env::var("MBS_REQUIRE_SLURM").as_deref() != Ok("1"),
            "Slurm (sbatch, slurmctld, slurmd, munged) is required here (MBS_REQUIRE_SLURM=1): \
             install Debian's slurm-wlm and munge"
        );
        eprintln!("Slurm is not installed (Debian's slurm-wlm and munge): job array not tested");
        return;
    }
    let program = common::example("dpend");
    // short paths: the cluster's Unix sockets live under its folder
    let root = std::env::temp_dir().join(format!("mbs-slurm-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&root).unwrap();
    let plan = root.join("plan.toml");
    std::fs::write(&plan, PLAN).unwrap();

    // the same sweep on this machine
    let local = root.join("local");
    run(Command::new(&program)
        .args(["--quiet", "--sweep"])
        .arg(&plan)
        .arg("--out")
        .arg(&local));

    let cluster = Cluster::start(&root.join("cluster"));
    let array = root.join("array");
    run(Command::new(&program)
        .args(["--quiet", "--sweep"])
        .arg(&plan)
        .arg("--out")
        .arg(&array)
        .arg("--slurm"));
    let submitted = run(Command::new("sbatch")
        .env("SLURM_CONF", cluster.conf())
        .arg("--parsable")
        .arg(array.join("sweep.sbatch")));
    let job = String::from_utf8_lossy(&submitted.stdout)
        .trim()
        .to_string();
    let start = Instant::now();
    loop {
        let q = run(Command::new("squeue")
            .env("SLURM_CONF", cluster.conf())
            .args(["-h", "-j", &job]));
        if q.stdout.iter().all(u8::is_ascii_whitespace) {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(180),
            "job array {job} still queued or running after 180 s: {}",
            String::from_utf8_lossy(&q.stdout)
        );
        std::thread::sleep(Duration::from_millis(250));
    }
    // each task wrote its part and its log
    for k in 0..3 {
        let part = array.join(format!("parts/part-{k}-of-3.csv"));
        assert!(
            part.exists(),
            "task {k} wrote no part; its log: {}",
            std::fs::read_to_string(array.join(format!("logs/task-{k}.log"))).unwrap_or_default()
        );
    }
    run(Command::new(&program)
        .args(["--quiet", "--sweep"])
        .arg(array.join("plan.toml"))
        .arg("--out")
        .arg(&array)
        .arg("--merge"));
    let merged = without_cpu(&array.join("results.csv"));
    assert_eq!(merged.len(), 61);
    assert_eq!(merged, without_cpu(&local.join("results.csv")));
    drop(cluster);
    let _ = std::fs::remove_dir_all(&root);
}
