//! Ratio tracking.

use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::spectrum::Spectrum;

use super::lookup::lookup;
use crate::counters::Counters;

use super::walk::{Event, Walk};

/// Transmittance along `ray` over `[0, t_max]` by ratio tracking (Novak,
/// Selle, Jarosz 2014, eq. 6), per channel of `S`: `T = product over
/// tentative collisions of (1 - sigma_t / sigma_maj)`
/// ([`Spectrum::null_fraction`]), Russian-rouletted once small. The
/// majorant bounds every channel, so one walk serves all three.
pub fn ratio_tracking<S: Spectrum, M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    c: &mut Counters,
) -> S {
    c.shadow_rays += 1;
    let segments = medium.majorants(ray.origin, ray.dir, 0.0, t_max);
    let mut walk = Walk::new(segments, false, rng);
    let mut tr = S::ONE;
    loop {
        match walk.next(rng, c) {
            Event::Enter(_) => {}
            Event::End => return tr,
            Event::Capped => return S::ZERO,
            Event::Collision { t, segment, .. } => {
                c.shadow_collisions += 1;
                let sigma: S = lookup(medium, ray, t, segment.majorant, c);
                tr = tr.mul(S::null_fraction(sigma, segment.majorant));
                if !tr.roulette(rng) {
                    return S::ZERO;
                }
            }
        }
    }
}
