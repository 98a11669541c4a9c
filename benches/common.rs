//! What the benchmarks share.

use std::path::PathBuf;
use std::time::SystemTime;

/// The state every model is measured at: q and qd of `n` coordinates, away from any symmetry.
pub fn test_state(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n).map(|i| 0.5 * (1.3 * i as f64 + 0.4).sin()).collect();
    let qd = (0..n).map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos()).collect();
    (q, qd)
}

/// criterion's median of `group/id` in ns, from its estimates file, when this run measured it:
/// none in test mode, and none for a benchmark a filter left out, whose file is older than
/// `since` (the start of the run), so that a summary never mixes in an earlier run's figures.
#[allow(dead_code)] // not every benchmark reads criterion's medians
pub fn median_ns(group: &str, id: &str, since: SystemTime) -> Option<f64> {
    let dir = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target"));
    let path = dir
        .join("criterion")
        .join(group)
        .join(id)
        .join("new/estimates.json");
    if std::fs::metadata(&path).ok()?.modified().ok()? < since {
        return None;
    }
    let text = std::fs::read_to_string(path).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v["median"]["point_estimate"].as_f64()
}

/// The processor the figures were measured on, as Linux describes it (`/proc/cpuinfo`: its
/// name, and its family and model, which tell its generation where a virtual machine names
/// it only by its maker): timings, and the ratios between code of different shapes, depend
/// on it. `unknown` elsewhere.
#[allow(dead_code)] // the benchmarks that print a summary print it
pub fn processor() -> String {
    let Ok(info) = std::fs::read_to_string("/proc/cpuinfo") else {
        return "unknown".into();
    };
    let field = |key: &str| {
        info.lines()
            .filter_map(|l| l.split_once(':'))
            .find(|(k, _)| k.trim() == key)
            .map(|(_, v)| v.trim().to_string())
    };
    match (field("model name"), field("cpu family"), field("model")) {
        (Some(name), Some(family), Some(model)) => {
            format!("{name} (family {family}, model {model})")
        }
        (Some(name), ..) => name,
        _ => "unknown".into(),
    }
}
