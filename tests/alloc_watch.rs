//! The test binary's global allocator. A binary has only one, and two test modules
//! watch allocations: `no_alloc` counts the allocations of a thread (the stepping loop
//! makes none), `format_properties` takes the largest single allocation a reader's
//! thread asks for (none beyond what the file can hold). Both per thread, as tests run
//! in parallel threads: what other tests allocate meanwhile never counts.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Watching;

thread_local! {
    /// Allocations (and reallocations) made by this thread.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
    /// Whether this thread's allocation sizes are watched (a reader's thread).
    static WATCHED: Cell<bool> = const { Cell::new(false) };
    /// The largest single allocation this thread asked for while watched.
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

/// The allocations and reallocations this thread has made so far.
pub fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

/// Runs `f` with this thread's allocation sizes watched: its result, and the largest
/// single allocation (or reallocation's new size) the thread asked for meanwhile.
pub fn largest_allocation<R>(f: impl FnOnce() -> R) -> (R, usize) {
    /// Ends the watch however `f` ends.
    struct Unwatch;
    impl Drop for Unwatch {
        fn drop(&mut self) {
            WATCHED.with(|w| w.set(false));
        }
    }
    LARGEST.with(|l| l.set(0));
    WATCHED.with(|w| w.set(true));
    let unwatch = Unwatch;
    let result = f();
    drop(unwatch);
    (result, LARGEST.with(Cell::get))
}

fn record(size: usize) {
    ALLOCATIONS.with(|c| c.set(c.get() + 1));
    if WATCHED.with(Cell::get) {
        LARGEST.with(|l| l.set(l.get().max(size)));
    }
}

// SAFETY: forwards every call to the system allocator unchanged; only counts and
// records sizes (in thread-locals of constant initialisers, which never allocate).
unsafe impl GlobalAlloc for Watching {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        record(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        record(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        record(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Watching = Watching;
