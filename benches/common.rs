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

/// Rounds of [`paired`].
#[allow(dead_code)] // the benchmarks that measure in pairs print it
pub const ROUNDS: usize = 401;

/// The ratio of the times of `second` and `first`, measured in pairs ([`paired`]).
#[allow(dead_code)] // not every benchmark measures in pairs
#[derive(Clone, Copy, Debug)]
pub struct Paired {
    /// quartiles of the rounds' ratios
    pub quartiles: [f64; 3],
    /// the ratio of the two functions' fastest blocks: the moments the machine ran each
    /// fastest, where the delays of other work, which only add time, were least
    pub fastest: f64,
}

#[allow(dead_code)] // not every benchmark measures in pairs
impl Paired {
    /// Not measured (criterion's test mode, or a filter left the function out).
    pub const NONE: Paired = Paired {
        quartiles: [f64::NAN; 3],
        fastest: f64::NAN,
    };
}

/// [`paired`] in a measuring run, which criterion's median of `group/id` marks ([`median_ns`]);
/// [`Paired::NONE`] in test mode or where a filter left that function out.
#[allow(dead_code)] // not every benchmark measures in pairs
pub fn paired_if_measured(
    (group, id): (&str, &str),
    since: SystemTime,
    first: &mut dyn FnMut(),
    second: &mut dyn FnMut(),
) -> Paired {
    match median_ns(group, id, since) {
        Some(_) => paired(first, second),
        None => Paired::NONE,
    }
}

/// The ratio of the times of `second` and `first`, measured in pairs: in each of [`ROUNDS`]
/// rounds a block of calls of each, back to back (which goes first alternates), each block
/// about 50 µs. A slower moment of the machine slows both blocks of a round, where criterion
/// measures one function for seconds, then the other; but on a shared machine a busy moment
/// can slow one kind of code more than another (the forward dynamics' chain of dependent
/// operations and the dense path's independent ones), so the ratio of the fastest blocks is
/// given too.
#[allow(dead_code)] // not every benchmark measures in pairs
pub fn paired(first: &mut dyn FnMut(), second: &mut dyn FnMut()) -> Paired {
    let time = |f: &mut dyn FnMut(), calls: usize| {
        let t = std::time::Instant::now();
        for _ in 0..calls {
            f();
        }
        t.elapsed().as_secs_f64()
    };
    let once = time(first, 100) / 100.0;
    let calls = ((50e-6 / once) as usize).max(1);
    let (mut fastest_a, mut fastest_b) = (f64::INFINITY, f64::INFINITY);
    let mut ratios: Vec<f64> = (0..ROUNDS)
        .map(|r| {
            let (a, b) = if r % 2 == 0 {
                let a = time(first, calls);
                (a, time(second, calls))
            } else {
                let b = time(second, calls);
                (time(first, calls), b)
            };
            fastest_a = fastest_a.min(a);
            fastest_b = fastest_b.min(b);
            b / a
        })
        .collect();
    ratios.sort_by(f64::total_cmp);
    Paired {
        quartiles: [
            ratios[ROUNDS / 4],
            ratios[ROUNDS / 2],
            ratios[3 * ROUNDS / 4],
        ],
        fastest: fastest_b / fastest_a,
    }
}
