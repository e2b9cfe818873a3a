//! Trackers for chromatic media, whose extinction differs per RGB channel.
//!
//! The majorant segments bound the largest channel ([`Media::sigma_t`]),
//! so one walk serves all three channels; what changes is how a tentative
//! collision is decided and weighted.
//!
//! - Free flights use spectral tracking (Kutz, Habel, Li, Novak 2017,
//!   "Spectral and Decomposition Tracking for Rendering Heterogeneous
//!   Volumes", section 4, with the history-aware probabilities of its
//!   eq. 16): a tentative collision at `x` is real with probability
//!   `P_r = avg(beta sigma_t(x)) / (sigma_maj avg(beta))` and null
//!   otherwise, and the path throughput `beta` is multiplied by
//!   `sigma_t / (sigma_maj P_r)` or `sigma_n / (sigma_maj P_n)` per channel.
//!   Every channel's estimate is unbiased whatever the probabilities, as
//!   long as they are positive wherever the channel's coefficient is; the
//!   averages over `beta`-weighted coefficients keep the weights bounded
//!   (each factor is at most 3 / the channel's share of `avg(beta)`). The
//!   role is that of pbrt-v4's hero-wavelength spectral MIS (`r_u`, `r_l`,
//!   Miller et al. 2019); with fixed RGB channels the probabilities can
//!   use all three channels at once. With equal channels it is delta
//!   tracking: `P_r = sigma_t / sigma_maj` and the weights are 1.
//! - Transmittance is ratio tracking per channel (Novak et al. 2014,
//!   eq. 6): `T_c = product of (1 - sigma_t,c / sigma_maj)`; every factor
//!   lies in [0, 1] since the majorant bounds every channel. Residual
//!   ratio tracking would need a control per channel, which the segments
//!   (one minorant, of the largest channel's extinction over all
//!   instances) do not give; chromatic media use ratio tracking for it.
//!   Track-length estimation returns the spectral flight's escape weight.

use glam::Vec3;

use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::stats::Counters;

use super::walk::{Event, Walk};
use super::{FreeFlight, TransmittanceEstimator, ROULETTE_Q, ROULETTE_THRESHOLD};

/// Per-channel extinction at a tentative collision, counted like
/// [`super::lookup`], clamped to the majorant (as pbrt-v4 clamps
/// `sigma_n` at 0).
#[inline]
fn lookup_rgb<M: Media>(medium: &M, ray: &Ray, t: f32, sigma_maj: f32, c: &mut Counters) -> Vec3 {
    c.density_lookups += 1;
    let sigma = medium.sigma_t_rgb_at(ray.at(t), ray.time);
    if sigma.max_element() > sigma_maj * (1.0 + 1e-5) {
        c.majorant_violations += 1;
    }
    sigma.min(Vec3::splat(sigma_maj)).max(Vec3::ZERO)
}

/// Samples a free flight along `ray` within `[0, t_max]` by spectral
/// tracking, multiplying `beta` by the flight's weights (see the module
/// documentation). On escape `beta` carries the null-collision weights,
/// whose expectation is each channel's transmittance; at a collision it
/// also carries `sigma_t / (sigma_maj P_r)`, so that multiplying by the
/// albedo gives the scattering term.
pub fn sample_free_flight_spectral<M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    beta: &mut Vec3,
    rng: &mut Rng,
    c: &mut Counters,
) -> FreeFlight {
    let segments = medium.majorants(ray.origin, ray.dir, 0.0, t_max);
    let mut walk = Walk::new(segments, false, rng);
    loop {
        match walk.next(rng, c) {
            Event::Enter(_) => {}
            Event::End => return FreeFlight::Escaped,
            Event::Capped => return FreeFlight::Capped,
            Event::Collision { t, segment, .. } => {
                let maj = segment.majorant;
                let sigma = lookup_rgb(medium, ray, t, maj, c);
                let mean_beta = beta.element_sum();
                if mean_beta.is_nan() || mean_beta <= 0.0 {
                    // A dead path (or a NaN one): nothing left to weight.
                    *beta = Vec3::ZERO;
                    return FreeFlight::Capped;
                }
                // Sums rather than averages: the factor 3 cancels.
                let p_real = ((*beta * sigma).element_sum() / (maj * mean_beta)).clamp(0.0, 1.0);
                if rng.uniform() < p_real {
                    *beta *= sigma / (maj * p_real);
                    c.real_collisions += 1;
                    return FreeFlight::Collision { t };
                }
                *beta *= (Vec3::splat(maj) - sigma) / (maj * (1.0 - p_real));
                c.null_collisions += 1;
            }
        }
    }
}

/// Per-channel transmittance along `ray` over `[0, t_max]` (see the module
/// documentation for which estimator runs); counts one shadow ray.
pub fn transmittance_rgb<M: Media>(
    estimator: TransmittanceEstimator,
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    c: &mut Counters,
) -> Vec3 {
    match estimator {
        TransmittanceEstimator::Ratio | TransmittanceEstimator::Residual => {
            ratio_tracking_rgb(medium, ray, t_max, rng, c)
        }
        TransmittanceEstimator::TrackLength => {
            c.shadow_rays += 1;
            let mut w = Vec3::ONE;
            match sample_free_flight_spectral(medium, ray, t_max, &mut w, rng, c) {
                FreeFlight::Escaped => w,
                FreeFlight::Collision { .. } | FreeFlight::Capped => Vec3::ZERO,
            }
        }
    }
}

/// Ratio tracking per channel, with pbrt-v4's Russian roulette on the
/// largest channel.
pub fn ratio_tracking_rgb<M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    c: &mut Counters,
) -> Vec3 {
    c.shadow_rays += 1;
    let segments = medium.majorants(ray.origin, ray.dir, 0.0, t_max);
    let mut walk = Walk::new(segments, false, rng);
    let mut tr = Vec3::ONE;
    loop {
        match walk.next(rng, c) {
            Event::Enter(_) => {}
            Event::End => return tr,
            Event::Capped => return Vec3::ZERO,
            Event::Collision { t, segment, .. } => {
                c.shadow_collisions += 1;
                let maj = segment.majorant;
                let sigma = lookup_rgb(medium, ray, t, maj, c);
                tr *= Vec3::ONE - sigma / maj;
                if !roulette_rgb(&mut tr, rng) {
                    return Vec3::ZERO;
                }
            }
        }
    }
}

/// [`super::roulette`] on the largest channel: the whole estimate lives or
/// dies together, so every channel's expectation is unchanged.
#[inline]
pub(crate) fn roulette_rgb(tr: &mut Vec3, rng: &mut Rng) -> bool {
    let m = tr.max_element();
    if m.is_nan() || m <= 0.0 {
        *tr = Vec3::ZERO;
        return false;
    }
    if m < ROULETTE_THRESHOLD {
        if rng.uniform() < ROULETTE_Q {
            *tr = Vec3::ZERO;
            return false;
        }
        *tr /= 1.0 - ROULETTE_Q;
    }
    true
}
