//! No allocation per step after warm-up: a counting global allocator watches every scheme
//! take 200 steps after its first 20, with fixed steps and, where it has them, adaptive ones.

#[path = "../examples/models/dpend.rs"]
mod dpend;

use mbs::{Integrator, Options, Output, Scheme, Simulation};
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
            let mut sim = match Simulation::new(dpend::DoublePendulum::default(), scheme, opts) {
                Ok(s) => s,
                Err(e) => panic!("{}: {e}", scheme.name()),
            };
            for _ in 0..20 {
                sim.step().unwrap();
            }
            let before = ALLOCATIONS.load(Ordering::Relaxed);
            for _ in 0..200 {
                sim.step().unwrap();
            }
            let allocated = ALLOCATIONS.load(Ordering::Relaxed) - before;
            assert_eq!(
                allocated,
                0,
                "{} allocated {allocated} times in 200 steps",
                scheme.name()
            );
        }
    }
}
