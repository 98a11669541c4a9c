//! Structural singularities: a mass matrix singular in every configuration.
//!
//! (a) two revolute joints about the same axis at the same point (`Trotz(q0) * Trotz(q1)`,
//!     a bar after them): q0 and q1 move it exactly alike. The generator cannot see it (each
//!     coordinate moves a body with mass); every scheme refuses the run at its start with
//!     `SingularMatrix` on the mass matrix naming both coordinates, before any step.
//! (b) a coordinate that moves no mass: a massless terminal frame turned by its own
//!     coordinate is a compile-time error, "coordinate `q[1]` moves no body with mass, so the
//!     mass matrix would be singular: …", covered by the trybuild case
//!     `compile-fail/tests/ui/physics/coordinate_moves_no_mass.rs` (checked here to still say so). A
//!     coordinate that turns a point mass about its own centre passes that check (it is in
//!     the pose of a body with mass) yet moves no mass: refused at the start of every scheme
//!     with `SingularMatrix` naming it alone.
//! (c) the same kind of singularity reached during a run: a slider at x = sin q0 coasting
//!     at 1 m/s from x = 0 arrives at x = 1 (q0 = π/2, where q0 stops moving it) at t = 1 s;
//!     the adaptive schemes stop before it with `SingularConfiguration` naming q[0]. The
//!     pivot (cos² q0 = 1 − x²) crosses 1e-4 only 5e-5 s before t = 1: RK4 at a fixed
//!     h = 1e-3 steps over that band (from 1.08e-4 at t = 1.000 to the far side), and is
//!     stopped in time with a looser `Options::singularity_tol` (1e-2).

use crate::support::{Work, check_work, work};
use mbs::{Failure, Model, Options, Scheme, Simulation, simulate};
use mbs_models::structural::{CoincidentAxes, SineSlider, SpinningPointMass};

fn refused_at_start<M: Model + Default + 'static>(
    label: &str,
    expected: &[&str],
) -> Vec<(String, Work)> {
    let mut snapshots = Vec::new();
    for scheme in Scheme::all() {
        let o = if scheme.is_adaptive() {
            Options::adaptive(1.0, 1e-6)
        } else {
            Options::fixed(1.0, 1e-3)
        };
        let e = Simulation::new(M::default(), scheme, o)
            .err()
            .unwrap_or_else(|| panic!("{label}: {} started", scheme.name()));
        if scheme == Scheme::Rk4 {
            println!("{label}: {e}");
        }
        match &e.kind {
            Failure::SingularMatrix {
                matrix,
                coordinates,
                ..
            } => {
                assert_eq!(*matrix, "the mass matrix M");
                assert_eq!(coordinates, expected, "{label} {}", scheme.name());
            }
            other => panic!("{label} {}: {other}", scheme.name()),
        }
        assert!(e.trajectory.is_empty() && e.stats.steps == 0 && e.t == 0.0);
        snapshots.push((format!("{label} {}", scheme.name()), work(&e.stats)));
    }
    snapshots
}

#[test]
fn structurally_singular_models_are_refused_naming_their_coordinates() {
    let mut snapshots = refused_at_start::<CoincidentAxes>("coincident axes", &["q[0]", "q[1]"]);
    snapshots.extend(refused_at_start::<SpinningPointMass>(
        "point mass turned about itself",
        &["q[1]"],
    ));
    // (b) at compile time: the trybuild case and its expected message
    let ui = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/compile-fail/tests/ui/physics/coordinate_moves_no_mass"
    );
    let source = std::fs::read_to_string(format!("{ui}.rs")).unwrap();
    let stderr = std::fs::read_to_string(format!("{ui}.stderr")).unwrap();
    assert!(source.contains("frame sensor;") && source.contains("Trotz(q[1])"));
    assert!(stderr.contains(
        "coordinate `q[1]` moves no body with mass, so the mass matrix would be singular"
    ));
    println!(
        "massless terminal frame: compile error (compile-fail/tests/ui/physics/coordinate_moves_no_mass.rs): {}",
        stderr.lines().next().unwrap()
    );
    // (c) reached during a run
    for (scheme, o) in [
        (Scheme::Dopri5, Options::adaptive(2.0, 1e-8)),
        (
            Scheme::from_name("gen-alpha").unwrap(),
            Options::adaptive(2.0, 1e-8),
        ),
        (
            Scheme::from_name("bdf").unwrap(),
            Options::adaptive(2.0, 1e-8),
        ),
        (Scheme::Radau5, Options::adaptive(2.0, 1e-8)),
    ] {
        let e = simulate(SineSlider::default(), scheme, o).expect_err("singular at t = 1");
        println!("sine slider, {}: {e}", scheme.name());
        match &e.kind {
            Failure::SingularConfiguration {
                coordinate,
                value,
                dependent,
                ..
            } => {
                assert_eq!(
                    (coordinate.as_str(), dependent.as_slice()),
                    ("q[0]", &["q[0]".to_string()][..])
                );
                assert!((value - std::f64::consts::FRAC_PI_2).abs() < 0.02);
            }
            other => panic!("{}: {other}", scheme.name()),
        }
        assert!(crate::support::all_finite(&e.trajectory) && e.t > 0.99 && e.t < 1.0);
        snapshots.push((format!("sine slider {}", scheme.name()), work(&e.stats)));
    }
    // RK4 at a fixed h = 1e-3: at the default tolerance its step from t = 1.000 (where the
    // pivot is 1.08e-4 of its start) lands past the singularity; a looser tolerance stops it
    let o = Options {
        singularity_tol: 1e-2,
        ..Options::fixed(2.0, 1e-3)
    };
    let e = simulate(SineSlider::default(), Scheme::Rk4, o).expect_err("singular at t = 1");
    println!("sine slider, rk4 h 1e-3, singularity_tol 1e-2: {e}");
    assert!(
        matches!(&e.kind, Failure::SingularConfiguration { coordinate, .. } if coordinate == "q[0]"),
        "{e}"
    );
    assert!(crate::support::all_finite(&e.trajectory) && e.t < 1.0);
    snapshots.push((
        "sine slider rk4, singularity_tol 1e-2".into(),
        work(&e.stats),
    ));
    // every refusal at the start is one forward-dynamics solve with a pivot that is not
    // positive, then one evaluation of M + h and its failed factorisation (which names the
    // coordinate)
    let start = [0, 0, 0, 1, 1, 0, 0, 0, 1, 0, 0, 0];
    let refused = 2 * Scheme::all().len();
    for (name, w) in &snapshots[..refused] {
        assert_eq!(w, &start, "{name}");
    }
    check_work(
        "structural",
        &snapshots[refused..],
        &[
            [87, 23, 0, 0, 667, 3, 0, 0, 3, 8, 0, 0], // sine slider dopri5
            [18577, 1, 10, 0, 2, 123, 93636, 92, 112, 93716, 93636, 93], // sine slider gen-alpha
            [1010, 17, 11, 0, 2, 132, 1044, 98, 120, 1132, 1044, 99], // sine slider bdf
            [173, 0, 0, 0, 2, 177, 1548, 173, 349, 1213, 516, 174], // sine slider radau5
            [994, 0, 0, 0, 4108, 3, 0, 0, 3, 8, 0, 0], // sine slider rk4, singularity_tol 1e-2
        ],
    );
}
