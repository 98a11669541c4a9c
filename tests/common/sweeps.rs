//! What the sweeps of every scheme and every analysis share: a silent panic report, and the
//! check of every failure's message.
#![allow(dead_code)] // each test binary uses a part

/// The most significant digits of any number in `text` (leading zeros not counted): a
/// message's numbers should read like the ones a user types (`short`, ten digits at most),
/// not like the 17 digits of a round trip.
pub fn longest_number(text: &str) -> usize {
    text.split(|c: char| !c.is_ascii_digit())
        .map(|run| run.trim_start_matches('0').len())
        .max()
        .unwrap_or(0)
}

/// Runs `f` with the default panic report silenced on this thread (a sweep catches the
/// panics it looks for; the report would only repeat them). One hook for the whole binary:
/// the tests run in parallel, and a hook taken and restored by each could leave another's
/// silent one behind, which would then swallow an assertion's message.
pub fn silenced<T>(f: impl FnOnce() -> T) -> T {
    use std::cell::Cell;
    static HOOK: std::sync::Once = std::sync::Once::new();
    thread_local!(static QUIET: Cell<bool> = const { Cell::new(false) });
    HOOK.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(|q| q.get()) {
                default(info)
            }
        }));
    });
    QUIET.with(|q| q.set(true));
    let out = f();
    QUIET.with(|q| q.set(false));
    out
}

/// `catch_unwind` of `f` with the panic report [`silenced`].
pub fn quiet_catch<T>(f: impl FnOnce() -> T) -> std::thread::Result<T> {
    silenced(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)))
}

/// The values a parameter of default `v` is swept over: zero, its opposite, a millionth and a
/// million times it, ±1e300, 1e-300, then NaN and infinity (the last two, which `set_params`
/// refuses, last: the first `PARAMETER_EDGES_FINITE` are finite).
pub fn parameter_edges(v: f64) -> [f64; 9] {
    [
        0.0,
        -v,
        1e-6 * v,
        1e6 * v,
        1e300,
        -1e300,
        1e-300,
        f64::NAN,
        f64::INFINITY,
    ]
}

/// How many of [`parameter_edges`] are finite (they come first).
pub const PARAMETER_EDGES_FINITE: usize = 7;

/// `model` with some parameters set (valid values of known names).
pub fn with_params<M: mbs::Model>(mut model: M, values: &[(&str, f64)]) -> M {
    use mbs::Parameters;
    let mut p = model.params().clone();
    for &(name, value) in values {
        p.set(name, value).expect("a known parameter");
    }
    model.set_params(p).expect("valid values");
    model
}
