//! Shared by the benchmarks: a global allocator that counts heap allocations (all threads), so
//! each bench can check that its hot path allocates nothing.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Heap allocations (and reallocations) since the program started.
pub static ALLOCS: AtomicUsize = AtomicUsize::new(0);

/// The counting allocator: the system allocator plus a counter.
pub struct Counting;

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// `n` joint configurations of `v` drawn uniformly within its joint limits from `seed` (the
/// static benches' workload: each iteration takes the next one).
#[allow(dead_code)] // not every bench that shares this module samples configurations
pub fn random_configurations(v: &usm_study::model::Vehicle, seed: u64, n: usize) -> Vec<Vec<f64>> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            v.joints
                .iter()
                .map(|j| rng.random_range(j.min..j.max))
                .collect()
        })
        .collect()
}
