//! The camera shutter: the interval of time, in frames relative to the
//! frame rendered, over which each pixel integrates (motion blur).

use crate::error::{Error, Result};
use crate::sampling::SampleStream;

/// A shutter open over `[open, close]` frames around the frame's own
/// instant (time 0): `-0.25..0.25` is a centred 180-degree shutter,
/// `0..0.5` one that opens on the frame.
///
/// Velocity is looked up at the frame's own instant (`t_ref = 0`), so a
/// moving medium at time `t` is displaced by `v * t`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shutter {
    pub open: f32,
    pub close: f32,
}

impl Shutter {
    /// The closed shutter of a still frame: every sample at time 0.
    pub const INSTANT: Shutter = Shutter {
        open: 0.0,
        close: 0.0,
    };

    pub fn new(open: f32, close: f32) -> Self {
        Self { open, close }
    }

    /// The open and close times, as scene files spell them.
    pub const fn times(self) -> [f32; 2] {
        [self.open, self.close]
    }

    /// Checks the interval is finite and not reversed.
    pub fn validate(&self) -> Result<()> {
        if !(self.open.is_finite() && self.close.is_finite()) || self.close < self.open {
            return Err(Error::invalid(format!(
                "shutter {},{} must be finite with open <= close (frames)",
                self.open, self.close
            )));
        }
        Ok(())
    }

    /// Whether samples spread over time at all; a zero-length shutter
    /// draws no time and renders the instant `open`.
    pub fn is_open(&self) -> bool {
        self.close > self.open
    }

    /// The farthest any sample is from the frame's instant, in frames:
    /// what bounds the displacement of moving media.
    pub fn max_abs_time(&self) -> f32 {
        self.open.abs().max(self.close.abs())
    }

    /// The time of one camera sample: uniform over the shutter (a box
    /// shutter), from the sample's own time draw; `open` when the shutter
    /// has no length, without drawing.
    #[inline]
    pub fn sample(&self, draws: &SampleStream) -> f32 {
        if !self.is_open() {
            return self.open;
        }
        let t = self.open + (self.close - self.open) * draws.time();
        t.min(self.close)
    }
}
