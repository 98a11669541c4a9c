//! dpend (MODELS.md, chaotic, E(0) = 0) over 1000 s, energy at outputs every 0.5 s: the
//! implicit midpoint rule at a fixed h = 1e-2 s has no secular drift (a line fitted to
//! E(t) moves over the run less than ten times the rms oscillation of E about it, and the
//! largest |E − E0| over 1000 s is less than twice that of the first 100 s), DOPRI5 at rtol
//! 1e-6 drifts (a steady climb, 90 times its oscillation, ten times larger at 1000 s than at
//! 100 s; trend, sign and size printed).

use crate::support::{Work, all_finite, check_work, fit_line, work};
use mbs::{Options, Output, Scheme, Trajectory, simulate};
use mbs_models::dpend::DoublePendulum;
use std::time::Instant;

const T_END: f64 = 1000.0;

/// Largest |E − E0| up to time `upto` (J).
fn deviation(tr: &Trajectory, upto: f64) -> f64 {
    let e0 = tr.energy[0].total();
    tr.t.iter()
        .zip(&tr.energy)
        .filter(|(t, _)| **t <= upto)
        .map(|(_, e)| (e.total() - e0).abs())
        .fold(0.0, f64::max)
}

/// (slope of E(t) in J/s, its standard error (outputs taken as independent), residual
/// spread in J, largest |E − E0| in J)
fn trend(tr: &Trajectory) -> (f64, f64, f64, f64) {
    let e: Vec<f64> = tr.energy.iter().map(|x| x.total()).collect();
    let (_, slope, spread) = fit_line(&tr.t, &e);
    let n = tr.len() as f64;
    let mt = tr.t.iter().sum::<f64>() / n;
    let stt: f64 = tr.t.iter().map(|t| (t - mt) * (t - mt)).sum();
    let deviation = e.iter().map(|x| (x - e[0]).abs()).fold(0.0, f64::max);
    (slope, spread / stt.sqrt(), spread, deviation)
}

#[test]
fn dpend_over_1000_s_midpoint_has_no_energy_drift_and_dopri5_drifts() {
    let out = Output::Every { dt: 0.5 };
    let mut snapshots: Vec<(String, Work)> = Vec::new();
    // m g l = 9.81 J is the scale of dpend's energies (E ranges over ±2.5 m g l)
    let clock = Instant::now();
    let o = Options {
        output: out.clone(),
        ..Options::fixed(T_END, 1e-2)
    };
    let (tr, st) = simulate(DoublePendulum::default(), Scheme::ImplicitMidpoint, o).unwrap();
    let elapsed = clock.elapsed();
    assert!(all_finite(&tr) && tr.t[tr.len() - 1] == T_END);
    let (slope, se, spread, dev) = trend(&tr);
    println!(
        "midpoint h 1e-2: {} steps in {:.0} ms; E(t) − E0: trend {slope:+.2e} J/s (± {se:.1e}), {:+.2e} J over 1000 s; oscillation about the trend {spread:.2e} J (rms), largest |E − E0| {dev:.2e} J",
        st.steps,
        elapsed.as_secs_f64() * 1e3,
        slope * T_END
    );
    let early = deviation(&tr, 100.0);
    println!("    largest |E − E0|: {early:.2e} J over the first 100 s, {dev:.2e} J over 1000 s");
    // no secular drift: the deviation does not grow with the length of the run, and the
    // fitted line stays within a few oscillations. The trajectory is chaotic, so the line
    // wanders with the last bits of the start: from the declared start and eleven others
    // 1e-13 to 1.1e-12 rad away, its move over 1000 s was 0.2 to 6.1 times the rms
    // oscillation, of either sign (above 1 for 9 of the 12); DOPRI5's climb is 90 times
    assert!((slope * T_END).abs() < 10.0 * spread, "midpoint drifts");
    assert!(
        dev < 0.3 && dev < 2.0 * early,
        "bounded: {early} then {dev}"
    );
    snapshots.push(("midpoint h 1e-2".into(), work(&st)));

    let clock = Instant::now();
    let o = Options {
        output: out,
        ..Options::adaptive(T_END, 1e-6)
    };
    let (tr, st) = simulate(DoublePendulum::default(), Scheme::Dopri5, o).unwrap();
    let elapsed = clock.elapsed();
    assert!(all_finite(&tr));
    let (slope, se, spread, dev) = trend(&tr);
    println!(
        "dopri5 rtol 1e-6: {} steps in {:.0} ms; E(t) − E0: trend {slope:+.2e} J/s (± {se:.1e}), {:+.2e} J over 1000 s; oscillation about the trend {spread:.2e} J (rms), largest |E − E0| {dev:.2e} J",
        st.steps,
        elapsed.as_secs_f64() * 1e3,
        slope * T_END
    );
    let early = deviation(&tr, 100.0);
    println!("    largest |E − E0|: {early:.2e} J over the first 100 s, {dev:.2e} J over 1000 s");
    // a secular drift: a climb many standard errors from zero that outgrows the oscillation
    // (89 times) and a deviation that grows with the length of the run (11 times)
    assert!(
        slope > 100.0 * se && slope * T_END > 50.0 * spread,
        "DOPRI5: trend {slope:e} ± {se:e} J/s, oscillation {spread:e} J"
    );
    assert!(dev > 8.0 * early, "DOPRI5: {early} then {dev}");
    snapshots.push(("dopri5 rtol 1e-6".into(), work(&st)));
    check_work(
        "dpend 1000 s",
        &snapshots,
        &[
            [
                100000, 0, 0, 0, 100001, 1, 830869, 0, 37156, 719401, 719401, 1,
            ], // midpoint h 1e-2
            [37916, 7975, 0, 0, 275348, 0, 0, 0, 0, 0, 0, 0], // dopri5 rtol 1e-6
        ],
    );
}
