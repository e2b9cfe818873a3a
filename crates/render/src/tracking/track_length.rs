//! The track-length transmittance estimator.

use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::stats::Counters;

use super::delta::{sample_free_flight, FreeFlight};

/// `T = 1` if a delta-tracked free flight escapes `[0, t_max]`, else 0: a
/// Bernoulli variable with mean `T` (the escape probability). It stops at
/// the first real collision, so it is cheap in dense media, but it has the
/// largest variance of the three estimators (`T (1 - T)`).
pub fn track_length_transmittance<M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    c: &mut Counters,
) -> f32 {
    c.shadow_rays += 1;
    match sample_free_flight(medium, ray, t_max, rng, c) {
        FreeFlight::Escaped => 1.0,
        FreeFlight::Collision { .. } | FreeFlight::Capped => 0.0,
    }
}
