//! seed2dof at 5 steps per period of its 1 Hz mode (h = 0.2 s) for 1000 periods:
//! generalized-α (ρ∞ = 0.8) stays bounded, damps its 10 Hz mode, and lets its 1 Hz mode decay
//! at the rate of the spectral radius of Chung & Hulbert's amplification matrix (the theory
//! `tests/spectral.rs` checks over 120 steps); RK4 at that step stops with `UnstableStep`
//! before any non-finite value, and its stability edge for the 10 Hz mode lies between
//! h = 0.044 s (1000 periods, bounded) and 0.046 s (refused).

use crate::common::{gen_alpha_characteristic, seed2dof_modes};
use crate::support::{Work, all_finite, check_work, fit_line, work};
use mbs::{Failure, GenAlphaParams, Options, Output, Scheme, Trajectory, simulate};
use mbs_models::seed2dof::Seed2dof;

/// Chung & Hulbert's amplification matrix of generalized-α on ẍ = −ω²x (state d, v, a, with
/// h = 1 and ω = wh): its spectral radius, from the characteristic polynomial (the largest
/// root in modulus, by Durand–Kerner), as in `tests/spectral.rs`.
fn spectral_radius(p: &GenAlphaParams, wh: f64) -> f64 {
    let c = gen_alpha_characteristic(p.alpha_m, p.alpha_f, p.beta, p.gamma, wh);
    // its roots (Durand–Kerner on complex pairs (re, im)); the largest in modulus
    let mul = |a: (f64, f64), b: (f64, f64)| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let div = |a: (f64, f64), b: (f64, f64)| {
        let d = b.0 * b.0 + b.1 * b.1;
        ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    };
    let eval = |x: (f64, f64)| {
        c.iter().fold((1.0, 0.0), |acc, &k| {
            let y = mul(acc, x);
            (y.0 + k, y.1)
        })
    };
    let mut z: Vec<(f64, f64)> = (0..3)
        .map(|k| {
            let a = 0.4 + 0.9 * k as f64;
            (0.9 * a.cos(), 0.9 * a.sin())
        })
        .collect();
    for _ in 0..500 {
        for i in 0..3 {
            let mut den = (1.0, 0.0);
            for j in 0..3 {
                if i != j {
                    den = mul(den, (z[i].0 - z[j].0, z[i].1 - z[j].1));
                }
            }
            let d = div(eval(z[i]), den);
            z[i] = (z[i].0 - d.0, z[i].1 - d.1);
        }
    }
    z.iter().map(|r| r.0.hypot(r.1)).fold(0.0, f64::max)
}

/// Energy of mode k at every output: ½(η̇² + ω²η²), η = v_kᵀq (M = I).
fn modal_energy(tr: &Trajectory, k: usize) -> Vec<f64> {
    let (w, v) = seed2dof_modes();
    (0..tr.len())
        .map(|i| {
            let (q, qd) = (tr.q(i), tr.qd(i));
            let eta = v[k][0] * q[0] + v[k][1] * q[1];
            let rate = v[k][0] * qd[0] + v[k][1] * qd[1];
            0.5 * (rate * rate + w[k] * w[k] * eta * eta)
        })
        .collect()
}

#[test]
fn seed2dof_five_steps_per_period_gen_alpha_decays_as_theory_and_rk4_is_refused() {
    let (w, _) = seed2dof_modes();
    let h = 0.2;
    let steps = 5020; // 1000.1 periods of the 0.996 Hz mode
    let t_end = h * steps as f64;
    let p = GenAlphaParams::from_rho_inf(0.8);
    let mut snapshots: Vec<(String, Work)> = Vec::new();

    let opts = Options {
        output: Output::Steps,
        ..Options::fixed(t_end, h)
    };
    let (tr, st) = simulate(Seed2dof::default(), Scheme::GenAlpha(p), opts).unwrap();
    snapshots.push(("gen-alpha ρ∞ 0.8, h 0.2".into(), work(&st)));
    assert!(all_finite(&tr));
    assert_eq!(tr.len(), steps + 1);
    let e0 = tr.energy[0].total();
    let e_max = tr.energy.iter().map(|e| e.total()).fold(0.0, f64::max);
    assert!(
        e_max <= e0 * (1.0 + 1e-12),
        "bounded: E max/E0 = {}",
        e_max / e0
    );

    let (rho1, rho2) = (spectral_radius(&p, w[0] * h), spectral_radius(&p, w[1] * h));
    let (e1, e2) = (modal_energy(&tr, 0), modal_energy(&tr, 1));
    // the 10 Hz mode (ωh = 12.6, ρ₂ = 0.916, near ρ∞): its amplitude falls as ρ₂ⁿ down to
    // the rounding of q (the modes of this linear system do not mix)
    let after = |n: usize| (e2[n] / e2[0]).sqrt();
    println!(
        "gen-α, h = 0.2: 10 Hz mode ρ theory {rho2:.6}; amplitude after 20, 100, 200 steps {:.2e}, {:.2e}, {:.2e} (ρ₂ⁿ {:.2e}, {:.2e}, {:.2e}); after 1000 periods {:.1e}",
        after(20),
        after(100),
        after(200),
        rho2.powi(20),
        rho2.powi(100),
        rho2.powi(200),
        after(steps)
    );
    for n in [20, 100, 200] {
        let ratio = after(n) / rho2.powi(n as i32);
        assert!(
            (0.5..2.0).contains(&ratio),
            "10 Hz mode after {n} steps: {ratio}"
        );
    }
    assert!(after(steps) < 1e-13);
    // the 1 Hz mode: the slope of ln E₁ against the step number is 2 ln ρ₁
    let n: Vec<f64> = (0..tr.len()).map(|i| i as f64).collect();
    let ln_e1: Vec<f64> = e1.iter().map(|e| e.ln()).collect();
    let (_, slope, spread) = fit_line(&n, &ln_e1);
    let rho1_measured = (0.5 * slope).exp();
    let amplitude = (e1[steps] / e1[0]).sqrt();
    println!(
        "gen-α, h = 0.2: 1 Hz mode ρ theory {rho1:.7}, measured {rho1_measured:.7} (ln E₁ fit, residual {spread:.1e}); amplitude after 1000 periods {amplitude:.3e}, theory ρ₁^{steps} = {:.3e}",
        rho1.powi(steps as i32)
    );
    assert!(rho1 < 1.0 && (rho1_measured / rho1 - 1.0).abs() < 1e-6);
    assert!((amplitude / rho1.powi(steps as i32)).ln().abs() < 0.1);

    // RK4 at the same step: refused with the stable step, the trajectory before it finite
    let e = simulate(Seed2dof::default(), Scheme::Rk4, Options::fixed(t_end, h)).unwrap_err();
    snapshots.push(("rk4 h 0.2 (UnstableStep)".into(), work(&e.stats)));
    println!("rk4, h = 0.2: {e}; {} outputs kept", e.trajectory.len());
    let h_advised = match e.kind {
        Failure::UnstableStep { h_stable, .. } => h_stable,
        ref other => panic!("{other}"),
    };
    assert!(h_advised < h && all_finite(&e.trajectory) && e.t == 0.0);
    // the estimate of the fastest mode is iterated to 0.1 % before a refusal: the advised
    // step is just inside the stability region (2.785/ω₂ = 0.04425 s) and runs bounded
    assert!((0.0440..0.0443).contains(&h_advised), "{h_advised}");
    let (tr, st) = simulate(
        Seed2dof::default(),
        Scheme::Rk4,
        Options {
            output: Output::Every { dt: 1.0 },
            ..Options::fixed(t_end, h_advised)
        },
    )
    .unwrap();
    snapshots.push(("rk4 at the advised step".into(), work(&st)));
    let e0 = tr.energy[0].total();
    let e_max = tr.energy.iter().map(|e| e.total()).fold(0.0, f64::max);
    println!(
        "rk4, h = {h_advised:.5} (advised): {} steps, E max/E0 {:.6}",
        st.steps,
        e_max / e0
    );
    assert!(all_finite(&tr) && e_max <= e0 * (1.0 + 1e-9));

    // the edge 2√2/ω₂ = 0.0449 s on the imaginary axis (the runtime refuses past 2.785/ρ)
    let opts = |h| Options {
        output: Output::Every { dt: 1.0 },
        ..Options::fixed(t_end, h)
    };
    let (tr, st) = simulate(Seed2dof::default(), Scheme::Rk4, opts(0.044)).unwrap();
    snapshots.push(("rk4 h 0.044".into(), work(&st)));
    let e0 = tr.energy[0].total();
    let e_max = tr.energy.iter().map(|e| e.total()).fold(0.0, f64::max);
    println!(
        "rk4, h = 0.044 (ω₂h = {:.3} < 2√2): {} steps, E max/E0 {:.6}, E end/E0 {:.3e}",
        w[1] * 0.044,
        st.steps,
        e_max / e0,
        tr.energy[tr.len() - 1].total() / e0
    );
    assert!(all_finite(&tr) && e_max <= e0 * (1.0 + 1e-9));
    let e = simulate(Seed2dof::default(), Scheme::Rk4, opts(0.046)).unwrap_err();
    snapshots.push(("rk4 h 0.046 (UnstableStep)".into(), work(&e.stats)));
    println!("rk4, h = 0.046 (ω₂h = {:.3}): {e}", w[1] * 0.046);
    assert!(matches!(e.kind, Failure::UnstableStep { .. }));
    assert!(all_finite(&e.trajectory));

    check_work(
        "seed2dof",
        &snapshots,
        &[
            [5020, 0, 0, 0, 1, 5021, 10044, 0, 1, 10041, 10041, 5021], // gen-alpha ρ∞ 0.8, h 0.2
            [0, 0, 0, 0, 7, 0, 0, 0, 0, 0, 0, 0],                      // rk4 h 0.2 (UnstableStep)
            [22692, 0, 0, 0, 102461, 0, 0, 0, 0, 0, 0, 0],             // rk4 at the advised step
            [22819, 0, 0, 0, 102745, 0, 0, 0, 0, 0, 0, 0],             // rk4 h 0.044
            [0, 0, 0, 0, 7, 0, 0, 0, 0, 0, 0, 0],                      // rk4 h 0.046 (UnstableStep)
        ],
    );
}
