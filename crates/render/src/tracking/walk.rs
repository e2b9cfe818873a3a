//! The loop every null-collision tracker shares: tentative collisions of a
//! Poisson process whose rate is constant on each majorant segment.

use crate::medium::MajorantSegment;
use crate::sampling::{sample_exponential, Rng};
use crate::stats::Counters;

use super::MAX_COLLISIONS;

/// A majorant segment (extinction units) with the rate at which
/// tentative collisions are placed on it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Segment {
    pub t0: f32,
    pub t1: f32,
    pub sigma_min: f32,
    pub sigma_maj: f32,
    /// `sigma_maj` for delta and ratio tracking, `sigma_maj - sigma_min`
    /// for residual ratio tracking.
    pub rate: f32,
}

pub(crate) enum Event {
    /// The walk entered a segment (residual tracking applies its control
    /// transmittance here).
    Enter(Segment),
    /// A tentative collision at `t` inside `segment`.
    Collision { t: f32, segment: Segment },
    /// No more segments: the ray left the medium.
    End,
    /// The per-call collision cap was hit (counted in `collision_cap_hits`).
    Capped,
}

/// Hofmann et al. (2021) / Novak et al. (2014) style walk: draw an optical
/// depth `tau = -ln(1 - u)`, subtract `rate * length` segment by segment,
/// and when `tau` runs out inside a segment step back to the collision
/// point `t = t_entry + tau / rate`. After a collision a fresh `tau` is drawn
/// (memorylessness makes this exact). Segments with zero rate are crossed
/// without drawing anything, the analytic skip of pbrt-v4's `SampleT_maj`.
pub(crate) struct Walk<I> {
    segments: I,
    residual: bool,
    current: Option<Segment>,
    t: f32,
    tau: f32,
    collisions: u32,
}

impl<I: Iterator<Item = MajorantSegment>> Walk<I> {
    pub fn new(segments: I, residual: bool, rng: &mut Rng) -> Self {
        Self {
            segments,
            residual,
            current: None,
            t: 0.0,
            tau: sample_exponential(rng.uniform()),
            collisions: 0,
        }
    }

    #[inline]
    pub fn next(&mut self, rng: &mut Rng, c: &mut Counters) -> Event {
        loop {
            let Some(seg) = self.current else {
                let Some(s) = self.segments.next() else {
                    return Event::End;
                };
                c.dda_segments += 1;
                // Segments come in extinction units (`Media::majorants`).
                let (sigma_min, sigma_maj) = (s.minorant, s.majorant);
                let rate = if self.residual {
                    sigma_maj - sigma_min
                } else {
                    sigma_maj
                };
                let seg = Segment {
                    t0: s.t0,
                    t1: s.t1,
                    sigma_min,
                    sigma_maj,
                    rate,
                };
                self.current = Some(seg);
                self.t = s.t0;
                return Event::Enter(seg);
            };
            // `rate > 0` is false for NaN too: such segments are skipped.
            if seg.rate > 0.0 {
                let depth = seg.rate * (seg.t1 - self.t);
                if self.tau < depth {
                    self.collisions += 1;
                    if self.collisions > MAX_COLLISIONS {
                        c.collision_cap_hits += 1;
                        return Event::Capped;
                    }
                    self.t = (self.t + self.tau / seg.rate).min(seg.t1);
                    self.tau = sample_exponential(rng.uniform());
                    return Event::Collision {
                        t: self.t,
                        segment: seg,
                    };
                }
                self.tau -= depth;
            }
            self.current = None;
        }
    }
}
