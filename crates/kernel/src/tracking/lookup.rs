//! The density lookup every tracker makes at a tentative collision.

use crate::counters::Counters;
use crate::medium::Media;
use crate::ray::Ray;
use crate::spectrum::Spectrum;

/// Extinction at a tentative collision, at the ray's time, counted, with
/// majorant violations (density above the segment's bound) counted too.
#[inline]
pub(crate) fn lookup<S: Spectrum, M: Media>(
    medium: &M,
    ray: &Ray,
    t: f32,
    majorant: f32,
    c: &mut Counters,
) -> S {
    c.density_lookups += 1;
    let sigma: S = medium.extinction(ray.at(t), ray.time);
    // A relative slack of 1e-5 forgives the f32 rounding of interpolation.
    if sigma.max_channel() > majorant * (1.0 + 1e-5) {
        c.majorant_violations += 1;
    }
    sigma.clamp_to_majorant(majorant)
}
