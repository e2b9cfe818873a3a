//! Delta (Woodcock) tracking: unbiased free-flight sampling against local
//! majorants, and its chromatic form, spectral tracking.

use glam::Vec3;

use crate::counters::Counters;
use crate::medium::Media;
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
    loop {
        match walk.next(rng, c) {
            Event::Enter(_) => {}
            Event::End => return FreeFlight::Escaped,
            Event::Capped => return FreeFlight::Capped,
            Event::Collision { t, segment, .. } => {
                let extinction =
                    |c: &mut Counters| lookup::<S, M>(medium, ray, t, segment.majorant, c);
                match S::collide(&segment, beta, rng, c, extinction) {
                    Collision::Real => {
                        c.real_collisions += 1;
                        return FreeFlight::Collision { t };
                    }
                    Collision::Null => c.null_collisions += 1,
                    Collision::Dead => return FreeFlight::Capped,
                }
            }
        }
    }
}
