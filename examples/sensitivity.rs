//! Parameter sensitivities of the sprung arm (`models/src/sprung_arm.rs`, three parameters
//! marked `sensitive`): how its equilibrium moves with them (`static_sensitivity`) and its
//! poles (`pole_sensitivity`), then
//! dq(t)/dp integrated with the motion (`mbs::Sensitivities`) by three schemes, against
//! central differences of plain runs, and what they cost: steps, evaluations and CPU time
//! with and without (best of 5 runs each).
//!
//! ```text
//! cargo run --release --example sensitivity
//! ```

use mbs::analysis::{StaticsOptions, pole_sensitivity, static_equilibrium, static_sensitivity};
use mbs::{
    Model, Options, Output, Parameters, Scheme, Sensitivities, StepControl, Trajectory, simulate,
};
use mbs_models::sprung_arm::SprungArm;
use std::time::{Duration, Instant};

fn options(rtol: f64) -> Options {
    Options {
        t_end: 2.0,
        step: StepControl::Adaptive {
            rtol,
            atol: rtol * 1e-2,
            h0: None,
        },
        output: Output::Last,
        ..Options::default()
    }
}

fn with(name: &str, value: f64) -> SprungArm {
    let mut model = SprungArm::default();
    let mut p = model.params().clone();
    p.set(name, value).expect("a parameter");
    model.set_params(p).expect("valid");
    model
}

/// The best wall time of 5 runs, and the last run's outputs and work.
fn timed<M: Model + 'static>(
    make: impl Fn() -> M,
    scheme: Scheme,
    rtol: f64,
) -> (Duration, Trajectory, mbs::Stats) {
    let mut best = Duration::MAX;
    let mut last = None;
    for _ in 0..5 {
        let model = make();
        let start = Instant::now();
        let r = simulate(model, scheme, options(rtol)).expect("run");
        best = best.min(start.elapsed());
        last = Some(r);
    }
    let (tr, stats) = last.expect("five runs");
    (best, tr, stats)
}

fn main() {
    let model = SprungArm::default();
    let statics = StaticsOptions::default();
    let eq = static_equilibrium(&model, &statics).expect("equilibrium");
    let s = static_sensitivity(&model, &eq, &statics).expect("sensitivity");
    println!(
        "equilibrium q = [{:.6}, {:.6}]; dq/dp (exact, from the generated ∂τ/∂p):",
        eq.q[0], eq.q[1]
    );
    for p in &s.params {
        println!(
            "  ∂q/∂{p:<3} = [{:>12.8}, {:>12.8}]",
            s.get(0, p).unwrap_or(f64::NAN),
            s.get(1, p).unwrap_or(f64::NAN)
        );
    }

    // how the poles move along the equilibria: dλ/dp from the left and right eigenvectors
    let poles = pole_sensitivity(&model, &eq, &statics).expect("pole sensitivity");
    println!("poles at the equilibrium and their sensitivities (exact, generated M', C', K'):");
    for (i, mode) in poles.modes.modes.iter().enumerate() {
        println!(
            "  mode {i}: f = {:.4} Hz, ζ = {:.4}",
            mode.frequency_hz, mode.damping_ratio
        );
        for p in &poles.params {
            let (dre, dim) = poles.dpole(i, p).unwrap_or((f64::NAN, f64::NAN));
            println!(
                "    d/d{p:<3}: dλ = {dre:>11.6} {:+.6}i 1/s,  df = {:>10.6} Hz,  dζ = {:>10.6}",
                dim,
                poles.dfrequency(i, p).unwrap_or(f64::NAN),
                poles.ddamping(i, p).unwrap_or(f64::NAN)
            );
        }
    }

    // dq(2 s)/dp by central differences of plain runs at rtol 1e-12
    let base = model.params().values();
    let mut reference = Vec::new();
    for (j, name) in SprungArm::SENSITIVE.iter().enumerate() {
        let e = 1e-5 * base[j];
        let end = |m: SprungArm| {
            let (tr, _) = simulate(m, Scheme::Dopri5, options(1e-12)).expect("run");
            tr.q(tr.len() - 1).to_vec()
        };
        let (qp, qm) = (end(with(name, base[j] + e)), end(with(name, base[j] - e)));
        reference.push([(qp[0] - qm[0]) / (2.0 * e), (qp[1] - qm[1]) / (2.0 * e)]);
    }
    println!(
        "\ndq(t = 2 s)/dp for {} at rtol 1e-8 (motion and sensitivities under one error control), best of 5:",
        SprungArm::SENSITIVE.join(", ")
    );
    println!(
        "{:>8} {:>12} {:>8} {:>8} {:>11} {:>11} {:>10}",
        "scheme", "max error", "steps", "steps", "evals", "evals", "CPU"
    );
    println!(
        "{:>8} {:>12} {:>8} {:>8} {:>11} {:>11} {:>10}",
        "", "vs diffs", "plain", "+sens", "plain", "+sens", "ratio"
    );
    for scheme in [
        Scheme::Dopri5,
        Scheme::Radau5,
        Scheme::Bdf(Default::default()),
    ] {
        let (t_plain, _, plain) = timed(SprungArm::default, scheme, 1e-8);
        let (t_sens, tr, sens) = timed(
            || Sensitivities::new(SprungArm::default()).expect("sensitive parameters"),
            scheme,
            1e-8,
        );
        let last = tr.len() - 1;
        let mut worst: f64 = 0.0;
        for (j, r) in reference.iter().enumerate() {
            let sq = Sensitivities::<SprungArm>::dq_dp(&tr, last, j);
            let scale = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (a, b) in sq.iter().zip(r) {
                worst = worst.max((a - b).abs() / scale);
            }
        }
        let evals = |s: &mbs::Stats| s.dynamics + s.forward_dynamics + s.inverse_dynamics;
        println!(
            "{:>8} {:>12.1e} {:>8} {:>8} {:>11} {:>11} {:>9.1}x",
            scheme.name(),
            worst,
            plain.steps,
            sens.steps,
            evals(&plain),
            evals(&sens),
            t_sens.as_secs_f64() / t_plain.as_secs_f64()
        );
    }
}
