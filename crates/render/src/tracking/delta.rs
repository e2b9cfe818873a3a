//! Delta (Woodcock) tracking: unbiased free-flight sampling against local
//! majorants.

use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::stats::Counters;

use super::lookup;
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
    /// The collision cap was hit; callers end the path.
    Capped,
}

/// Samples the distance to the first real collision along `ray` within
/// `[0, t_max]` with density `sigma_t(t) exp(-integral of sigma_t)`.
///
/// Tentative collisions come from the majorant walk; one at `t` is real
/// with probability `sigma_t(t) / sigma_maj` (Woodcock et al. 1965; pbrt-v4
/// `SampleT_maj` with its absorption and scattering events merged, since the
/// path integrator weights by albedo). When `xi * sigma_maj` falls below
/// the segment's minorant the collision is real whatever the density, so it
/// is accepted without a lookup: the same decision with the same random
/// number, only cheaper (the control part of decomposition tracking, Kutz
/// et al. 2017).
pub fn sample_free_flight<M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
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
                let xi = rng.uniform() * segment.majorant;
                if xi < segment.minorant || xi < lookup(medium, ray, t, segment.majorant, c) {
                    c.real_collisions += 1;
                    return FreeFlight::Collision { t };
                }
                c.null_collisions += 1;
            }
        }
    }
}
