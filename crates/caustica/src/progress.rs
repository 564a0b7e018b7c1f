//! Progress reports and cancellation: how long computations tell the front end what they are
//! doing (and show the pixels they finish), and how the front end stops them. Every layer may
//! use this module; it uses only `math`.

use crate::math::Vec3;
use std::sync::atomic::{AtomicBool, Ordering};

/// Receives progress reports; the library never prints.
pub trait Progress: Sync {
    /// A phase begins with `total` units of work.
    fn start(&self, phase: &str, total: u64);
    /// `n` more units are done.
    fn advance(&self, n: u64);
    /// The phase is over.
    fn finish(&self);
    /// A block of the image is finished, for a live preview. Renderers that make the image
    /// piece by piece report each piece once (the course model's Whitted tiles, from worker
    /// threads); progressive integrators report nothing here, their front end shows each pass's
    /// mean instead. Ignored unless overridden.
    fn pixels(&self, _block: &PixelBlock) {}
}

/// Finished pixels of an image being rendered.
#[derive(Clone, Copy, Debug)]
pub struct PixelBlock<'a> {
    /// Column of the block's left edge.
    pub x: usize,
    /// Row of the block's top edge (rows counted from the top).
    pub y: usize,
    /// Width of the block.
    pub width: usize,
    /// Height of the block.
    pub height: usize,
    /// Linear RGB values, `width × height` of them, rows from the top.
    pub pixels: &'a [Vec3],
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
