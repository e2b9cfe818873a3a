//! Adjoint-driven Russian roulette and splitting (Vorba and Křivánek
//! 2016, "Adjoint-Driven Russian Roulette and Splitting in Light
//! Transport Simulation", section 4): at each scattering vertex, the
//! path's expected contribution from here on, its throughput times the
//! radiance cache's in-scattered radiance, is compared with what the
//! path was expected to bring when it first scattered. A path far below
//! that plays roulette, surviving with probability equal to the ratio;
//! a path far above it splits into copies that share its weight. Both
//! keep the estimate unbiased for any cache: a survivor is divided by its
//! probability, `n` copies each carry `1 / n`.
//!
//! In a thick bright cloud this moves the work to where the light is: a
//! path that wandered into the dark core stops early, a path from a
//! shadowed pixel that reached the lit rim, rare and bright, splits into
//! several estimates of that rim's light.

use glam::Vec3;
use smallvec::SmallVec;

use super::path::{Path, PathTracer};
use crate::guiding::{luminance, Guide};
use crate::medium::Media;
use crate::phase::Phase;
use crate::sampling::{Rng, SampleStream};
use crate::stats::Counters;

/// The weight window's width: the ratio of its upper to its lower edge
/// (Vorba and Křivánek's `s`). Inside it a path goes on unchanged.
const WINDOW: f32 = 5.0;
/// The window's lower edge relative to its centre, `2 / (1 + s)`, so the
/// centre is the mean of the edges.
const WINDOW_LOW: f32 = 2.0 / (1.0 + WINDOW);
const WINDOW_HIGH: f32 = WINDOW * WINDOW_LOW;
/// Copies one split makes, at most.
const MAX_SPLIT: u32 = 4;
/// Branches one camera sample may hold in all: splitting stops there, so
/// a sample's cost stays bounded however the cache errs.
const MAX_BRANCHES: u32 = 16;

/// A scattering vertex, before its next-event estimation and direction.
#[derive(Clone, Copy)]
pub(super) struct At<'m> {
    pub p: Vec3,
    pub phase: &'m Phase,
    /// The vertex's index in the draw allocation.
    pub vertex: u32,
}

/// A copy of a path left at a vertex by a split, with its own numbers.
pub(super) struct Branch<'m> {
    pub path: Path,
    pub at: At<'m>,
    pub stream: SampleStream,
}

/// The copies waiting to be traced, and how many a sample has made.
#[derive(Default)]
pub(super) struct Pending<'m> {
    branches: SmallVec<[Branch<'m>; 4]>,
    made: u32,
}

impl<'m> Pending<'m> {
    pub fn pop(&mut self) -> Option<Branch<'m>> {
        self.branches.pop()
    }

    /// Copies a split may still make.
    fn room(&self) -> u32 {
        MAX_BRANCHES.saturating_sub(self.made)
    }

    /// Leaves `copies - 1` copies of `path` at `at` (the path itself is
    /// the first), each drawing from a stream of its own seeded from
    /// `draws`, so the sample stays a function of its own numbers.
    pub fn split(&mut self, path: &Path, at: &At<'m>, copies: u32, draws: &mut SampleStream) {
        for k in 1..copies {
            self.made += 1;
            let seed = draws.rng().next_u64();
            let mut copy = path.clone();
            copy.out = Default::default();
            self.branches.push(Branch {
                path: copy,
                at: *at,
                stream: SampleStream::random(Rng::new(seed, u64::from(k), u64::from(path.depth))),
            });
        }
    }
}

/// How many paths go on from a vertex whose expected contribution is
/// `ratio` times what the path was expected to bring: 0 or 1 (roulette,
/// `u` deciding) below the window, 1 inside it, up to `room + 1` above.
/// Returns the count with the factor each path's throughput takes.
fn window(ratio: f32, u: f32, room: u32) -> (u32, f32) {
    if ratio < WINDOW_LOW {
        // Survives with probability `ratio` (the window's centre is 1).
        if u < ratio {
            (1, 1.0 / ratio)
        } else {
            (0, 0.0)
        }
    } else if ratio > WINDOW_HIGH && room > 0 {
        let n = (ratio.round() as u32).clamp(2, MAX_SPLIT.min(room + 1));
        (n, 1.0 / n as f32)
    } else {
        (1, 1.0)
    }
}

impl<M: Media> PathTracer<'_, M> {
    /// Roulette and splitting at scattering vertex `at`: how many paths
    /// go on from it (0 ends the path), `path`'s throughput already
    /// divided among them. The first vertex sets what the path is
    /// expected to bring; a guide that does not do roulette, or has not
    /// learned there, leaves the path as it is.
    pub(super) fn weight_window(
        &self,
        path: &mut Path,
        guide: Option<&Guide>,
        at: &At,
        pending: &Pending,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> u32 {
        let Some(guide) = guide else { return 1 };
        let Some(inscattered) = guide.inscattered(guide.site_of(at.p)) else {
            return 1;
        };
        let expected = luminance(path.beta) * inscattered;
        if path.depth <= 1 {
            path.expected = expected;
            return 1;
        }
        if !(path.expected > 0.0 && expected.is_finite()) {
            return 1;
        }
        let (n, factor) = window(
            expected / path.expected,
            draws.rng().uniform(),
            pending.room(),
        );
        path.beta *= factor;
        match n {
            0 => c.roulette_ends += 1,
            _ => c.split_copies += u64::from(n - 1),
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Inside the window a path goes on unchanged; below it, it survives
    /// with probability equal to the ratio, divided by it (so its expected
    /// weight is 1); above it, it splits into about `ratio` copies of
    /// weight `1 / n`, at most `MAX_SPLIT` and only as many as there is
    /// room for.
    #[test]
    fn the_weight_window_keeps_the_expected_weight() {
        assert_eq!(window(1.0, 0.5, 16), (1, 1.0));
        assert_eq!(window(WINDOW_HIGH * 0.99, 0.5, 16), (1, 1.0));
        assert_eq!(window(WINDOW_LOW * 1.01, 0.5, 16), (1, 1.0));
        for ratio in [0.01f32, 0.1, 0.3] {
            let n = 100_000;
            let kept: f32 = (0..n)
                .map(|i| {
                    let (k, f) = window(ratio, (i as f32 + 0.5) / n as f32, 16);
                    k as f32 * f
                })
                .sum::<f32>()
                / n as f32;
            assert!((kept - 1.0).abs() < 1e-3, "ratio {ratio}: {kept}");
        }
        assert_eq!(window(3.0, 0.5, 16), (3, 1.0 / 3.0));
        assert_eq!(window(40.0, 0.5, 16), (MAX_SPLIT, 1.0 / MAX_SPLIT as f32));
        assert_eq!(window(40.0, 0.5, 1), (2, 0.5));
        assert_eq!(window(40.0, 0.5, 0), (1, 1.0));
    }
}
