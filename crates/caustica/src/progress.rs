//! Progress reports and cancellation: how long computations tell the front end what they are
//! doing, and how the front end stops them. Every layer may use this module; it uses none.

use std::sync::atomic::{AtomicBool, Ordering};

/// Receives progress reports; the library never prints.
pub trait Progress: Sync {
    /// A phase begins with `total` units of work.
    fn start(&self, phase: &str, total: u64);
    /// `n` more units are done.
    fn advance(&self, n: u64);
    /// The phase is over.
    fn finish(&self);
}

/// Progress that goes nowhere.
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _: &str, _: u64) {}
    fn advance(&self, _: u64) {}
    fn finish(&self) {}
}

/// Progress reporting and cancellation for a long computation.
#[derive(Clone, Copy)]
pub struct Control<'a> {
    /// Where progress goes.
    pub progress: &'a dyn Progress,
    /// Set to stop early; the work done so far is kept.
    pub cancel: &'a AtomicBool,
}

impl Control<'_> {
    /// Whether the computation should stop.
    #[inline]
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}
