//! Training the radiance cache: passes over the whole frame on a fixed
//! schedule, before the render.
//!
//! Pass `k` renders every pixel of the camera's full image (a crop
//! renders the same passes, so its cache, and its pixels, are the full
//! render's), following the cache as it was after pass `k - 1`, and the
//! cache then learns the pass's records tile by tile in tile order: the
//! cache after each pass is a function of the seed and the settings
//! alone, whatever the thread count. Training samples draw from their own
//! random streams and are not added to the image (Müller et al. 2017
//! discard theirs too: they follow worse guides than the render).

use std::time::Instant;

use rayon::prelude::*;

use super::learn::PathRecorder;
use super::regions::Record;
use super::{Decisions, Guide, GuidingStats};
use crate::camera::Camera;
use crate::medium::Bounds3;
use crate::ray::Ray;
use crate::sampling::{mix64, Draw, SampleStream, SamplerKind};
use crate::shutter::Shutter;
use crate::stats::Counters;

/// Keeps the training samples' numbers apart from the render's.
const TRAIN_DOMAIN: u64 = 0x7a11_9e1d_e5ca_c4e5;
/// Pixel rows and columns a training task renders.
const TILE: u32 = 16;
/// Tiles rendered before their records are learned (bounds the records
/// held at once).
const CHUNK_TILES: usize = 128;

/// The samples per pixel of each training pass.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TrainingSchedule {
    pub passes: Vec<u32>,
}

impl TrainingSchedule {
    /// Doubling passes, 1, 1, 2, 4, ... spp, a quarter of `spp` in all
    /// (at least 4, at most 32).
    pub fn for_spp(spp: u32) -> TrainingSchedule {
        let total = (spp / 4).clamp(4, 32);
        let mut passes = Vec::new();
        let (mut sum, mut next) = (0, 1);
        while sum < total {
            let n = next.min(total - sum);
            passes.push(n);
            sum += n;
            next = if passes.len() == 1 { 1 } else { next * 2 };
        }
        TrainingSchedule { passes }
    }

    pub fn total_spp(&self) -> u32 {
        self.passes.iter().sum()
    }
}

/// What the camera and sampler of a render are, for the training passes.
pub struct Frame<'a> {
    pub camera: &'a Camera,
    pub shutter: Shutter,
    pub sampler: SamplerKind,
    pub seed: u64,
}

/// Trains a cache over `bounds` on `schedule`: `trace(guide, ray,
/// draws, counters, recorder)` renders one camera sample guided by
/// `guide` (empty in the first pass) and records its path.
pub fn train<F>(
    bounds: Bounds3,
    decisions: Decisions,
    frame: &Frame,
    schedule: &TrainingSchedule,
    trace: F,
) -> (Guide, GuidingStats, Counters)
where
    F: Fn(&Guide, Ray, &mut SampleStream, &mut Counters, &mut PathRecorder) + Sync,
{
    let start = Instant::now();
    let mut guide = Guide::new(bounds, decisions);
    let mut counters = Counters::default();
    let (w, h) = (frame.camera.width(), frame.camera.height());
    let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let seed = mix64(frame.seed ^ TRAIN_DOMAIN);
    let (mut first, mut records) = (0u32, 0u64);
    for &spp in &schedule.passes {
        for chunk in tiles.chunks(CHUNK_TILES) {
            let learned: Vec<(Vec<Record>, Counters)> = chunk
                .par_iter()
                .map(|&(x0, y0)| {
                    let mut out = Vec::new();
                    let mut c = Counters::default();
                    let mut recorder = PathRecorder::new(&mut out);
                    for y in y0..(y0 + TILE).min(h) {
                        for x in x0..(x0 + TILE).min(w) {
                            let index = u64::from(y) * u64::from(w) + u64::from(x);
                            for s in first..first + spp {
                                let mut draws = SampleStream::new(frame.sampler, seed, index, s);
                                let (u, v) = draws.get_2d(Draw::PixelJitter, 0);
                                let time = frame.shutter.sample(&draws);
                                let ray = frame.camera.ray_at(x as f32 + u, y as f32 + v, time);
                                trace(&guide, ray, &mut draws, &mut c, &mut recorder);
                            }
                        }
                    }
                    (out, c)
                })
                .collect();
            for (out, c) in learned {
                records += out.len() as u64;
                counters += c;
                guide.accumulate(out);
            }
        }
        guide.regions.finish_pass();
        first += spp;
    }
    let stats = GuidingStats {
        mode: "on".into(),
        training_passes: schedule.passes.len() as u32,
        training_spp: schedule.total_spp(),
        training_seconds: start.elapsed().as_secs_f64(),
        regions: guide.regions.len(),
        memory_bytes: guide.memory_bytes(),
        records,
    };
    (guide, stats, counters)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedules_double_up_to_a_quarter_of_the_samples() {
        assert_eq!(TrainingSchedule::for_spp(64).passes, vec![1, 1, 2, 4, 8]);
        assert_eq!(TrainingSchedule::for_spp(4).passes, vec![1, 1, 2]);
        assert_eq!(TrainingSchedule::for_spp(40).passes, vec![1, 1, 2, 4, 2]);
        assert_eq!(TrainingSchedule::for_spp(4096).total_spp(), 32);
    }
}
