//! Stopping long work from outside (a notebook's interrupt, Ctrl-C in a script): a
//! request for the whole process that the simulation's step loops check every
//! [`CHECK_EVERY`] steps and the sweeps, tests and searches between their points, so
//! that a call returns within a fraction of a second with what it finished.
//!
//! The command line needs none of it (its Ctrl-C ends the process); a host that runs
//! the library inside itself — the Python module — enters a [`Scope`] around each
//! long call and calls [`request`] when its user interrupts. The request stops every
//! call of the process then running, and is withdrawn when the last of them has
//! returned. Checking it is one relaxed atomic load: nothing is allocated, and the
//! kernel's step loop pays it once per [`CHECK_EVERY`] steps.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Steps of a simulation between two checks of the request (a power of two, checked
/// with a mask): under half a millisecond of the worm gear's kernel (11 M steps/s,
/// docs/performance.md), a few milliseconds of eight lanes.
pub const CHECK_EVERY: u64 = 4096;

/// A stop request and the calls it concerns: the process has one, [`GLOBAL`]; tests
/// make their own.
pub struct Flag {
    requested: AtomicBool,
    active: AtomicUsize,
}

/// The process's request, which the simulations check.
pub static GLOBAL: Flag = Flag::new();

/// The work was stopped by a request ([`request`]) before it finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("interrupted")]
pub struct Interrupted;

impl Flag {
    /// No request, no call.
    pub const fn new() -> Flag {
        Flag {
            requested: AtomicBool::new(false),
            active: AtomicUsize::new(0),
        }
    }

    /// Asks every running call to stop.
    pub fn request(&self) {
        self.requested.store(true, Ordering::Relaxed);
    }

    /// Whether a stop is asked for.
    #[inline(always)]
    pub fn requested(&self) -> bool {
        self.requested.load(Ordering::Relaxed)
    }

    /// Enters a long call: while any is in progress, a request stays; when the last
    /// one ends, it is withdrawn, so that the next call runs whole.
    pub fn enter(&self) -> Scope<'_> {
        self.active.fetch_add(1, Ordering::SeqCst);
        Scope(self)
    }
}

impl Default for Flag {
    fn default() -> Flag {
        Flag::new()
    }
}

/// A long call in progress ([`Flag::enter`]).
#[must_use = "the scope lasts as long as the guard"]
pub struct Scope<'a>(&'a Flag);

impl Drop for Scope<'_> {
    fn drop(&mut self) {
        if self.0.active.fetch_sub(1, Ordering::SeqCst) == 1 {
            self.0.requested.store(false, Ordering::SeqCst);
        }
    }
}

/// Asks every running call of the process to stop ([`GLOBAL`]).
pub fn request() {
    GLOBAL.request();
}

/// Whether a stop of the process's calls is asked for.
#[inline(always)]
pub fn requested() -> bool {
    GLOBAL.requested()
}

/// `Err(Interrupted)` when a stop is asked for.
#[inline]
pub fn check() -> Result<(), Interrupted> {
    if requested() {
        Err(Interrupted)
    } else {
        Ok(())
    }
}

/// Whether step `step` of a simulation is one where the request is checked, and it
/// is asked for (one mask and, every [`CHECK_EVERY`] steps, one load).
#[inline(always)]
pub fn at_step(step: u64) -> bool {
    step & (CHECK_EVERY - 1) == 0 && requested()
}

/// Enters a long call of the process ([`Flag::enter`] of [`GLOBAL`]).
pub fn enter() -> Scope<'static> {
    GLOBAL.enter()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The request lasts while a scope is open and is withdrawn with the last one
    /// (on a flag of the test's own: the process's would stop the other tests).
    #[test]
    fn a_request_lasts_until_the_last_scope_ends() {
        let flag = Flag::new();
        let outer = flag.enter();
        assert!(!flag.requested());
        let inner = flag.enter();
        flag.request();
        assert!(flag.requested());
        drop(inner);
        assert!(flag.requested());
        drop(outer);
        assert!(!flag.requested());
    }

    #[test]
    fn the_step_loop_checks_once_per_block_of_steps() {
        assert_eq!(CHECK_EVERY.count_ones(), 1);
        // Not requested in this process's tests: no step stops.
        assert!(!(0..3 * CHECK_EVERY).any(at_step));
    }
}
