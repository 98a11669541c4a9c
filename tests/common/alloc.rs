//! A global allocator that counts the allocations of each thread, for the tests that prove
//! that steps allocate nothing: libtest's own threads allocate now and then (and tests may
//! run side by side), so only the current thread's count is meaningful.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    // `try_with`: the allocator also runs while thread-locals are torn down
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations (and reallocations) made by this thread so far.
pub fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

/// 20 steps of warm-up, then 200 steps that must not allocate.
pub fn assert_no_allocation<M: mbs::Model + 'static>(sim: mbs::Simulation<M>, what: &str) {
    assert_no_allocation_then(sim, what, |_| {});
}

/// [`assert_no_allocation`], then `after` sees the simulation.
#[allow(dead_code)]
pub fn assert_no_allocation_then<M: mbs::Model + 'static>(
    mut sim: mbs::Simulation<M>,
    what: &str,
    after: impl FnOnce(&mbs::Simulation<M>),
) {
    use mbs::Integrator;
    for _ in 0..20 {
        sim.step().unwrap();
    }
    let before = allocations();
    for _ in 0..200 {
        sim.step().unwrap();
    }
    let allocated = allocations() - before;
    assert_eq!(
        allocated, 0,
        "{what} allocated {allocated} times in 200 steps"
    );
    after(&sim);
}
