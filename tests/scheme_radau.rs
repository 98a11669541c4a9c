//! Radau IIA 3 and 5 (`mbs-runtime/src/integrators/radau/`) on the canonical models:
//! observed orders on seed2dof (fixed step and adaptive), accuracy against the reference runs
//! of dpend and arm3d_6, work counters of one reference run per scheme, and the iteration
//! matrices and how long they are kept (failures and allocations are checked with every
//! scheme in `failures.rs` and `no_alloc.rs`).

use mbs_models::arm3d_6;
mod common;
#[path = "common/quoted.rs"]
mod quoted;
use mbs_models::dpend;
use mbs_models::seed2dof;

use common::*;
use mbs::{IterationMatrix, Options, Output, Scheme, Stats, simulate};

mbs::multibody! {
    /// dpend (`models/src/dpend.rs`) with generated tangents, for exact iteration matrices.
    pub model DoublePendulumT {
        param l = 1.0; param m = 1.0; param g = 9.81;
        let i_bar = m * l * l / 12;
        dof q[0] = PI / 2; dof q[1] = 0.0;
        body bar1 { mass = m; inertia = (i_bar, 0, i_bar); }
        body bar2 { mass = m; inertia = (i_bar, 0, i_bar); }
        TOG[bar1] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l / 2, 0) * Trotz(q[1]) * Tdisp(0, -l / 2, 0);
        gravity(0, -g, 0);
        option tangents;
    }
}

const SCHEMES: [Scheme; 2] = [Scheme::Radau3, Scheme::Radau5];

fn sci(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:.3e}")).collect();
    items.join(", ")
}

/// Period of the 10 Hz mode of seed2dof.
fn t2() -> f64 {
    2.0 * std::f64::consts::PI / seed2dof_modes().0[1]
}

/// Largest error over 50 outputs of a fixed-step run to `t_end`.
fn fixed_error(scheme: Scheme, h: f64, t_end: f64) -> f64 {
    let opts = Options {
        output: Output::Every { dt: t_end / 50.0 },
        energy: false,
        ..Options::fixed(t_end, h)
    };
    let (tr, _) = simulate(seed2dof::Seed2dof::default(), scheme, opts).unwrap();
    seed2dof_max_error(&tr)
}

#[test]
fn fixed_step_orders_on_seed2dof() {
    let t2 = t2();
    for scheme in SCHEMES {
        // h = T₂/20 … T₂/160 over one period of the 1 Hz mode
        let hs: Vec<f64> = (0..4).map(|k| t2 / 20.0 / 2f64.powi(k)).collect();
        let errs: Vec<f64> = hs.iter().map(|&h| fixed_error(scheme, h, 1.0)).collect();
        let p = loglog_slope(&hs, &errs);
        println!(
            "{:<7} h {}\n        errors {} → order {p:.2}",
            scheme.name(),
            sci(&hs),
            sci(&errs)
        );
        let theory = scheme.order() as f64;
        assert!(
            (p - theory).abs() <= 0.3,
            "{}: observed order {p:.2}, theory {theory}",
            scheme.name()
        );
    }
}

#[test]
fn adaptive_orders_on_seed2dof() {
    for (scheme, rtols) in [
        (Scheme::Radau3, [1e-4, 1e-5, 1e-6, 1e-7]),
        (Scheme::Radau5, [1e-5, 1e-6, 1e-7, 1e-8]),
    ] {
        let mut steps = Vec::new();
        let mut errs = Vec::new();
        for rtol in rtols {
            let opts = Options {
                output: Output::Every { dt: 0.02 },
                energy: false,
                ..Options::adaptive(1.0, rtol)
            };
            let (tr, st) = simulate(seed2dof::Seed2dof::default(), scheme, opts).unwrap();
            steps.push(st.steps as f64);
            errs.push(seed2dof_max_error(&tr));
        }
        let p = -loglog_slope(&steps, &errs);
        println!(
            "{:<7} steps {steps:?}\n        errors {} → order {p:.2}",
            scheme.name(),
            sci(&errs)
        );
        let theory = scheme.order() as f64;
        assert!(
            (p - theory).abs() <= 0.3,
            "{}: error–steps slope {p:.2}, theory {theory}",
            scheme.name()
        );
    }
}

/// Runs `model` adaptively to `t_end` and compares the final state with the reference.
fn against_reference<M: mbs::Model + 'static>(
    model: M,
    name: &str,
    scheme: Scheme,
    t_end: f64,
    rtol: f64,
) -> (f64, Stats) {
    let (q, qd) = reference_state(name, t_end);
    let opts = Options {
        output: Output::Last,
        energy: false,
        ..Options::adaptive(t_end, rtol)
    };
    let (tr, st) = simulate(model, scheme, opts).unwrap();
    let e = final_error(&tr, &q, &qd);
    println!(
        "{name} {:<7} t = {t_end}: error {e:.2e}, {} steps, rejected {} (error) {} (Newton), \
         {} evaluations, {} factorisations",
        scheme.name(),
        st.steps,
        st.rejected_error,
        st.rejected_newton,
        st.evaluations(),
        st.factorizations
    );
    (e, st)
}

/// dpend is chaotic: a state error grows about 10⁴-fold from t = 5 to t = 10 s (the reference's
/// own DOP853 run at rtol 1e-10 is 9e-6 away at t = 10). At rtol 1e-10 both schemes are within
/// 1e-6 at t = 5 s, but not at t = 10 s (Radau5: 1.3e-5 in 3373 steps, Radau3: 6.7e-4 in 35306
/// steps; Dopri5: 3.7e-5); within 1e-6 at t = 10 s takes rtol 1e-12 for Radau5 (7.1e-7, 7309
/// steps) and 1e-14 for Radau3 (6.1e-7, 353647 steps: an order-3 method at this accuracy).
#[test]
fn dpend_against_reference() {
    for scheme in SCHEMES {
        let model = dpend::DoublePendulum::default();
        let (e, _) = against_reference(model, "dpend", scheme, 5.0, 1e-10);
        assert!(e < 1e-6, "{}: dpend error {e:e} at t = 5", scheme.name());
    }
    for (scheme, rtol) in [(Scheme::Radau5, 1e-12), (Scheme::Radau3, 1e-11)] {
        let model = dpend::DoublePendulum::default();
        let (e, _) = against_reference(model, "dpend", scheme, 10.0, rtol);
        assert!(e < 1e-6, "{}: dpend error {e:e} at t = 10", scheme.name());
    }
}

#[test]
fn arm3d_6_at_2_s() {
    for scheme in SCHEMES {
        let (e, _) = against_reference(arm3d_6::Arm3d6::default(), "arm3d_6", scheme, 2.0, 1e-10);
        assert!(e < 1e-6, "{}: arm3d_6 error {e:e} at t = 2", scheme.name());
    }
}

/// One reference run per scheme, dpend from 0 to 2 s at rtol 1e-6 (atol 1e-8), snapshotted: a
/// change that silently doubles the work fails here. dpend has no generated tangents: each
/// evaluation of M, C_t, K_t is 1 M and 2n + 1 = 5 τ (finite differences); each Newton
/// iteration is s τ (one per stage). The start and the initial-step probe solve for qdd by
/// forward dynamics (2, without M); M is evaluated once more at the start, the reference of
/// the singular-configuration watch. Every (re)factorisation is a complex and a real LU
/// (Radau3's real one is the error filter only); solves: 1 complex per Newton iteration (+1
/// real for Radau5) and 1 real per error estimate.
///
/// - Radau3 (local rtol' = 0.1·rtol: 649 steps under RADAU5's transformation): 2074 attempts,
///   1662 matrix evaluations (1662·5 + 4081·2 = 16472 τ; 1662 + 1 M), 1882 factorisations of
///   both blocks (2·1882 = 3764), 4081 + 2074 = 6155 solves;
/// - Radau5: 141 attempts, 129 matrix evaluations (129·5 + 370·3 = 1755 τ; 129 + 1 M), 140
///   factorisations of both blocks (2·140 = 280), 2·370 + 141 = 881 solves.
///
/// RADAU5's rule re-evaluates the matrices whenever Newton contracted by more than θ = 0.001,
/// which on this non-stiff problem is nearly every step; h changes at almost every step, so
/// the blocks are refactorised too.
#[test]
fn work_counters_snapshot() {
    let cases = [
        (
            Scheme::Radau3,
            [2072, 2, 0, 0, 2, 1663, 16472, 3764, 6155, 4081],
        ),
        (Scheme::Radau5, [133, 8, 0, 0, 2, 130, 1755, 280, 881, 370]),
    ];
    for (scheme, expected) in cases {
        let opts = Options {
            output: Output::Last,
            energy: false,
            ..Options::adaptive(2.0, 1e-6)
        };
        let (_, st) = simulate(dpend::DoublePendulum::default(), scheme, opts).unwrap();
        println!("{} dpend to 2 s at rtol 1e-6:\n{st}", scheme.name());
        assert_eq!(work_counts(&st), expected, "{}", scheme.name());
    }
}

/// Every way of building the iteration matrices gives the same motion (to the tolerance); the
/// work differs: exact tangents (1 M and 1 tangent evaluation per Jacobian), finite
/// differences (1 M and 2n + 1 = 5 τ), mass only (1 M, slower Newton).
#[test]
fn iteration_matrices() {
    let (q, qd) = reference_state("dpend", 2.0);
    for scheme in SCHEMES {
        for im in [
            IterationMatrix::Exact,
            IterationMatrix::FiniteDifferences,
            IterationMatrix::MassOnly,
        ] {
            for step in [Options::adaptive(2.0, 1e-9), Options::fixed(2.0, 2e-3)] {
                let opts = Options {
                    output: Output::Last,
                    energy: false,
                    iteration_matrix: im,
                    ..step
                };
                let (tr, st) = simulate(DoublePendulumT::default(), scheme, opts).unwrap();
                let e = final_error(&tr, &q, &qd);
                println!(
                    "{:<7} {im:?} {:?}: error {e:.2e}, {} steps, {} Newton iterations, \
                     {} M, {} τ, {} tangents",
                    scheme.name(),
                    step.step,
                    st.steps,
                    st.newton_iterations,
                    st.mass_matrix,
                    st.inverse_dynamics,
                    st.tangents
                );
                assert!(e < 1e-5, "{} {im:?}: error {e:e}", scheme.name());
                assert_eq!(st.tangents > 0, im == IterationMatrix::Exact);
            }
        }
    }
}

/// The tumble (`TumbleBall`, 10 s): Radau5's Newton, with its matrices fresh at every step,
/// cannot converge at the steps its error controller asks for (the rotation moves the stage
/// accelerations further than the extrapolated start values follow), and used to halve the
/// step about once per accepted step. The step Newton last failed at now caps the
/// controller's proposals until accepted steps relax it: the work counters, with the numbers
/// before that memory in the comments.
#[test]
fn newton_limited_steps_are_remembered() {
    use mbs_models::tumble::TumbleBall;
    // (rtol, steps, Newton rejections); before: 1e-6 2,279 steps / 2,065 Newton rejections,
    // 1e-10 7,900 / 7,582 (`docs/figures/wp_tumble.csv` as first committed); at 1e-6 2,347 / 1,334
    // before the predictive correction forgot the steps before a failed Newton iteration
    for (rtol, steps, rejected) in [(1e-6, 2335, 1329), (1e-10, 8007, 4958)] {
        let (_, st) = simulate(
            TumbleBall::default(),
            Scheme::Radau5,
            Options::adaptive(10.0, rtol),
        )
        .unwrap();
        println!(
            "tumble, radau5, rtol {rtol:e}: {} steps, {} rejected by Newton, {} by the error test",
            st.steps, st.rejected_newton, st.rejected_error
        );
        assert_eq!((st.steps, st.rejected_newton), (steps, rejected));
    }
}

/// Radau keeps its iteration matrices for the next step while Newton contracts below
/// `NewtonOptions::keep_below` (RADAU5's THET): by default 0.1 where they are differences on
/// 16 coordinates or more, as RADAU5's documentation advises where they are costly, and
/// RADAU5's 0.001 otherwise. The free hexapod tumbling (24 coordinates, no generated
/// tangents: each matrix 1 M and 2n + 1 = 49 τ; the work–precision study's run, 1 s at rtol
/// 1e-6) and the standing one (2 s at rtol 1e-6, its contacts and PD torques written in the
/// language) take fewer evaluations for an error as small: the README's figures. A value out
/// of (0, 1) is refused, naming the option.
#[test]
fn costly_iteration_matrices_are_kept_longer() {
    use mbs::options::{COSTLY_KEEP_BELOW, RADAU5_KEEP_BELOW};
    use mbs_models::hexapod::{Hexapod, HexapodStanding};
    fn run<M: mbs::Model + Clone + 'static>(
        name: &str,
        model: &M,
        start: &Options,
        keep_below: Option<f64>,
        reference: &mbs::Trajectory,
    ) -> (f64, Stats) {
        let opts = Options {
            newton: mbs::NewtonOptions {
                keep_below,
                ..Default::default()
            },
            ..start.clone()
        };
        let (tr, st) = simulate(model.clone(), Scheme::Radau5, opts).unwrap();
        let e = final_error(&tr, reference.q(0), reference.qd(0));
        println!(
            "{name}, Radau5 at rtol 1e-6, keep_below {keep_below:?}: error {e:.2e}, {} steps, \
             {} matrices, {} evaluations, {} factorisations, {} Newton iterations",
            st.steps,
            st.mass_matrix,
            st.evaluations(),
            st.factorizations,
            st.newton_iterations
        );
        (e, st)
    }
    // DOPRI5 at rtol 1e-12 where the motion is smooth, Radau5 at 1e-10 (its matrices as
    // RADAU5 keeps them) on the stiff contacts
    fn reference<M: mbs::Model + Clone + 'static>(
        model: &M,
        start: &Options,
        scheme: Scheme,
        rtol: f64,
    ) -> mbs::Trajectory {
        let opts = Options {
            step: Options::adaptive(start.t_end, rtol).step,
            newton: mbs::NewtonOptions {
                keep_below: Some(RADAU5_KEEP_BELOW),
                ..Default::default()
            },
            ..start.clone()
        };
        let (tr, st) = simulate(model.clone(), scheme, opts).unwrap();
        assert_eq!(st.chart_switches, 0, "the runs compare q in one chart");
        tr
    }
    let free = Options {
        qd0: Some(
            (0..24)
                .map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos())
                .collect(),
        ),
        output: Output::Last,
        energy: false,
        ..Options::adaptive(1.0, 1e-6)
    };
    let standing = Options {
        output: Output::Last,
        energy: false,
        ..Options::adaptive(2.0, 1e-6)
    };
    let mut phrases = Vec::new();
    let r = reference(&Hexapod::default(), &free, Scheme::Dopri5, 1e-12);
    let free_run = |keep_below| run("free hexapod", &Hexapod::default(), &free, keep_below, &r);
    let (e0, s0) = free_run(Some(RADAU5_KEEP_BELOW));
    let (e1, s1) = free_run(None);
    let (_, s2) = free_run(Some(COSTLY_KEEP_BELOW));
    assert_eq!(
        s1.evaluations(),
        s2.evaluations(),
        "the default is 0.1 here"
    );
    assert!(s1.mass_matrix * 2 < s0.mass_matrix, "{s0}\n{s1}");
    assert!(2 * s1.evaluations() < s0.evaluations(), "{s0}\n{s1}");
    assert!(e0 < 1e-5 && e1 < 1e-5, "{e0:e} {e1:e}");
    phrases.push(format!(
        "1 s at rtol 1e-6, {} → {} evaluations, its error {e0:.1e} → {e1:.1e};",
        quoted::thousands(s0.evaluations()),
        quoted::thousands(s1.evaluations())
    ));
    let r = reference(
        &HexapodStanding::default(),
        &standing,
        Scheme::Radau5,
        1e-10,
    );
    let standing_run = |keep_below| {
        let model = HexapodStanding::default();
        run("standing hexapod", &model, &standing, keep_below, &r)
    };
    let (e0, s0) = standing_run(Some(RADAU5_KEEP_BELOW));
    let (e1, s1) = standing_run(None);
    assert!(s1.evaluations() < s0.evaluations(), "{s0}\n{s1}");
    assert!(e0 < 1e-4 && e1 < 1e-4, "{e0:e} {e1:e}");
    phrases.push(format!(
        "standing on its feet, 2 s, {} → {} evaluations, its error {e0:.1e} → {e1:.1e}",
        quoted::thousands(s0.evaluations()),
        quoted::thousands(s1.evaluations())
    ));
    // chain24 (24 coordinates, differences too), whose Newton contracts by more than 0.1 at
    // most steps: nearly as many matrices either way
    let [c0, c1] = [Some(RADAU5_KEEP_BELOW), None].map(|keep_below| {
        let opts = Options {
            output: Output::Last,
            energy: false,
            newton: mbs::NewtonOptions {
                keep_below,
                ..Default::default()
            },
            ..Options::adaptive(2.0, 1e-6)
        };
        let (_, st) = simulate(
            mbs_models::chain24::Chain24::default(),
            Scheme::Radau5,
            opts,
        )
        .unwrap();
        println!(
            "chain24 over 2 s, Radau5 at rtol 1e-6, keep_below {keep_below:?}: {} steps, {} matrices, {} evaluations",
            st.steps,
            st.mass_matrix,
            st.evaluations()
        );
        st
    });
    phrases.push(format!(
        "(chain24 over 2 s: {} → {} matrices, {} → {} evaluations)",
        quoted::thousands(c0.mass_matrix),
        quoted::thousands(c1.mass_matrix),
        quoted::thousands(c0.evaluations()),
        quoted::thousands(c1.evaluations())
    ));
    quoted::says("README.md", &phrases);
    for bad in [0.0, 1.0, -0.1, f64::NAN] {
        let opts = Options {
            newton: mbs::NewtonOptions {
                keep_below: Some(bad),
                ..Default::default()
            },
            ..free.clone()
        };
        let e = simulate(Hexapod::default(), Scheme::Radau5, opts).unwrap_err();
        assert!(e.to_string().contains("newton.keep_below"), "{e}");
    }
}
