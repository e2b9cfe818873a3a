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
    Flight::start(medium, ray, t_max, beta, rng).finish::<S, _>(medium, c)
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
    let mut a = Flight::start(medium, ra, t_max[0], ba, ga);
    let mut b = Flight::start(medium, rb, t_max[1], bb, gb);
    loop {
        if let Some(fa) = a.event::<S, _>(medium, c) {
            return [fa, b.finish::<S, _>(medium, c)];
        }
        if let Some(fb) = b.event::<S, _>(medium, c) {
            return [a.finish::<S, _>(medium, c), fb];
        }
    }
}

/// A free flight under way: its ray, its majorant walk, its weight and its
/// generator.
struct Flight<'a, I> {
    ray: &'a Ray,
    walk: Walk<I>,
    beta: &'a mut Vec3,
    rng: &'a mut Rng,
}

impl<'a, I: Iterator<Item = MajorantSegment>> Flight<'a, I> {
    /// The flight along `ray` up to `t_max`, its first optical depth drawn.
    #[inline(always)]
    fn start<M: Media<Majorants<'a> = I>>(
        medium: &'a M,
        ray: &'a Ray,
        t_max: f32,
        beta: &'a mut Vec3,
        rng: &'a mut Rng,
    ) -> Self {
        let segments = medium.majorants(ray.origin, ray.dir, 0.0, t_max);
        let walk = Walk::new(segments, false, rng);
        Self {
            ray,
            walk,
            beta,
            rng,
        }
    }

    /// Steps the walk to where the flight ends.
    #[inline(always)]
    fn finish<S: Spectrum, M: Media>(&mut self, medium: &M, c: &mut Counters) -> FreeFlight {
        loop {
            if let Some(flight) = self.event::<S, M>(medium, c) {
                return flight;
            }
        }
    }

    /// One event of the walk, decided by [`Spectrum::collide`]: where the
    /// flight ended, or `None` while it goes on.
    #[inline(always)]
    fn event<S: Spectrum, M: Media>(&mut self, medium: &M, c: &mut Counters) -> Option<FreeFlight> {
        match self.walk.next(self.rng, c) {
            Event::Enter(_) => None,
            Event::End => Some(FreeFlight::Escaped),
            Event::Capped => Some(FreeFlight::Capped),
            Event::Collision { t, segment, .. } => {
                let ray = self.ray;
                let extinction =
                    |c: &mut Counters| lookup::<S, M>(medium, ray, t, segment.majorant, c);
                match S::collide(&segment, self.beta, self.rng, c, extinction) {
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
}
