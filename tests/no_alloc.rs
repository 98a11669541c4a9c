//! No allocation per step after warm-up: a counting global allocator watches every scheme
//! take 200 steps after its first 20, with fixed steps and, where it has them, adaptive ones;
//! then a constrained model with every constraint method. (One test: the allocator counts
//! every thread.)

#[path = "../examples/models/dpend.rs"]
mod dpend;

#[path = "../examples/models/pendulum3.rs"]
mod pendulum3;
use mbs::{ConstraintMethod, GenAlphaParams, Integrator, Options, Output, Scheme, Simulation};
use pendulum3::Pendulum3;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn steps_allocate_nothing_after_warm_up() {
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
            assert_no_allocation(sim, scheme.name());
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
        assert_no_allocation(sim, &format!("{} with {}", scheme.name(), method.name()));
    }
}

/// 20 steps of warm-up, then 200 steps that must not allocate.
fn assert_no_allocation<M: mbs::Model + 'static>(mut sim: Simulation<M>, what: &str) {
    for _ in 0..20 {
        sim.step().unwrap();
    }
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    for _ in 0..200 {
        sim.step().unwrap();
    }
    let allocated = ALLOCATIONS.load(Ordering::Relaxed) - before;
    assert_eq!(
        allocated, 0,
        "{what} allocated {allocated} times in 200 steps"
    );
}
