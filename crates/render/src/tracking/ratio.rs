//! Ratio tracking.

use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::stats::Counters;

use super::walk::{Event, Walk};
use super::{lookup, roulette};

/// Transmittance along `ray` over `[0, t_max]` by ratio tracking (Novak,
/// Selle, Jarosz 2014, eq. 6): `T = product over tentative collisions of
/// (1 - sigma_t / sigma_maj)`. A weight is clamped at 0 where the density
/// exceeds its majorant (as pbrt-v4 clamps `sigma_n`), and the estimate is
/// Russian-rouletted once small.
pub fn ratio_tracking<M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    c: &mut Counters,
) -> f32 {
    c.shadow_rays += 1;
    let segments = medium.majorants(ray.origin, ray.dir, 0.0, t_max);
    let mut walk = Walk::new(segments, false, rng);
    let mut tr = 1.0f32;
    loop {
        match walk.next(rng, c) {
            Event::Enter(_) => {}
            Event::End => return tr,
            Event::Capped => return 0.0,
            Event::Collision { t, segment, .. } => {
                c.shadow_collisions += 1;
                let sigma = lookup(medium, ray, t, segment.majorant, c);
                tr *= (1.0 - sigma / segment.majorant).max(0.0);
                if !roulette(&mut tr, rng) {
                    return 0.0;
                }
            }
        }
    }
}
