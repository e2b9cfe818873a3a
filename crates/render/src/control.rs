//! Watching and stopping a render from another thread.
//!
//! The render loop reads the flag once per tile and adds to the progress
//! once per tile, so the hot loops never touch these atomics. A cancelled
//! render finishes the tiles already running and skips the rest; its image
//! is incomplete and the caller must discard it ([`RenderControl::is_cancelled`]).

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Shared between a render and whoever watches it (a progress callback,
/// a Ctrl-C handler, a preview server).
#[derive(Debug, Default)]
pub struct RenderControl {
    cancelled: AtomicBool,
    /// Work done and planned: samples for a sample budget, milliseconds
    /// for a time budget.
    done: AtomicU64,
    total: AtomicU64,
}

impl RenderControl {
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks the render to stop at the next tile.
    pub fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed)
    }

    /// `(done, total)`; `done <= total` once the render has started.
    pub fn progress(&self) -> (u64, u64) {
        let total = self.total.load(Ordering::Relaxed);
        (self.done.load(Ordering::Relaxed).min(total), total)
    }

    pub(crate) fn start(&self, total: u64) {
        self.done.store(0, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
    }

    pub(crate) fn add(&self, work: u64) {
        self.done.fetch_add(work, Ordering::Relaxed);
    }

    pub(crate) fn set(&self, done: u64) {
        self.done.store(done, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_is_clamped_to_its_total_and_cancel_sticks() {
        let c = RenderControl::new();
        c.start(10);
        c.add(4);
        assert_eq!(c.progress(), (4, 10));
        c.add(20);
        assert_eq!(c.progress(), (10, 10));
        assert!(!c.is_cancelled());
        c.cancel();
        assert!(c.is_cancelled());
    }
}
