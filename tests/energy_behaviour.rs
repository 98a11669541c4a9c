//! Long runs: implicit midpoint and Newmark (¼, ½) keep the energy of a linear oscillator
//! bounded over 10⁴ periods; DOPRI5 at rtol 1e-4 lets it drift (a measured trend).

use mbs::{NewmarkParams, Options, Output, Scheme, Trajectory, simulate};

mbs::multibody! {
    /// A linear oscillator: 1 kg on a spring of 4π² N/m (period 1 s).
    pub model Oscillator {
        param k = 39.47841760435743;
        dof x = 1.0;
        body mass { mass = 1.0; }
        TOG[mass] = Tdisp(1 + x, 0, 0);
        spring(ground, mass, k = k, l0 = 1, axis = x);
    }
}

const PERIODS: f64 = 1e4;

fn deviation(tr: &Trajectory, upto: f64) -> f64 {
    let e0 = tr.energy[0].total();
    tr.t.iter()
        .zip(&tr.energy)
        .filter(|(t, _)| **t <= upto)
        .map(|(_, e)| (e.total() - e0).abs() / e0)
        .fold(0.0, f64::max)
}

#[test]
fn symmetric_schemes_keep_the_energy_bounded_and_dopri5_drifts() {
    let out = Output::Every { dt: 100.0 };
    for scheme in [
        Scheme::ImplicitMidpoint,
        Scheme::Newmark(NewmarkParams::default()),
    ] {
        let opts = Options {
            output: out.clone(),
            ..Options::fixed(PERIODS, 1.0 / 20.0)
        };
        let (tr, _) = simulate(Oscillator::default(), scheme, opts).unwrap();
        let (early, late) = (deviation(&tr, PERIODS / 10.0), deviation(&tr, PERIODS));
        println!(
            "{:<9} energy deviation: {early:.2e} over 10³ periods, {late:.2e} over 10⁴",
            scheme.name()
        );
        // bounded at the level of rounding over the whole run (these schemes conserve the
        // energy of a linear oscillator exactly, up to round-off)
        assert!(late < 1e-10, "{}", scheme.name());
    }
    let opts = Options {
        output: out,
        ..Options::adaptive(PERIODS, 1e-4)
    };
    let (tr, st) = simulate(Oscillator::default(), Scheme::Dopri5, opts).unwrap();
    let (early, late) = (deviation(&tr, PERIODS / 10.0), deviation(&tr, PERIODS));
    println!(
        "dopri5    energy deviation: {early:.2e} over 10³ periods, {late:.2e} over 10⁴ ({} steps)",
        st.steps
    );
    // a secular drift: the deviation grows with the length of the run, about linearly
    assert!(
        late > 5.0 * early && late > 1e-3,
        "DOPRI5: {early:e}, {late:e}"
    );
}
