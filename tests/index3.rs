//! The Newmark family at index 3 (Arnold & Brüls 2007) on Cash's pendulum (`pendulum3` of
//! MODELS.md): accuracy at t = 1 against the reference, the three invariants, the observed
//! orders of q and λ, the λ oscillation of the undamped member (Cardona & Géradin 1989), the
//! condition of the iteration matrix with and without the scaling of Bottasso, Dopico &
//! Trainelli (2008), work counters. (No allocation per step: `tests/no_alloc.rs`.)

mod common;
#[path = "common/quoted.rs"]
mod quoted;

use mbs::integrators::index3_iteration_matrix;
use mbs::{
    ConstraintMethod, GenAlphaParams, Model, NewmarkParams, Options, Output, Scheme, State, Stats,
    simulate,
};
use mbs_models::pendulum3;
use pendulum3::Pendulum3;

/// (x, y, ẋ, ẏ, λ) at t = 1 from tests/reference/pendulum3.json.
fn reference() -> [f64; 5] {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/pendulum3.json"
    );
    let text = std::fs::read_to_string(path).expect("reference file");
    let r: serde_json::Value = serde_json::from_str(&text).expect("reference JSON");
    let s = &r["state"];
    ["x", "y", "xd", "yd", "lam"].map(|k| s[k].as_f64().expect("reference value"))
}

fn gen_alpha(rho: f64) -> Scheme {
    Scheme::GenAlpha(GenAlphaParams::from_rho_inf(rho))
}

/// Fixed steps h to t = 1 at index 3 with full Newton (a fresh matrix per iteration is not
/// needed; `reuse = false` only removes the tolerance of modified Newton from the orders).
fn run_fixed(scheme: Scheme, h: f64) -> (mbs::Trajectory, Stats) {
    let mut o = Options::fixed(1.0, h);
    o.constraints.method = ConstraintMethod::Index3;
    o.energy = false;
    simulate(Pendulum3::default(), scheme, o).expect("pendulum3 runs")
}

/// |x − x_ref|, |v − v_ref|, |λ − λ_ref| (max norms) and the three invariants at output `k`.
fn errors(t: &mbs::Trajectory, k: usize) -> ([f64; 3], [f64; 3]) {
    let r = reference();
    let (q, v, l) = (t.q(k), t.qd(k), t.lambda(k)[0]);
    let e = [
        (q[0] - r[0]).abs().max((q[1] - r[1]).abs()),
        (v[0] - r[2]).abs().max((v[1] - r[3]).abs()),
        (l - r[4]).abs(),
    ];
    (e, invariants(q, v, l))
}

/// 1 − x² − y², x ẋ + y ẏ, ẋ² + ẏ² − λ − y: zero on the exact solution.
fn invariants(q: &[f64], v: &[f64], l: f64) -> [f64; 3] {
    [
        1.0 - q[0] * q[0] - q[1] * q[1],
        q[0] * v[0] + q[1] * v[1],
        v[0] * v[0] + v[1] * v[1] - l - q[1],
    ]
}

#[test]
fn pendulum3_at_t1_with_generalized_alpha() {
    // h = 1 ms, ρ∞ = 0.8: second order, so the error is ~0.2 h² per unit time
    let tol = 1e-6;
    let (traj, stats) = run_fixed(gen_alpha(0.8), 1e-3);
    let k = traj.len() - 1;
    assert!((traj.t[k] - 1.0).abs() < 1e-12);
    let (e, inv) = errors(&traj, k);
    println!(
        "gen-α ρ∞ 0.8, h 1e-3: |Δq| {:.2e} |Δv| {:.2e} |Δλ| {:.2e}",
        e[0], e[1], e[2]
    );
    println!(
        "invariants: position {:.1e}, velocity {:.1e}, acceleration {:.1e}\n{stats}",
        inv[0], inv[1], inv[2]
    );
    assert!(e.iter().all(|&x| x < tol), "errors {e:?}");
    // positions hold the constraint to the Newton tolerance; velocities and λ to O(h²)
    assert!(inv[0].abs() < 1e-10);
    assert!(
        inv.iter().all(|x| x.abs() <= 10.0 * tol),
        "invariants {inv:?}"
    );
    // along the whole run, not only at the end
    let worst = (0..traj.len())
        .map(|i| invariants(traj.q(i), traj.qd(i), traj.lambda(i)[0])[0].abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-10, "max |Φ| along the run {worst:e}");
    quoted::says(
        "README.md",
        &[format!(
            "pendulum3 at t = 1 within {} (gen-α, h = 1 ms)",
            bound(e.iter().copied().fold(0.0, f64::max))
        )],
    );
}

/// `x` rounded up to one significant digit, as a bound: 5.34e-7 → "6e-7".
fn bound(x: f64) -> String {
    let mut exponent = x.log10().floor() as i32;
    let mut digit = (x / 10f64.powi(exponent)).ceil();
    if digit >= 10.0 {
        (digit, exponent) = (1.0, exponent + 1);
    }
    format!("{digit}e{exponent}")
}

/// log2 of successive error ratios over step halvings.
fn orders(errs: &[f64]) -> Vec<f64> {
    errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

#[test]
fn generalized_alpha_index3_is_second_order_in_q_and_lambda() {
    let hs = [8e-3, 4e-3, 2e-3, 1e-3];
    let mut lowest = f64::INFINITY;
    for rho in [0.5, 0.8] {
        let mut eq = Vec::new();
        let mut el = Vec::new();
        for &h in &hs {
            let (traj, _) = run_fixed(gen_alpha(rho), h);
            let (e, _) = errors(&traj, traj.len() - 1);
            eq.push(e[0]);
            el.push(e[2]);
        }
        let (oq, ol) = (orders(&eq), orders(&el));
        let f = |v: &[f64], p: &str| {
            v.iter()
                .map(|x| {
                    if p == "e" {
                        format!("{x:.2e}")
                    } else {
                        format!("{x:.2}")
                    }
                })
                .collect::<Vec<_>>()
                .join(" ")
        };
        println!(
            "ρ∞ {rho}: |Δq| {} (orders {}); |Δλ| {} (orders {})",
            f(&eq, "e"),
            f(&oq, "o"),
            f(&el, "e"),
            f(&ol, "o")
        );
        assert!(oq.iter().all(|&o| o >= 1.9), "q orders {oq:?}");
        assert!(ol.iter().all(|&o| o >= 1.9), "λ orders {ol:?}");
        lowest = oq.iter().chain(&ol).copied().fold(lowest, f64::min);
    }
    quoted::says(
        "README.md",
        &[format!("q and λ of order {lowest:.0} at index 3")],
    );
}

/// At ρ∞ = 1 (no numerical damping) q still converges with order 2, but λ does not: the
/// O(1) error the start leaves in λ and in the accelerations (a₀ = qdd₀ is not the
/// algorithmic acceleration of the exact solution) is never damped and alternates in sign
/// from step to step, whatever h — the oscillation Cardona & Géradin (1989) report for the
/// undamped Newmark rule at index 3. With ρ∞ = 0.8 the same transient dies out in a few
/// steps.
#[test]
fn undamped_members_leave_lambda_oscillating() {
    let inv_at = |t: &mbs::Trajectory, i: usize| invariants(t.q(i), t.qd(i), t.lambda(i)[0])[2];
    for h in [4e-3, 1e-3] {
        for (name, scheme) in [
            ("gen-α ρ∞ 1", gen_alpha(1.0)),
            (
                "trapezoidal Newmark",
                Scheme::Newmark(NewmarkParams::default()),
            ),
            ("gen-α ρ∞ 0.8", gen_alpha(0.8)),
        ] {
            let (traj, _) = run_fixed(scheme, h);
            let k = traj.len() - 1;
            let (e, _) = errors(&traj, k);
            // the acceleration-level invariant measures λ's error along the run; its sign
            // alternates when λ oscillates
            let late: Vec<f64> = (k - 6..=k).map(|i| inv_at(&traj, i)).collect();
            let alternating = late.windows(2).all(|w| w[0] * w[1] < 0.0);
            let amplitude = late.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            println!(
                "{name:20} h {h:.0e}: |Δq| {:.2e}, |Δλ| {:.2e}, late λ error {amplitude:.2e}, alternating {alternating}",
                e[0], e[2]
            );
            if name == "gen-α ρ∞ 0.8" {
                assert!(amplitude < 1e-4 && e[2] < 1e-4);
            } else {
                assert!(e[0] < 1e-4, "q still converges");
                assert!(alternating && amplitude > 0.1 && e[2] > 0.1, "λ oscillates");
            }
        }
    }
}

/// The index-3 iteration matrix at the start of pendulum3 for steps h = 10⁻¹ … 10⁻⁶: 2-norm
/// condition numbers from the singular values, with the constraint rows scaled by 1/β' and
/// without; the slope of log cond against log h.
#[test]
fn scaling_keeps_the_iteration_matrix_conditioned_as_h_shrinks() {
    let model = Pendulum3::default();
    let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
    model.initial_state(&mut q, &mut qd);
    let state = State {
        t: 0.0,
        q: q.to_vec(),
        qd: qd.to_vec(),
        qdd: vec![0.0, -2.0],
        lambda: vec![1.0],
    };
    let n = Pendulum3::NQ + Pendulum3::NC;
    let cond = |h: f64, scaled: bool| {
        let a = index3_iteration_matrix(
            Pendulum3::default(),
            GenAlphaParams::from_rho_inf(0.8),
            h,
            &state,
            scaled,
        )
        .expect("matrix");
        let sv = nalgebra::DMatrix::from_column_slice(n, n, &a).singular_values();
        sv.max() / sv.min()
    };
    let hs: Vec<f64> = (1..=6).map(|k| 10f64.powi(-k)).collect();
    let slope = |c: &[f64]| common::loglog_slope(&hs, c);
    let scaled: Vec<f64> = hs.iter().map(|&h| cond(h, true)).collect();
    let unscaled: Vec<f64> = hs.iter().map(|&h| cond(h, false)).collect();
    println!("{:>8} {:>12} {:>12}", "h", "cond scaled", "unscaled");
    for i in 0..hs.len() {
        println!(
            "{:>8.0e} {:>12.3e} {:>12.3e}",
            hs[i], scaled[i], unscaled[i]
        );
    }
    let (ss, su) = (slope(&scaled), slope(&unscaled));
    println!("log-log slopes: scaled {ss:.3}, unscaled {su:.3}");
    assert!(ss.abs() < 0.5, "scaled slope {ss}");
    assert!(
        su < -1.8,
        "unscaled slope {su}: the condition should grow as h⁻²"
    );
    // the scaled condition as the README writes it: one figure when every h gives it
    let figures: Vec<String> = scaled.iter().map(|c| format!("{c:.2}")).collect();
    let scaled_text = if figures.iter().all(|f| *f == figures[0]) {
        format!("{} throughout", figures[0])
    } else {
        figures.join(", ")
    };
    quoted::says(
        "README.md",
        &[format!(
            "scaled: {scaled_text} (log–log slope {}); unscaled: {:.1e} → {:.1e} (slope {})",
            quoted::minus(format!("{ss:.3}")),
            unscaled[0],
            unscaled[hs.len() - 1],
            quoted::minus(format!("{su:.3}"))
        )],
    );
}

/// The scaled and unscaled matrices give the same steps (scaling changes the conditioning,
/// not the solution) until rounding matters.
#[test]
fn scaling_does_not_change_the_solution() {
    let run = |scaled: bool| {
        let mut o = Options::fixed(1.0, 1e-2);
        o.constraints.method = ConstraintMethod::Index3;
        o.constraints.scaling = scaled;
        o.output = Output::Last;
        simulate(Pendulum3::default(), gen_alpha(0.8), o)
            .expect("runs")
            .0
    };
    let (a, b) = (run(true), run(false));
    let d = (0..2)
        .map(|i| (a.q(0)[i] - b.q(0)[i]).abs())
        .fold(0.0, f64::max);
    println!("h = 1e-2: scaled vs unscaled q differ by {d:.1e}");
    assert!(d < 1e-9);
}

/// Work of one index-3 run (h = 2 ms to t = 1), snapshotted: a fresh iteration matrix per
/// step (modified Newton within the step) by differences of τ (the model has no generated
/// tangents: n + 1 = 3 evaluations), about 1.5 iterations per step (one τ each), and one M
/// per accepted step to watch for a singular configuration (those matrices do not evaluate M).
#[test]
fn work_counters_of_an_index3_run() {
    let (_, s) = run_fixed(gen_alpha(0.8), 2e-3);
    println!("{s}");
    let counts = [
        s.steps,
        s.rejected_newton,
        s.dynamics,
        s.mass_matrix,
        s.inverse_dynamics,
        s.factorizations,
        s.newton_iterations,
    ];
    assert_eq!(counts, [500, 0, 1, 500, 2235, 502, 735], "{s}");
}
