//! Singular configurations under every scheme: the tumbling body on XYZ angles meets the
//! singularity of its middle angle (q1 = ±π/2) half-way through its first flip (see
//! `tumble.rs`), and every scheme, at fixed steps (h = 1e-3 s) and, where it has an error
//! estimate, adaptive (rtol 1e-6), stops there with `Failure::SingularConfiguration` naming
//! q[1] (q[0] and q[2] moving the body alike), whatever its iteration matrix: the generated
//! tangents or forward differences of τ. The Newmark family and BDF with forward
//! differences never evaluate M while iterating, so they watch each accepted state with one
//! evaluation and one Cholesky factorisation of M: on MODELS.md's ZYX start, which stays
//! 5.5–11° from the singularity at h = 1e-3, that is exactly one M and one condition check
//! per accepted step (asserted), and the run is otherwise unchanged.

use crate::support::all_finite;
use mbs::{Failure, IterationMatrix, Options, Scheme, SimError, simulate};
use mbs_models::tumble::{Tumble, TumbleXyz};

#[test]
fn every_scheme_stops_at_the_euler_singularity_with_the_typed_error() {
    for scheme in Scheme::all() {
        let name = scheme.name();
        let mut modes = vec![("fixed h 1e-3", Options::fixed(10.0, 1e-3))];
        if scheme.is_adaptive() {
            modes.push(("adaptive rtol 1e-6", Options::adaptive(10.0, 1e-6)));
        }
        for (mode, o) in modes {
            for it in [IterationMatrix::Auto, IterationMatrix::FiniteDifferences] {
                let o = Options {
                    iteration_matrix: it,
                    ..o.clone()
                };
                let label = format!("{name} {mode} {it:?}");
                let e: SimError = match simulate(TumbleXyz::default(), scheme, o) {
                    Ok((tr, _)) => panic!("{label}: completed at t = {}", tr.t[tr.len() - 1]),
                    Err(e) => e,
                };
                let Failure::SingularConfiguration {
                    coordinate,
                    dependent,
                    value,
                    ..
                } = &e.kind
                else {
                    panic!("{label}: {}", e.kind);
                };
                println!(
                    "{label:<46} t {:.4}  q[1] {value:.4}  {} steps, {} M, {} condition checks",
                    e.t, e.stats.steps, e.stats.mass_matrix, e.stats.condition_checks
                );
                assert_eq!(coordinate, "q[1]", "{label}");
                assert_eq!(dependent, &["q[0]", "q[2]"], "{label}");
                assert!((7.9..8.1).contains(&e.t), "{label}: t = {}", e.t);
                // stopped before the angle reached π/2, within 1.5° of it
                let gap = std::f64::consts::FRAC_PI_2 - value.abs();
                assert!(
                    gap > 0.0 && gap.to_degrees() < 1.5,
                    "{label}: q[1] = {value}"
                );
                assert!(all_finite(&e.trajectory), "{label}");
            }
        }
    }
}

/// The cost of watching accepted states away from the singularity: one M and one condition
/// check per accepted step, nothing else. (At fixed steps: adaptive runs at rtol 1e-6 flip
/// elsewhere, and gen-alpha's and BDF's meet the singularity before t = 10 s, where the
/// watch stops them.)
#[test]
fn watching_accepted_states_costs_one_mass_matrix_per_step() {
    for name in ["newmark", "hht", "gen-alpha", "bdf"] {
        let scheme = Scheme::from_name(name).unwrap();
        let o = Options {
            iteration_matrix: IterationMatrix::FiniteDifferences,
            ..Options::fixed(10.0, 1e-3)
        };
        let unwatched = Options {
            singularity_tol: 0.0,
            ..o.clone()
        };
        let (_, s) = simulate(Tumble::default(), scheme, o).unwrap();
        let (_, u) = simulate(Tumble::default(), scheme, unwatched).unwrap();
        println!(
            "ZYX {name} h 1e-3 FiniteDifferences: {} steps, τ {}, factorisations {}, M {} (unwatched {}), condition checks {}",
            s.steps,
            s.inverse_dynamics,
            s.factorizations,
            s.mass_matrix,
            u.mass_matrix,
            s.condition_checks
        );
        assert_eq!(s.steps, u.steps, "{name}");
        assert_eq!(s.inverse_dynamics, u.inverse_dynamics, "{name}");
        assert_eq!(s.factorizations, u.factorizations, "{name}");
        // one M per accepted step, and the reference factorised at the start
        assert_eq!(s.mass_matrix, u.mass_matrix + s.steps + 1, "{name}");
        assert_eq!(s.condition_checks, s.steps + 1, "{name}");
    }
}
