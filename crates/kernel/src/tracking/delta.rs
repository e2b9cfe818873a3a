//! Delta (Woodcock) tracking: unbiased free-flight sampling against local
//! majorants, and its chromatic form, spectral tracking.

use glam::Vec3;

use crate::counters::Counters;
use crate::medium::{MajorantSegment, Media};
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::spectrum::{Collision, Spectrum};

use super::lookup::lookup;
use super::walk::{Event, Walk};

/// Where a free flight ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FreeFlight {
    /// No real collision before `t_max`: the flight escaped. Its probability
    /// is the transmittance, which makes the escape indicator the
    /// track-length transmittance estimator.
    Escaped,
    /// A real collision at ray parameter `t`.
    Collision { t: f32 },
    /// The collision cap was hit, or the path's weight died; callers end
    /// the path.
    Capped,
}

/// Samples the distance to the first real collision along `ray` within
/// `[0, t_max]` with density `sigma_t(t) exp(-integral of sigma_t)`.
///
/// Tentative collisions come from the majorant walk; each is decided by
/// [`Spectrum::collide`]: delta tracking for a grey medium (`beta`
/// untouched), spectral tracking for a chromatic one, which multiplies
/// `beta` by the flight's weights. On escape `beta` then carries the
/// null-collision weights, whose expectation is each channel's
/// transmittance; at a collision it also carries `sigma_t / (sigma_maj
/// P_r)`, so that multiplying by the albedo gives the scattering term.
pub fn sample_free_flight<S: Spectrum, M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    beta: &mut Vec3,
    rng: &mut Rng,
    c: &mut Counters,
) -> FreeFlight {
    let segments = medium.majorants(ray.origin, ray.dir, 0.0, t_max);
    let mut walk = Walk::new(segments, false, rng);
    finish_flight::<S, _, _>(medium, ray, &mut walk, beta, rng, c)
}

/// Two free flights at once, as [`sample_free_flight`] samples each: their
/// walks advance in turn, one event each, until one ends; the other then
/// goes on alone. Each flight draws only from its own generator, so each
/// ends exactly where it would alone; what changes is that an out-of-order
/// core overlaps the two flights' chains of dependent steps.
///
/// Written out for two rather than for N lanes: a loop over arrays of
/// walks cost more in bookkeeping than the overlap gave (BENCHMARKS.md,
/// "How busy a core is"). `cirrus bench interleave` measures this pair
/// against flights one at a time.
pub fn sample_free_flight_pair<S: Spectrum, M: Media>(
    medium: &M,
    rays: [&Ray; 2],
    t_max: [f32; 2],
    betas: [&mut Vec3; 2],
    rngs: [&mut Rng; 2],
    c: &mut Counters,
) -> [FreeFlight; 2] {
    let ([ra, rb], [ba, bb], [ga, gb]) = (rays, betas, rngs);
    let mut wa = Walk::new(
        medium.majorants(ra.origin, ra.dir, 0.0, t_max[0]),
        false,
        ga,
    );
    let mut wb = Walk::new(
        medium.majorants(rb.origin, rb.dir, 0.0, t_max[1]),
        false,
        gb,
    );
    loop {
        if let Some(fa) = flight_event::<S, _, _>(medium, ra, &mut wa, ba, ga, c) {
            return [fa, finish_flight::<S, _, _>(medium, rb, &mut wb, bb, gb, c)];
        }
        if let Some(fb) = flight_event::<S, _, _>(medium, rb, &mut wb, bb, gb, c) {
            return [finish_flight::<S, _, _>(medium, ra, &mut wa, ba, ga, c), fb];
        }
    }
}

/// Steps a free flight's walk to where the flight ends.
#[inline(always)]
fn finish_flight<S: Spectrum, M: Media, I: Iterator<Item = MajorantSegment>>(
    medium: &M,
    ray: &Ray,
    walk: &mut Walk<I>,
    beta: &mut Vec3,
    rng: &mut Rng,
    c: &mut Counters,
) -> FreeFlight {
    loop {
        if let Some(flight) = flight_event::<S, _, _>(medium, ray, walk, beta, rng, c) {
            return flight;
        }
    }
}

/// One event of a free flight's walk, decided by [`Spectrum::collide`]:
/// where the flight ended, or `None` while it goes on.
#[inline(always)]
fn flight_event<S: Spectrum, M: Media, I: Iterator<Item = MajorantSegment>>(
    medium: &M,
    ray: &Ray,
    walk: &mut Walk<I>,
    beta: &mut Vec3,
    rng: &mut Rng,
    c: &mut Counters,
) -> Option<FreeFlight> {
    match walk.next(rng, c) {
        Event::Enter(_) => None,
        Event::End => Some(FreeFlight::Escaped),
        Event::Capped => Some(FreeFlight::Capped),
        Event::Collision { t, segment, .. } => {
            let extinction = |c: &mut Counters| lookup::<S, M>(medium, ray, t, segment.majorant, c);
            match S::collide(&segment, beta, rng, c, extinction) {
                Collision::Real => {
                    c.real_collisions += 1;
                    Some(FreeFlight::Collision { t })
                }
                Collision::Null => {
                    c.null_collisions += 1;
                    None
                }
                Collision::Dead => Some(FreeFlight::Capped),
            }
        }
    }
}
