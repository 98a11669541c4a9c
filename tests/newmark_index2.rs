//! The Newmark family (generalized-α, HHT, trapezoidal Newmark) on the stabilized index-2
//! form (Arnold, Brüls & Cardona): observed orders of q, qd and λ at fixed steps on Cash's
//! pendulum (`pendulum3` of MODELS.md), Φ = 0 and Φ̇ = 0 at every output, no allocation per
//! step, a work-counter snapshot, and which error test each method runs (what rtol means for
//! every scheme and method is measured in `tests/tolerance_proportionality.rs`).

#[path = "common/alloc.rs"]
mod alloc;
mod common;
#[path = "common/quoted.rs"]
mod quoted;

use common::constraint_residuals;

use mbs::{
    ConstraintMethod, ErrorTest, GenAlphaParams, HhtParams, NewmarkParams, Options, Output, Scheme,
    Simulation, Stats, simulate,
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
    let mut lowest = f64::INFINITY;
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
        let asserted = if lambda { min(&ol) } else { f64::INFINITY };
        lowest = lowest.min(min(&oq)).min(min(&ov)).min(asserted);
    }
    // the README's status row: q and λ of order 2 at index 3, and so q, qd and λ at index 2
    quoted::says(
        "README.md",
        &[format!(
            "of order {lowest:.0} at index 3, q, qd and λ at index 2 (`cargo test --release \
             --test newmark_index2"
        )],
    );
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
        let sim = Simulation::new(Pendulum3::default(), scheme, o).expect("simulation");
        alloc::assert_no_allocation(sim, scheme.name());
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

/// 1641 steps (the start needs a few tiny ones: a₀ = qdd₀ leaves an O(h) error in a), 5 τ
/// per step (2 Newton iterations and a matrix of 3 τ), 16 constraint evaluations per step
/// (Φ, B, Φ_t per iteration; B(q₀); for the matrix B, ∂(Bᵀλ)/∂q and Z = ∂(B qd + Φ_t)/∂q
/// by differences: Φ_t and, per coordinate, B and Φ_t; B of the accepted state for the
/// loops' watch), one M per step for the singular-configuration watch
const SNAPSHOT: [usize; 10] = [1641, 14, 0, 2, 1641, 8246, 26369, 1659, 3285, 3281];

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
