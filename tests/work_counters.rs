//! Work counters of one reference run per scheme (dpend, 0 → 2 s), snapshotted: a change that
//! silently doubles the work fails here. Adaptive schemes run at rtol 1e-6 (atol 1e-8); fixed-
//! step ones at h = 2 ms. dpend has no generated tangents, so implicit schemes build their
//! iteration matrix by finite differences (3 evaluations of τ for 2 coordinates).

use mbs_models::dpend;

mod common;
#[path = "common/quoted.rs"]
mod quoted;
use common::work_counts;
use quoted::thousands;

use mbs::{GenAlphaParams, HhtParams, NewmarkParams, Options, Output, Scheme, Stats, simulate};

fn run(scheme: Scheme) -> Stats {
    let opts = if scheme.is_adaptive() {
        Options::adaptive(2.0, 1e-6)
    } else {
        Options::fixed(2.0, 2e-3)
    };
    let opts = Options {
        output: Output::Last,
        energy: false,
        ..opts
    };
    simulate(dpend::DoublePendulum::default(), scheme, opts)
        .unwrap()
        .1
}

#[test]
fn work_counters_of_reference_runs() {
    let cases: [(Scheme, [usize; 10]); 7] = [
        // explicit schemes solve for qdd by the generated forward dynamics: no M, no
        // factorisation. 1000 steps, 1 evaluation each + the start + 2 every 16 steps for the
        // stability check, + 2 per extra power iteration at the first step (2 until the
        // estimate settles)
        (Scheme::ExplicitEuler, [1000, 0, 0, 0, 1131, 0, 0, 0, 0, 0]),
        (Scheme::Rk4, [1000, 0, 0, 0, 4131, 0, 0, 0, 0, 0]),
        // 93 attempts × 6 evaluations (first same as last) + the start + the initial-step probe
        (Scheme::Dopri5, [80, 13, 0, 0, 560, 0, 0, 0, 0, 0]),
        // local tolerance 0.3·rtol^1.5 (their global error follows rtol): 15× the steps of a
        // per-step rtol; about 3.2 Newton iterations per step; a factorisation every 45–55
        // steps; one M per accepted step, the singular-configuration watch (finite-difference
        // iteration matrices do not evaluate M), and one at the start, its reference
        (
            Scheme::Newmark(NewmarkParams::default()),
            [12523, 12, 0, 0, 2, 12524, 40644, 276, 39816, 39816],
        ),
        (
            Scheme::Hht(HhtParams::default()),
            [13694, 12, 0, 0, 2, 13695, 44566, 274, 43744, 43744],
        ),
        (
            Scheme::GenAlpha(GenAlphaParams::default()),
            [14957, 12, 0, 0, 2, 14958, 48601, 274, 47779, 47779],
        ),
        // fixed step, Newton to 1e-10 (5 iterations per step) and one forward-dynamics solve
        // per step for qdd
        (
            Scheme::ImplicitMidpoint,
            [1000, 0, 0, 0, 1001, 1, 5123, 34, 5021, 5021],
        ),
    ];
    let got: Vec<[usize; 10]> = cases.iter().map(|(s, _)| work_counts(&run(*s))).collect();
    for ((scheme, _), got) in cases.iter().zip(&got) {
        println!("{:<10} {got:?}", scheme.name());
    }
    for ((scheme, expected), got) in cases.iter().zip(&got) {
        assert_eq!(got, expected, "{}", scheme.name());
    }
    let (newmark, gen_alpha) = (got[3], got[5]);
    quoted::says(
        "README.md",
        &[format!(
            "dpend to 2 s: {} M beside {} τ for Newmark",
            thousands(newmark[5]),
            thousands(newmark[6])
        )],
    );
    quoted::says(
        "docs/accuracy.md",
        &[format!(
            "dpend to 2 s at rtol 1e-6 takes {} gen-α steps",
            thousands(gen_alpha[0])
        )],
    );
}
