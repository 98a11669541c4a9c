//! No allocation per step after warm-up: a counting global allocator watches every scheme
//! take 200 steps after its first 20, with fixed steps and, where it has them, adaptive ones;
//! then a constrained model with every constraint method. The allocator counts this thread's
//! allocations (`tests/common/alloc.rs`).

use mbs_models::dpend;

use mbs::{ConstraintMethod, GenAlphaParams, Options, Output, Scheme, Simulation};
use mbs_models::pendulum3;
use pendulum3::Pendulum3;

#[path = "common/alloc.rs"]
mod alloc;

#[test]
fn steps_allocate_nothing_after_warm_up() {
    // the counter sees this thread's allocations
    let before = alloc::allocations();
    let v = std::hint::black_box(vec![1u8; 16]);
    assert!(alloc::allocations() > before && v.len() == 16);
    for scheme in Scheme::all() {
        // outputs every 10 ms: their buffers are reserved up front
        let mut modes = vec![Options::fixed(100.0, 1e-3)];
        if scheme.is_adaptive() {
            modes.push(Options::adaptive(100.0, 1e-7));
        }
        for base in modes {
            let opts = Options {
                output: Output::Every { dt: 0.01 },
                ..base
            };
            let sim = match Simulation::new(dpend::DoublePendulum::default(), scheme, opts) {
                Ok(s) => s,
                Err(e) => panic!("{}: {e}", scheme.name()),
            };
            alloc::assert_no_allocation(sim, scheme.name());
        }
    }
    let gen_alpha = Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8));
    for (scheme, method) in [
        (gen_alpha, ConstraintMethod::Index3),
        (Scheme::Dopri5, ConstraintMethod::Projection),
        (
            Scheme::Bdf(Default::default()),
            ConstraintMethod::Projection,
        ),
        (Scheme::Rk4, ConstraintMethod::Partitioning),
        (
            Scheme::Rk4,
            ConstraintMethod::Baumgarte {
                alpha: 5.0,
                beta: 5.0,
            },
        ),
    ] {
        let base = if scheme.is_adaptive() {
            Options::adaptive(100.0, 1e-7)
        } else {
            Options::fixed(100.0, 1e-3)
        };
        let mut opts = Options {
            output: Output::Every { dt: 0.01 },
            ..base
        };
        opts.constraints.method = method;
        let sim = Simulation::new(Pendulum3::default(), scheme, opts).unwrap();
        alloc::assert_no_allocation(sim, &format!("{} with {}", scheme.name(), method.name()));
    }
}

/// Re-centring the chart of a rotation joint allocates nothing either: the spherical pendulum
/// swings through the bottom, where its joint's chart moves, inside the 200 steps watched
/// (its first re-centring comes at t ≈ 0.3 s, after the 20 steps of warm-up, at most 0.1 s;
/// the re-centrings are counted).
#[test]
fn recentring_allocates_nothing() {
    use mbs::Integrator;
    use mbs_models::spherical_pendulum::SphericalPendulum;
    for scheme in Scheme::all() {
        let mut modes = vec![Options::fixed(100.0, 5e-3)];
        if scheme.is_adaptive() {
            // RKC, of order 2 with its tolerance scaled by 0.3·√rtol, steps too short at
            // rtol 1e-5 to reach the bottom within the window
            let rtol = if scheme == Scheme::Rkc { 1e-3 } else { 1e-5 };
            modes.push(Options {
                h_max: 5e-3,
                ..Options::adaptive(100.0, rtol)
            });
        }
        for base in modes {
            let opts = Options {
                output: Output::Every { dt: 0.01 },
                ..base
            };
            let sim = Simulation::new(SphericalPendulum::default(), scheme, opts)
                .unwrap_or_else(|e| panic!("{}: {e}", scheme.name()));
            let mut switches = 0;
            alloc::assert_no_allocation_then(sim, scheme.name(), |s| {
                switches = s.stats().chart_switches;
            });
            assert!(
                switches > 0,
                "{}: no re-centring in the window",
                scheme.name()
            );
        }
    }
}
