//! The loop every null-collision tracker shares: tentative collisions of a
//! Poisson process whose rate is constant on each majorant segment.

use crate::counters::Counters;
use crate::medium::MajorantSegment;
use crate::sampling::{sample_exponential, Rng};

use super::MAX_COLLISIONS;

/// Segments come in extinction units (`Media::majorants`): `minorant` and
/// `majorant` bound `sigma_t`. The walk places tentative collisions on a
/// segment at its `rate`: `majorant` for delta and ratio tracking,
/// `majorant - minorant` for residual ratio tracking.
pub(crate) enum Event {
    /// The walk entered a segment (residual tracking applies its control
    /// transmittance here).
    Enter(MajorantSegment),
    /// A tentative collision at `t` inside `segment`, placed at `rate`.
    Collision {
        t: f32,
        segment: MajorantSegment,
        rate: f32,
    },
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
    /// The segment being walked and its rate.
    current: Option<(MajorantSegment, f32)>,
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

    // Always: the inliner's heuristics once left it out of line in the
    // trackers, which cost about 7% of a path-traced render.
    #[inline(always)]
    pub fn next(&mut self, rng: &mut Rng, c: &mut Counters) -> Event {
        loop {
            let Some((seg, rate)) = self.current else {
                let Some(s) = self.segments.next() else {
                    return Event::End;
                };
                c.dda_segments += 1;
                let rate = if self.residual {
                    s.majorant - s.minorant
                } else {
                    s.majorant
                };
                self.current = Some((s, rate));
                self.t = s.t0;
                return Event::Enter(s);
            };
            // `rate > 0` is false for NaN too: such segments are skipped.
            if rate > 0.0 {
                let depth = rate * (seg.t1 - self.t);
                if self.tau < depth {
                    self.collisions += 1;
                    if self.collisions > MAX_COLLISIONS {
                        c.collision_cap_hits += 1;
                        return Event::Capped;
                    }
                    self.t = (self.t + self.tau / rate).min(seg.t1);
                    self.tau = sample_exponential(rng.uniform());
                    return Event::Collision {
                        t: self.t,
                        segment: seg,
                        rate,
                    };
                }
                self.tau -= depth;
            }
            self.current = None;
        }
    }
}
