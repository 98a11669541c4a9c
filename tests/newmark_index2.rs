//! The Newmark family (generalized-α, HHT, trapezoidal Newmark) on the stabilized index-2
//! form (Arnold, Brüls & Cardona): observed orders of q, qd and λ at fixed steps on Cash's
//! pendulum (`pendulum3` of MODELS.md), Φ = 0 and Φ̇ = 0 at every output, no allocation per
//! step, a work-counter snapshot, and what rtol means: the mixed error over (q, qd) of the
//! family, with every constraint method its documentation offers, against rtol.

#[path = "common/alloc.rs"]
mod alloc;

use mbs::work_precision::mixed_error;
use mbs::{
    ConstraintMethod, ErrorTest, GenAlphaParams, HhtParams, Integrator, Model, NewmarkParams,
    Options, Output, Scheme, Simulation, Stats, Trajectory, simulate,
};
use mbs_models::{pendulum3, slidercrank};
use pendulum3::Pendulum3;

fn gen_alpha(rho: f64) -> Scheme {
    Scheme::GenAlpha(GenAlphaParams::from_rho_inf(rho))
}
fn hht() -> Scheme {
    Scheme::Hht(HhtParams::default())
}
fn newmark() -> Scheme {
    Scheme::Newmark(NewmarkParams::default())
}

fn json(name: &str) -> serde_json::Value {
    let path = format!("{}/tests/reference/{name}.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("reference file");
    serde_json::from_str(&text).expect("reference JSON")
}

/// (x, y, ẋ, ẏ, λ) of pendulum3 at t = 1.
fn pendulum3_reference() -> [f64; 5] {
    let s = &json("pendulum3")["state"];
    ["x", "y", "xd", "yd", "lam"].map(|k| s[k].as_f64().expect("reference value"))
}

fn with(mut o: Options, method: ConstraintMethod) -> Options {
    o.constraints.method = method;
    o.energy = false;
    o
}

/// |Δq|, |Δqd|, |Δλ| (max norms) of pendulum3 at t = 1 with fixed steps h at index 2.
fn pendulum3_errors(scheme: Scheme, h: f64) -> [f64; 3] {
    let o = with(Options::fixed(1.0, h), ConstraintMethod::Index2);
    let (t, _) = simulate(Pendulum3::default(), scheme, o).expect("pendulum3 runs");
    let k = t.len() - 1;
    assert!((t.t[k] - 1.0).abs() < 1e-12);
    let r = pendulum3_reference();
    let (q, v, l) = (t.q(k), t.qd(k), t.lambda(k)[0]);
    [
        (q[0] - r[0]).abs().max((q[1] - r[1]).abs()),
        (v[0] - r[2]).abs().max((v[1] - r[3]).abs()),
        (l - r[4]).abs(),
    ]
}

#[test]
fn index2_is_second_order_in_q_qd_and_lambda() {
    let hs = [8e-3, 4e-3, 2e-3, 1e-3];
    let cases = [
        ("gen-alpha ρ∞ 0.5", gen_alpha(0.5), true),
        ("gen-alpha ρ∞ 0.8", gen_alpha(0.8), true),
        ("hht α −0.05", hht(), true),
        // ρ∞ = 1: nothing damps λ's start-up error (as at index 3)
        ("newmark (¼, ½)", newmark(), false),
    ];
    for (name, scheme, lambda) in cases {
        let e: Vec<[f64; 3]> = hs.iter().map(|&h| pendulum3_errors(scheme, h)).collect();
        let order =
            |k: usize| -> Vec<f64> { e.windows(2).map(|w| (w[0][k] / w[1][k]).log2()).collect() };
        let (oq, ov, ol) = (order(0), order(1), order(2));
        println!(
            "{name}: |Δq| {:.2e} → {:.2e}, orders q {oq:.2?} qd {ov:.2?} λ {ol:.2?}",
            e[0][0], e[3][0]
        );
        let min = |o: &[f64]| o.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(min(&oq) >= 1.7, "{name}: q orders {oq:?}");
        assert!(min(&ov) >= 1.7, "{name}: qd orders {ov:?}");
        if lambda {
            assert!(min(&ol) >= 1.7, "{name}: λ orders {ol:?}");
        }
    }
}

/// Largest |Φ_i| and |Φ̇_i| = |B qd + Φ_t| over the outputs of a trajectory.
fn constraint_residuals<M: Model>(m: &M, t: &Trajectory) -> (f64, f64) {
    let (n, nc) = (M::NQ, M::NC);
    let (mut phi, mut b, mut phi_t) = (vec![0.0; nc], vec![0.0; nc * n], vec![0.0; nc]);
    let (mut worst, mut worst_rate) = (0.0f64, 0.0f64);
    for k in 0..t.len() {
        let (tk, q, qd) = (t.t[k], t.q(k), t.qd(k));
        m.constraints(tk, q, &mut phi);
        m.constraint_jacobian(tk, q, &mut b);
        m.constraint_rate(tk, q, &mut phi_t);
        for i in 0..nc {
            let rate = phi_t[i] + (0..n).map(|j| b[i + nc * j] * qd[j]).sum::<f64>();
            worst = worst.max(phi[i].abs());
            worst_rate = worst_rate.max(rate.abs());
        }
    }
    (worst, worst_rate)
}

#[test]
fn positions_and_velocities_satisfy_the_constraints_at_every_output() {
    for scheme in [gen_alpha(0.8), hht()] {
        for step in [Options::fixed(1.0, 1e-3), Options::adaptive(1.0, 1e-6)] {
            let o = Options {
                output: Output::Steps,
                ..with(step, ConstraintMethod::Index2)
            };
            let m = Pendulum3::default();
            let (t, _) = simulate(m.clone(), scheme, o).expect("pendulum3 runs");
            let (phi, rate) = constraint_residuals(&m, &t);
            println!(
                "pendulum3 {}: max |Φ| {phi:.1e}, max |Φ̇| {rate:.1e}",
                scheme.name()
            );
            // the constraint tolerance (1e-11; |Φ̇| per unit of the largest |qd| ≥ 1)
            assert!(phi <= 1e-11 && rate <= 1e-11, "|Φ| {phi:e}, |Φ̇| {rate:e}");
        }
    }
    let m = slidercrank::SliderCrank::default();
    let o = Options {
        output: Output::Steps,
        ..with(Options::adaptive(0.5, 1e-5), ConstraintMethod::Index2)
    };
    let (t, _) = simulate(m.clone(), gen_alpha(0.8), o).expect("slider-crank runs");
    let (phi, rate) = constraint_residuals(&m, &t);
    let vmax = (0..t.len())
        .flat_map(|k| t.qd(k).iter().map(|x| x.abs()))
        .fold(1.0f64, f64::max);
    println!("slider-crank: max |Φ| {phi:.1e}, max |Φ̇| {rate:.1e} (max |qd| {vmax:.1})");
    assert!(
        phi <= 1e-11 && rate <= 1e-11 * vmax,
        "|Φ| {phi:e}, |Φ̇| {rate:e}"
    );
}

#[test]
fn index2_steps_allocate_nothing_after_warm_up() {
    for (scheme, base) in [
        (gen_alpha(0.8), Options::adaptive(100.0, 1e-7)),
        (hht(), Options::fixed(100.0, 1e-3)),
        (newmark(), Options::fixed(100.0, 1e-3)),
    ] {
        let o = Options {
            output: Output::Every { dt: 0.01 },
            ..with(base, ConstraintMethod::Index2)
        };
        let mut sim = Simulation::new(Pendulum3::default(), scheme, o).expect("simulation");
        for _ in 0..20 {
            sim.step().expect("step");
        }
        let before = alloc::allocations();
        for _ in 0..200 {
            sim.step().expect("step");
        }
        let allocated = alloc::allocations() - before;
        assert_eq!(
            allocated,
            0,
            "{} allocated {allocated} times",
            scheme.name()
        );
    }
}

/// steps, rejected by the error test, by Newton, M+h, M, τ, constraint evaluations,
/// factorisations, solves, Newton iterations
fn counts(s: &Stats) -> [usize; 10] {
    [
        s.steps,
        s.rejected_error,
        s.rejected_newton,
        s.dynamics,
        s.mass_matrix,
        s.inverse_dynamics,
        s.constraints,
        s.factorizations,
        s.solves,
        s.newton_iterations,
    ]
}

#[test]
fn work_counters_of_an_adaptive_index2_run() {
    // pendulum3 to t = 1 at rtol 1e-6, gen-α ρ∞ 0.8 (exact tangents: a fresh scaled matrix
    // per step, one τ per Newton iteration plus one for the matrix)
    let o = Options {
        output: Output::Last,
        ..with(Options::adaptive(1.0, 1e-6), ConstraintMethod::Index2)
    };
    let (_, stats) = simulate(Pendulum3::default(), gen_alpha(0.8), o).expect("runs");
    let got = counts(&stats);
    println!("{got:?}\n{stats}");
    assert_eq!(stats.error_test, ErrorTest::PositionsVelocities);
    assert_eq!(got, SNAPSHOT);
}

/// 2007 steps (the start needs a few tiny ones: a₀ = qdd₀ leaves an O(h) error in a), 5 τ
/// per step (2 Newton iterations and a matrix of 3 τ), 15 constraint evaluations per step
/// (Φ, B, Φ_t per iteration; B(q₀); for the matrix B, ∂(Bᵀλ)/∂q and Z = ∂(B qd + Φ_t)/∂q
/// by differences: Φ_t and, per coordinate, B and Φ_t), one M per step for the
/// singular-configuration watch
const SNAPSHOT: [usize; 10] = [2007, 12, 0, 2, 2007, 10048, 30136, 2023, 3995, 3991];

/// Digits of the mixed error over (q, qd) (floor 0.01) at the end of a run, minus −log10 rtol
/// ("short": positive when the run falls short of rtol).
fn short<M: Model + Clone + 'static>(
    m: &M,
    scheme: Scheme,
    method: Option<ConstraintMethod>,
    t_end: f64,
    rtol: f64,
    reference: &[f64],
) -> f64 {
    let mut o = Options {
        output: Output::Last,
        energy: false,
        ..Options::adaptive(t_end, rtol)
    };
    if let Some(method) = method {
        o.constraints.method = method;
    }
    let (t, _) = simulate(m.clone(), scheme, o).expect("runs");
    let k = t.len() - 1;
    assert!((t.t[k] - t_end).abs() < 1e-12);
    let y: Vec<f64> = t.q(k).iter().chain(t.qd(k)).copied().collect();
    -rtol.log10() + mixed_error(&y, reference, 0.01).log10()
}

/// Within 1 digit of rtol, and never more than 0.2 digits lost when rtol tightens a decade.
fn assert_follows_rtol(what: &str, shorts: &[f64]) {
    println!("{what}: short by {shorts:.2?} digits at rtol 1e-4, 1e-5, …");
    assert!(shorts.iter().all(|s| s.abs() <= 1.0), "{what}: {shorts:?}");
    assert!(
        shorts.windows(2).all(|w| w[1] - w[0] <= 0.2),
        "{what}: {shorts:?}"
    );
}

/// (θ, ψ, s, θ̇, ψ̇, ṡ) of the slider-crank, form (a), at t = 2 from form (b) (θ alone, the
/// loop in closed form) by DOPRI5 at rtol 1e-13.
fn slidercrank_reference() -> Vec<f64> {
    let o = Options {
        output: Output::Last,
        energy: false,
        step: mbs::StepControl::Adaptive {
            rtol: 1e-13,
            atol: 1e-15,
            h0: None,
        },
        ..Options::adaptive(2.0, 1e-13)
    };
    let (t, _) = simulate(slidercrank::SliderCrankClosed::default(), Scheme::Dopri5, o)
        .expect("form (b) runs");
    let k = t.len() - 1;
    let (th, thd) = (t.q(k)[0], t.qd(k)[0]);
    let (r, l) = (0.1, 0.3);
    let (psi, s) = slidercrank::closed_loop(th);
    let psid = -r * th.cos() * thd / (l * psi.cos());
    let sd = -r * th.sin() * thd - l * psi.sin() * psid;
    vec![th, psi, s, thd, psid, sd]
}

#[test]
fn the_mixed_error_follows_rtol_at_index2() {
    let index2 = Some(ConstraintMethod::Index2);
    let r = pendulum3_reference();
    let m = Pendulum3::default();
    for scheme in [gen_alpha(0.8), hht()] {
        let s: Vec<f64> = [1e-4, 1e-5, 1e-6, 1e-7]
            .iter()
            .map(|&rtol| short(&m, scheme, index2, 1.0, rtol, &r[..4]))
            .collect();
        assert_follows_rtol(&format!("pendulum3 {}", scheme.name()), &s);
    }
    let r = slidercrank_reference();
    let m = slidercrank::SliderCrank::default();
    for scheme in [gen_alpha(0.8), hht()] {
        let s: Vec<f64> = [1e-4, 1e-5, 1e-6]
            .iter()
            .map(|&rtol| short(&m, scheme, index2, 2.0, rtol, &r))
            .collect();
        assert_follows_rtol(&format!("slider-crank (a) {}", scheme.name()), &s);
    }
}

#[test]
fn the_error_test_covers_velocities_at_index2_only() {
    let test = |scheme, method| {
        let o = with(Options::adaptive(1.0, 1e-5), method);
        simulate(Pendulum3::default(), scheme, o)
            .expect("runs")
            .1
            .error_test
    };
    let (i2, i3, proj) = (
        ConstraintMethod::Index2,
        ConstraintMethod::Index3,
        ConstraintMethod::Projection,
    );
    assert_eq!(test(gen_alpha(0.8), i2), ErrorTest::PositionsVelocities);
    assert_eq!(test(hht(), i2), ErrorTest::PositionsVelocities);
    assert_eq!(test(gen_alpha(0.8), i3), ErrorTest::Positions);
    assert_eq!(test(gen_alpha(0.8), proj), ErrorTest::Positions);
    // without numerical damping, adaptive index 2 is refused (λ oscillates on fast loops)
    let o = with(Options::adaptive(1.0, 1e-5), i2);
    let e = simulate(Pendulum3::default(), newmark(), o).expect_err("refused");
    assert!(
        matches!(e.kind, mbs::Failure::ConstraintsUnsupported { .. }),
        "{e}"
    );
}
