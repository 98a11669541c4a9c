//! Parameter sensitivities of the sprung arm (`models/src/sprung_arm.rs`, three parameters
//! marked `sensitive`): how its equilibrium moves with them (`static_sensitivity`) and its
//! poles (`pole_sensitivity`), then
//! dq(t)/dp integrated with the motion (`mbs::Sensitivities`) by three schemes, against
//! central differences of plain runs, and what they cost: steps, evaluations and CPU time
//! with and without (best of 5 runs each). Then the same for a closed loop, the four-bar of
//! `models/src/fourbar.rs` with four sensitive parameters: its equilibrium and multipliers,
//! and its motion's sensitivities with their drift from the constraints' derivatives.
//!
//! ```text
//! cargo run --release --example sensitivity
//! ```

use mbs::analysis::{StaticsOptions, pole_sensitivity, static_equilibrium, static_sensitivity};
use mbs::{
    Model, Options, Output, Parameters, Scheme, Sensitivities, StepControl, Trajectory, simulate,
};
use mbs_models::fourbar::SensitiveFourBar;
use mbs_models::sprung_arm::SprungArm;
use std::time::{Duration, Instant};

fn options(t_end: f64, rtol: f64) -> Options {
    Options {
        t_end,
        step: StepControl::Adaptive {
            rtol,
            atol: rtol * 1e-2,
            h0: None,
        },
        output: Output::Last,
        ..Options::default()
    }
}

/// The default model with parameter `name` set to `value`.
fn with<M: Model + Default>(name: &str, value: f64) -> M {
    let mut model = M::default();
    let mut p = model.params().clone();
    p.set(name, value).expect("a parameter");
    model.set_params(p).expect("valid");
    model
}

/// The default value of parameter `name`.
fn param<M: Model + Default>(name: &str) -> f64 {
    let i = <M::Params as Parameters>::NAMES
        .iter()
        .position(|n| *n == name)
        .expect("a parameter");
    M::default().params().values()[i]
}

/// The best wall time of 5 runs, and the last run's outputs and work.
fn timed<M: Model + 'static>(
    make: impl Fn() -> M,
    scheme: Scheme,
    t_end: f64,
    rtol: f64,
) -> (Duration, Trajectory, mbs::Stats) {
    let mut best = Duration::MAX;
    let mut last = None;
    for _ in 0..5 {
        let model = make();
        let start = Instant::now();
        let r = simulate(model, scheme, options(t_end, rtol)).expect("run");
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
    print_poles(&poles);

    motion::<SprungArm>(2.0);

    // a closed loop: the equilibrium moves on the constraints, and the multipliers with it
    let model = SensitiveFourBar::default();
    let eq = static_equilibrium(&model, &statics).expect("equilibrium");
    let s = static_sensitivity(&model, &eq, &statics).expect("sensitivity");
    println!(
        "\nfour-bar with a crank spring: equilibrium q = [{:.6}, {:.6}, {:.6}], λ = [{:.6}, {:.6}]; dq/dp and dλ/dp (exact, from ∂τ/∂p, ∂Φ/∂p and ∂(Bᵀλ)/∂p):",
        eq.q[0], eq.q[1], eq.q[2], eq.lambda[0], eq.lambda[1]
    );
    for (j, p) in s.params.iter().enumerate() {
        println!(
            "  ∂q/∂{p:<3} = [{:>12.8}, {:>12.8}, {:>12.8}]   ∂λ/∂{p:<3} = [{:>12.6}, {:>12.6}]",
            s.get(0, p).unwrap_or(f64::NAN),
            s.get(1, p).unwrap_or(f64::NAN),
            s.get(2, p).unwrap_or(f64::NAN),
            s.dlambda_dp[2 * j],
            s.dlambda_dp[2 * j + 1]
        );
    }
    let poles = pole_sensitivity(&model, &eq, &statics).expect("pole sensitivity");
    println!(
        "its poles on the constraint manifold and their sensitivities (exact, generated B', K_λ' too):"
    );
    print_poles(&poles);
    motion::<SensitiveFourBar>(1.0);
}

/// Each mode and its dλ/dp, df/dp and dζ/dp.
fn print_poles(poles: &mbs::analysis::PoleSensitivity) {
    for (i, mode) in poles.modes.modes.iter().enumerate() {
        println!(
            "  mode {i}: f = {:.4} Hz, ζ = {:.4}, nearest other pole {:.2e} of its size away",
            mode.frequency_hz, mode.damping_ratio, poles.separation[i]
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
}

/// dq(t_end)/dp of `M`'s default motion by three schemes at rtol 1e-8 against central
/// differences of plain runs at rtol 1e-12, with the work and CPU time of each (best of 5);
/// on closed loops also the largest drift of the sensitivities from B s + ∂Φ/∂p = 0.
fn motion<M: Model + Default + 'static>(t_end: f64) {
    let mut reference = Vec::new();
    for name in M::SENSITIVE {
        let p0 = param::<M>(name);
        let e = 1e-5 * p0;
        let end = |m: M| {
            let (tr, _) = simulate(m, Scheme::Dopri5, options(t_end, 1e-12)).expect("run");
            tr.q(tr.len() - 1).to_vec()
        };
        let (qp, qm) = (end(with(name, p0 + e)), end(with(name, p0 - e)));
        let d: Vec<f64> = qp
            .iter()
            .zip(&qm)
            .map(|(a, b)| (a - b) / (2.0 * e))
            .collect();
        reference.push(d);
    }
    println!(
        "\n{}: dq(t = {t_end} s)/dp for {} at rtol 1e-8 (the error test the largest of the motion's and each parameter's sensitivities' norms), best of 5:",
        M::default().info().name,
        M::SENSITIVE.join(", ")
    );
    let drift = if M::NC > 0 { "drift" } else { "" };
    println!(
        "{:>8} {:>12} {:>8} {:>8} {:>11} {:>11} {:>10} {:>9}",
        "scheme", "max error", "steps", "steps", "evals", "evals", "CPU", drift
    );
    println!(
        "{:>8} {:>12} {:>8} {:>8} {:>11} {:>11} {:>10} {:>9}",
        "",
        "vs diffs",
        "plain",
        "+sens",
        "plain",
        "+sens",
        "ratio",
        if M::NC > 0 { "|Bs+Φp|" } else { "" }
    );
    for scheme in [
        Scheme::Dopri5,
        Scheme::Radau5,
        Scheme::Bdf(Default::default()),
    ] {
        let (t_plain, _, plain) = timed(M::default, scheme, t_end, 1e-8);
        let wrap = || Sensitivities::new(M::default()).expect("sensitive parameters");
        let (t_sens, tr, sens) = timed(wrap, scheme, t_end, 1e-8);
        let last = tr.len() - 1;
        let mut worst: f64 = 0.0;
        for (j, r) in reference.iter().enumerate() {
            let sq = Sensitivities::<M>::dq_dp(&tr, last, j);
            let scale = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (a, b) in sq.iter().zip(r) {
                worst = worst.max((a - b).abs() / scale);
            }
        }
        let evals = |s: &mbs::Stats| s.dynamics + s.forward_dynamics + s.inverse_dynamics;
        let drift = if M::NC > 0 {
            let drift = wrap().residuals(&tr, last).map_or(f64::NAN, |r| r.0);
            format!("{drift:.1e}")
        } else {
            String::new()
        };
        println!(
            "{:>8} {:>12.1e} {:>8} {:>8} {:>11} {:>11} {:>9.1}x {:>9}",
            scheme.name(),
            worst,
            plain.steps,
            sens.steps,
            evals(&plain),
            evals(&sens),
            t_sens.as_secs_f64() / t_plain.as_secs_f64(),
            drift
        );
    }
}
