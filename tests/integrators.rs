//! Integrators on the canonical models: observed orders, failures as values, outputs.

mod common;
#[path = "../examples/models/seed2dof.rs"]
mod seed2dof;

use common::*;
use mbs::{GenAlphaParams, HhtParams, NewmarkParams, Options, Output, Scheme, simulate};
use seed2dof::Seed2dof;

/// Period of the 10 Hz mode.
fn t2() -> f64 {
    2.0 * std::f64::consts::PI / seed2dof_modes().0[1]
}

fn fixed_run(scheme: Scheme, h: f64, t_end: f64) -> f64 {
    let opts = Options {
        output: Output::Every { dt: t_end / 50.0 },
        energy: false,
        ..Options::fixed(t_end, h)
    };
    let (tr, _) = simulate(Seed2dof::default(), scheme, opts).unwrap();
    seed2dof_max_error(&tr)
}

/// Observed order by halving h three times: the log–log slope of error against h.
fn observed_order(scheme: Scheme, h0: f64, t_end: f64) -> f64 {
    let hs: Vec<f64> = (0..4).map(|k| h0 / 2f64.powi(k)).collect();
    let errs: Vec<f64> = hs.iter().map(|&h| fixed_run(scheme, h, t_end)).collect();
    let p = loglog_slope(&hs, &errs);
    println!("{:<10} errors {errs:.3?} → order {p:.2}", scheme.name());
    p
}

#[test]
fn fixed_step_orders_on_seed2dof() {
    let t2 = t2();
    let cases = [
        (Scheme::ExplicitEuler, t2 / 2000.0, 0.2),
        (Scheme::Rk4, t2 / 40.0, 1.0),
        (Scheme::Dopri5, t2 / 20.0, 1.0),
        (Scheme::Newmark(NewmarkParams::default()), t2 / 40.0, 1.0),
        (Scheme::Hht(HhtParams { alpha: -0.1 }), t2 / 40.0, 1.0),
        (
            Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8)),
            t2 / 40.0,
            1.0,
        ),
        (Scheme::ImplicitMidpoint, t2 / 40.0, 1.0),
    ];
    for (scheme, h0, t_end) in cases {
        let p = observed_order(scheme, h0, t_end);
        let theory = scheme.order() as f64;
        assert!(
            (p - theory).abs() <= 0.3,
            "{}: observed order {p:.2}, theory {theory}",
            scheme.name()
        );
    }
}

/// Error against the number of steps when tightening rtol: slope ≈ −order.
fn adaptive_slope(scheme: Scheme, rtols: &[f64]) -> f64 {
    let mut steps = Vec::new();
    let mut errs = Vec::new();
    for &rtol in rtols {
        let opts = Options {
            output: Output::Every { dt: 0.02 },
            energy: false,
            ..Options::adaptive(1.0, rtol)
        };
        let (tr, st) = simulate(Seed2dof::default(), scheme, opts).unwrap();
        steps.push(st.steps as f64);
        errs.push(seed2dof_max_error(&tr));
    }
    let p = -loglog_slope(&steps, &errs);
    println!(
        "{:<10} steps {steps:?} errors {errs:.3?} → order {p:.2}",
        scheme.name()
    );
    p
}

#[test]
fn adaptive_orders_on_seed2dof() {
    for (scheme, rtols) in [
        (Scheme::Dopri5, [1e-5, 1e-6, 1e-7, 1e-8]),
        (
            Scheme::Newmark(NewmarkParams::default()),
            [1e-4, 1e-5, 1e-6, 1e-7],
        ),
        (
            Scheme::GenAlpha(GenAlphaParams::default()),
            [1e-4, 1e-5, 1e-6, 1e-7],
        ),
        (Scheme::Hht(HhtParams::default()), [1e-4, 1e-5, 1e-6, 1e-7]),
    ] {
        let p = adaptive_slope(scheme, &rtols);
        let theory = scheme.order() as f64;
        assert!(
            (p - theory).abs() <= 0.3,
            "{}: observed order {p:.2} vs {theory}",
            scheme.name()
        );
    }
}
