//! The track-length transmittance estimator.

use glam::Vec3;

use crate::counters::Counters;
use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::spectrum::Spectrum;

use super::delta::{sample_free_flight, FreeFlight};

/// `T = 1` if a delta-tracked free flight escapes `[0, t_max]`, else 0: a
/// Bernoulli variable with mean `T` (the escape probability). It stops at
/// the first real collision, so it is cheap in dense media, but it has the
/// largest variance of the three estimators (`T (1 - T)`). A chromatic
/// flight (spectral tracking) escapes with its null-collision weights,
/// whose expectation is each channel's `T`.
pub fn track_length_transmittance<S: Spectrum, M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    c: &mut Counters,
) -> S {
    c.shadow_rays += 1;
    let mut weight = Vec3::ONE;
    match sample_free_flight::<S, M>(medium, ray, t_max, &mut weight, rng, c) {
        FreeFlight::Escaped if S::CHROMATIC => S::tinted(1.0, weight),
        FreeFlight::Escaped => S::ONE,
        FreeFlight::Collision { .. } | FreeFlight::Capped => S::ZERO,
    }
}
