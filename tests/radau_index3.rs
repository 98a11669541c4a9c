//! Radau IIA at index 3 on the pendulum in Cartesian coordinates (pendulum3): positions,
//! velocities and the multiplier λ at t = 1 against the reference, the invariants, and the
//! observed orders with fixed steps against the theory of Radau IIA for index-3 DAEs (Hairer,
//! Lubich & Roche 1989; Jay 1993; Hairer & Wanner II, §VII.4): with s stages the positions
//! converge with order 2s − 1, the velocities with order s and λ with order s − 1.
//!
//! What is measured (`cargo test --release --test radau_index3 -- --nocapture` prints it):
//! fixed steps give those orders (Radau5: 5.0, 3.0, 2.0; Radau3: 2.8–2.9, 2.0, 1.0, its
//! positions approaching 3 slowly, in the differences of successive runs too). The velocity and
//! λ errors are local: at t = 1 they are those of the last step (C·h^s and C·h^(s−1)), and the
//! step control, which weights velocity errors by h and λ errors by h² as RADAU5 does for
//! index-2 and index-3 components, does not aim at them. So λ within 1e-6 takes steps below
//! about 2e-3 for Radau5 (here bounded by `h_max`), and is practically out of reach for
//! Radau3: its λ is first order (about 0.12h) while λ's rounding noise grows as ε/h², so
//! 1e-6 is met only near h = 1e-5 (80 000 fixed steps: 8.9e-7; 160 000: 3.6e-5, noise). The
//! invariant ẋ² + ẏ² − λ − y is λ's error and follows it, not rtol; x ẋ + y ẏ follows the
//! velocity error of the last step.

use mbs::{ConstraintMethod, Options, Output, Scheme, Simulation, Stats, Trajectory, simulate};
use mbs_models::pendulum3;
use pendulum3::Pendulum3;
#[path = "common/alloc.rs"]
mod alloc;
mod common;
#[path = "common/quoted.rs"]
mod quoted;
use common::{fixed, with_method};

/// (x, y, ẋ, ẏ, λ) at t = 1 from `tests/reference/pendulum3.json`.
fn reference() -> [f64; 5] {
    let path = format!(
        "{}/tests/reference/pendulum3.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    assert_eq!(json["t"].as_f64(), Some(1.0));
    let s = &json["state"];
    let v = |k: &str| s[k].as_f64().unwrap_or_else(|| panic!("state.{k}"));
    [v("x"), v("y"), v("xd"), v("yd"), v("lam")]
}

fn run(scheme: Scheme, o: Options, method: ConstraintMethod) -> ([f64; 5], Stats) {
    let (tr, st) = match simulate(Pendulum3::default(), scheme, with_method(o, method)) {
        Ok(r) => r,
        Err(e) => panic!("{}: {e}", scheme.name()),
    };
    (last(&tr), st)
}

fn index3(scheme: Scheme, o: Options) -> ([f64; 5], Stats) {
    run(scheme, o, ConstraintMethod::Index3)
}

/// The final state (x, y, ẋ, ẏ, λ) of a run.
fn last(tr: &Trajectory) -> [f64; 5] {
    let i = tr.len() - 1;
    assert_eq!(tr.t[i], 1.0);
    let (q, qd, l) = (tr.q(i), tr.qd(i), tr.lambda(i));
    [q[0], q[1], qd[0], qd[1], l[0]]
}

/// Errors of q, qd and λ against the reference (max over the components).
fn errors(s: &[f64; 5], r: &[f64; 5]) -> [f64; 3] {
    let d = |i: usize| (s[i] - r[i]).abs();
    [d(0).max(d(1)), d(2).max(d(3)), d(4)]
}

/// |1 − x² − y²|, |x ẋ + y ẏ|, |ẋ² + ẏ² − λ − y|.
fn invariants(s: &[f64; 5]) -> [f64; 3] {
    let [x, y, xd, yd, l] = *s;
    [
        (1.0 - x * x - y * y).abs(),
        (x * xd + y * yd).abs(),
        (xd * xd + yd * yd - l - y).abs(),
    ]
}

fn print_row(label: &str, s: &[f64; 5], st: &Stats) -> ([f64; 3], [f64; 3]) {
    let (e, inv) = (errors(s, &reference()), invariants(s));
    println!(
        "{label:<27} {:>8.1e} {:>8.1e} {:>8.1e} | {:>8.1e} {:>8.1e} {:>8.1e} | {:>5} {:>3}/{:<3} {:>6} {:>5} {:>5}",
        e[0],
        e[1],
        e[2],
        inv[0],
        inv[1],
        inv[2],
        st.steps,
        st.rejected_error,
        st.rejected_newton,
        st.evaluations(),
        st.newton_iterations,
        st.factorizations
    );
    (e, inv)
}

fn print_header() {
    println!(
        "{:<27} {:>8} {:>8} {:>8} | {:>8} {:>8} {:>8} | {:>5} {:>7} {:>6} {:>5} {:>5}",
        "run",
        "err q",
        "err qd",
        "err λ",
        "1−x²−y²",
        "xẋ+yẏ",
        "v²−λ−y",
        "steps",
        "rej e/N",
        "evals",
        "newt",
        "fact"
    );
}

/// Adaptive Radau5 at index 3: q, qd and λ within 1e-6 of the reference at t = 1, the
/// position and velocity invariants within 10·rtol; λ (second order, not aimed at by the
/// step control) needs steps below about 2e-3 for 1e-6.
#[test]
fn adaptive_radau5_reaches_the_reference() {
    print_header();
    let rtol = 1e-10;
    let (s, st) = index3(Scheme::Radau5, Options::adaptive(1.0, rtol));
    let (e, inv) = print_row("radau5 rtol 1e-10", &s, &st);
    assert!(e[0] < 1e-9 && e[1] < 1e-6, "{e:?}");
    let mut quotes = vec![format!(
        "index 3: {} steps, {} evaluations, q within {:.1e}, λ within {:.1e}",
        st.steps,
        quoted::thousands(st.evaluations()),
        e[0],
        e[2]
    )];
    assert!(inv[0] <= 10.0 * rtol && inv[1] <= 10.0 * rtol, "{inv:?}");
    // λ: second order, about 0.2 h² at the last steps
    assert!(e[2] < 2e-4 && inv[2] < 2e-4, "{e:?} {inv:?}");
    // with steps bounded by 1.5e-3, λ within 1e-6 too
    let o = Options {
        h_max: 1.5e-3,
        ..Options::adaptive(1.0, rtol)
    };
    let (s, st) = index3(Scheme::Radau5, o);
    let (e, inv) = print_row("radau5 rtol 1e-10 h≤1.5e-3", &s, &st);
    assert!(e.iter().all(|&x| x < 1e-6), "{e:?}");
    assert!(inv[0] <= 10.0 * rtol && inv[1] <= 10.0 * rtol, "{inv:?}");
    assert!(inv[2] < 1e-6, "{inv:?}");
    // `Auto` takes Radau by projection (index 3 only on request): λ of the index-1 form at
    // the projected state, as accurate as q and qd
    let (auto, st) = run(
        Scheme::Radau5,
        Options::adaptive(1.0, rtol),
        ConstraintMethod::Auto,
    );
    let (e, _) = print_row("radau5 rtol 1e-10 (Auto)", &auto, &st);
    assert!(st.projections > 0);
    assert!(e.iter().all(|&x| x < 1e-8), "{e:?}");
    quotes.push(format!(
        "projection: {} steps, {} evaluations",
        st.steps,
        quoted::thousands(st.evaluations())
    ));
    quoted::says("README.md", &quotes);
}

/// Adaptive Radau3 at index 3: q and qd within 1e-6; λ is first order, within 1e-3.
#[test]
fn adaptive_radau3_reaches_the_reference_in_q_and_qd() {
    print_header();
    let rtol = 1e-8;
    let (s, st) = index3(Scheme::Radau3, Options::adaptive(1.0, rtol));
    let (e, inv) = print_row("radau3 rtol 1e-8", &s, &st);
    assert!(e[0] < 1e-8 && e[1] < 1e-6, "{e:?}");
    assert!(inv[0] <= 10.0 * rtol && inv[1] <= 1e-6, "{inv:?}");
    assert!(e[2] < 2e-3 && inv[2] < 2e-3, "{e:?} {inv:?}");
}

/// Observed orders with fixed steps h = 1/k, k doubling: log2 of successive error ratios.
fn orders(scheme: Scheme, ks: &[u32]) -> Vec<[f64; 3]> {
    let r = reference();
    println!(
        "{:<7} {:>6} {:>10} {:>10} {:>10} | {:>5} {:>5} {:>5} | {:>6} {:>5}",
        "scheme", "h", "err q", "err qd", "err λ", "p q", "p qd", "p λ", "evals", "newt"
    );
    let mut prev: Option<[f64; 3]> = None;
    let mut out = Vec::new();
    for &k in ks {
        let (s, st) = index3(scheme, fixed(k));
        let e = errors(&s, &r);
        let p = prev.map(|pe| [0, 1, 2].map(|i| (pe[i] / e[i]).log2()));
        let f = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2}"));
        println!(
            "{:<7} {:>6} {:>10.3e} {:>10.3e} {:>10.3e} | {:>5} {:>5} {:>5} | {:>6} {:>5}",
            scheme.name(),
            format!("1/{k}"),
            e[0],
            e[1],
            e[2],
            f(p.map(|p| p[0])),
            f(p.map(|p| p[1])),
            f(p.map(|p| p[2])),
            st.evaluations(),
            st.newton_iterations
        );
        if let Some(p) = p {
            out.push(p);
        }
        prev = Some(e);
    }
    out
}

/// Radau5 (s = 3): q of order 5, qd of order 3, λ of order 2. The positions are measured
/// at larger steps, where their errors stay above the reference's accuracy (~1e-11).
#[test]
fn radau5_fixed_step_orders_are_five_three_two() {
    let p = orders(Scheme::Radau5, &[5, 10, 20, 40, 80, 160]);
    let last = p.last().expect("orders");
    assert!(
        p[..3].iter().all(|p| (4.8..5.3).contains(&p[0])),
        "q: {p:?}"
    );
    assert!((2.85..3.15).contains(&last[1]), "qd: {p:?}");
    assert!((1.9..2.1).contains(&last[2]), "λ: {p:?}");
}

/// Radau3 (s = 2): q of order 3, qd of order 2, λ of order 1. The positions approach their
/// order slowly (2.8 to 2.9 from h = 1/80 to 1/640, in the differences of successive runs
/// too, so not an artefact of the reference).
#[test]
fn radau3_fixed_step_orders_are_three_two_one() {
    let p = orders(Scheme::Radau3, &[20, 40, 80, 160, 320, 640]);
    let last = p.last().expect("orders");
    assert!(
        p[1..].iter().all(|p| (2.7..3.2).contains(&p[0])),
        "q: {p:?}"
    );
    assert!((1.9..2.1).contains(&last[1]), "qd: {p:?}");
    assert!((0.9..1.1).contains(&last[2]), "λ: {p:?}");
}

/// No allocation per step at index 3 either: the augmented buffers are made in `start`.
#[test]
fn index3_steps_allocate_nothing_after_warm_up() {
    for scheme in [Scheme::Radau3, Scheme::Radau5] {
        for base in [Options::fixed(100.0, 1e-2), Options::adaptive(100.0, 1e-8)] {
            let o = Options {
                output: Output::Every { dt: 0.01 },
                ..with_method(base, ConstraintMethod::Index3)
            };
            let sim = Simulation::new(Pendulum3::default(), scheme, o)
                .unwrap_or_else(|e| panic!("{}: {e}", scheme.name()));
            alloc::assert_no_allocation(sim, scheme.name());
        }
    }
}

/// `Stats::error_test` says what rtol controls: at index 3 Radau weights velocities by h and
/// λ by h², the Newmark family estimates positions only, fixed steps test nothing.
#[test]
fn stats_name_the_components_the_error_test_controls() {
    use mbs::{ErrorTest, GenAlphaParams};
    let adaptive = Options::adaptive(1.0, 1e-6);
    let test = |scheme, o: &Options, method| run(scheme, o.clone(), method).1.error_test;
    assert_eq!(
        test(Scheme::Radau5, &adaptive, ConstraintMethod::Index3),
        ErrorTest::PositionsScaledVelocities
    );
    assert_eq!(
        test(Scheme::Radau5, &adaptive, ConstraintMethod::Projection),
        ErrorTest::PositionsVelocities
    );
    assert_eq!(
        test(Scheme::Dopri5, &adaptive, ConstraintMethod::Projection),
        ErrorTest::PositionsVelocities
    );
    let gen_alpha = Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8));
    assert_eq!(
        test(gen_alpha, &adaptive, ConstraintMethod::Index3),
        ErrorTest::Positions
    );
    assert_eq!(
        test(Scheme::Radau5, &fixed(100), ConstraintMethod::Index3),
        ErrorTest::None
    );
}
