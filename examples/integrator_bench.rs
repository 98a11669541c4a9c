//! What integrating costs beyond the model's equations, and what accuracy costs in time.
//!
//! ```text
//! cargo run --release --example integrator_bench
//! ```
//!
//! 1. Overhead per step: the wall time of a step minus the time of the evaluations it made
//!    (M+h, τ, M, forward dynamics), in units of one M+h evaluation, per scheme, on dpend and on the (contact-free) hexapod,
//!    with fixed steps.
//! 2. dpend over 10 s: the CPU time and evaluations each scheme needs for 6 correct digits at
//!    t = 10 s against `tests/reference/dpend.json`: rtol from 1e-6 to 1e-14, or h halved from
//!    10 ms, until reached within the default budget of 10⁶ steps; dpend is chaotic, and order-1
//!    and order-2 schemes do not reach it within that budget.

use mbs_models::dpend;
use mbs_models::hexapod;

use mbs::{Model, Options, Output, Scheme, Stats, simulate};
use std::hint::black_box;
use std::time::Instant;

fn test_state(n: usize) -> (Vec<f64>, Vec<f64>) {
    (
        (0..n).map(|i| 0.5 * (1.3 * i as f64 + 0.4).sin()).collect(),
        (0..n).map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos()).collect(),
    )
}

/// Seconds per call of `f`, over `reps` calls.
fn per_call(reps: usize, mut f: impl FnMut()) -> f64 {
    let t0 = Instant::now();
    for _ in 0..reps {
        f();
    }
    t0.elapsed().as_secs_f64() / reps as f64
}

/// Seconds per call of M+h, of τ and of forward dynamics at the test state.
fn evaluation_times<M: Model>(model: &M) -> (f64, f64, f64) {
    let n = M::NQ;
    let (q, qd) = test_state(n);
    let (mut m, mut h, mut tau) = (vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
    let (mut qdd, mut pivots) = (vec![0.0; n], vec![0.0; n]);
    let u = vec![0.0; M::NU];
    let reps = 200_000 / n.max(1);
    let (q, qd) = (&q, &qd);
    let t_dyn = per_call(reps, || {
        model.dynamics(0.0, black_box(q), black_box(qd), &u, &mut m, &mut h)
    });
    let t_tau = per_call(reps, || {
        model.inverse_dynamics(
            0.0,
            black_box(q),
            black_box(qd),
            black_box(&h),
            &u,
            &mut tau,
        )
    });
    let t_fwd = per_call(reps, || {
        model.forward_dynamics(0.0, black_box(q), black_box(qd), &u, &mut qdd, &mut pivots)
    });
    (t_dyn, t_tau, t_fwd)
}

fn overhead<M: Model + Clone + 'static>(name: &str, model: M, h: f64, t_end: f64) {
    let (t_dyn, t_tau, t_fwd) = evaluation_times(&model);
    println!(
        "\n{name}: one M+h {:.0} ns, one τ {:.0} ns, one forward dynamics {:.0} ns; fixed step h = {h} s to t = {t_end} s",
        t_dyn * 1e9,
        t_tau * 1e9,
        t_fwd * 1e9
    );
    println!(
        "  {:<10} {:>10} {:>12} {:>10} {:>10} {:>10} {:>22}",
        "scheme", "steps", "µs/step", "M+h/step", "τ/step", "fwd/step", "overhead (M+h units)"
    );
    for scheme in Scheme::all() {
        let opts = Options {
            output: Output::Last,
            energy: false,
            ..Options::fixed(t_end, h)
        };
        let t0 = Instant::now();
        let r = simulate(model.clone(), scheme, opts);
        let wall = t0.elapsed().as_secs_f64();
        match r {
            Ok((_, st)) => {
                let s = st.steps as f64;
                let evals = st.dynamics as f64 * t_dyn
                    + (st.inverse_dynamics + st.mass_matrix) as f64 * t_tau
                    + st.forward_dynamics as f64 * t_fwd;
                let over = (wall - evals) / s / t_dyn;
                println!(
                    "  {:<10} {:>10} {:>12.3} {:>10.2} {:>10.2} {:>10.2} {:>22.2}",
                    scheme.name(),
                    st.steps,
                    wall / s * 1e6,
                    st.dynamics as f64 / s,
                    st.inverse_dynamics as f64 / s,
                    st.forward_dynamics as f64 / s,
                    over
                );
            }
            Err(e) => println!("  {:<10} {}", scheme.name(), e.kind),
        }
    }
}

fn reference_at_10() -> (Vec<f64>, Vec<f64>) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/reference/dpend.json");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("reference file"))
            .expect("json");
    let s = json["states"]
        .as_array()
        .expect("states")
        .iter()
        .find(|s| s["t"].as_f64() == Some(10.0))
        .expect("t = 10")
        .clone();
    let v = |k: &str| {
        s[k].as_array()
            .expect("array")
            .iter()
            .map(|x| x.as_f64().expect("number"))
            .collect()
    };
    (v("q"), v("qd"))
}

fn error_at_10(opts: Options, scheme: Scheme, q: &[f64], qd: &[f64]) -> Option<(f64, Stats, f64)> {
    let t0 = Instant::now();
    let (tr, st) = simulate(dpend::DoublePendulum::default(), scheme, opts).ok()?;
    let cpu = t0.elapsed().as_secs_f64();
    let i = tr.len() - 1;
    let e = tr
        .q(i)
        .iter()
        .zip(q)
        .chain(tr.qd(i).iter().zip(qd))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    Some((e, st, cpu))
}

fn six_digits() {
    let (q, qd) = reference_at_10();
    println!("\ndpend over 10 s, to 6 correct digits at t = 10 s (max error on q, qd < 1e-6):");
    println!(
        "  {:<10} {:>16} {:>10} {:>12} {:>12} {:>10}",
        "scheme", "setting", "error", "steps", "evaluations", "CPU ms"
    );
    for scheme in Scheme::all() {
        let mut best = None;
        if scheme.is_adaptive() {
            for k in 6..=14 {
                let rtol = 10f64.powi(-k);
                let o = Options {
                    output: Output::Last,
                    energy: false,
                    ..Options::adaptive(10.0, rtol)
                };
                if let Some((e, st, cpu)) = error_at_10(o, scheme, &q, &qd) {
                    best = Some((format!("rtol 1e-{k}"), e, st, cpu));
                    if e < 1e-6 {
                        break;
                    }
                }
            }
        } else {
            let mut h = 1e-2;
            while 10.0 / h <= 1e6 {
                let o = Options {
                    output: Output::Last,
                    energy: false,
                    ..Options::fixed(10.0, h)
                };
                if let Some((e, st, cpu)) = error_at_10(o, scheme, &q, &qd) {
                    best = Some((format!("h {h:.1e}"), e, st, cpu));
                    if e < 1e-6 {
                        break;
                    }
                }
                h /= 2.0;
            }
        }
        match best {
            Some((setting, e, st, cpu)) => {
                let note = if e < 1e-6 { "" } else { "  (not reached)" };
                println!(
                    "  {:<10} {:>16} {:>10.2e} {:>12} {:>12} {:>10.1}{note}",
                    scheme.name(),
                    setting,
                    e,
                    st.steps,
                    st.evaluations(),
                    cpu * 1e3
                );
            }
            None => println!("  {:<10} no run succeeded", scheme.name()),
        }
    }
}

fn main() {
    overhead("dpend", dpend::DoublePendulum::default(), 1e-3, 2.0);
    overhead(
        "hexapod (free, no contact)",
        hexapod::Hexapod::default(),
        1e-3,
        0.2,
    );
    six_digits();
}
