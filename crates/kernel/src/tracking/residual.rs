//! Residual ratio tracking.

use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::spectrum::Spectrum;

use super::lookup::lookup;
use crate::counters::Counters;

use super::walk::{Event, Walk};

/// Transmittance along `ray` over `[0, t_max]` by residual ratio tracking
/// (Novak, Selle, Jarosz 2014, section 5, eq. 12) with each segment's
/// minorant as the control `sigma_c`:
///
/// `T = exp(-integral of sigma_c) * product of (1 - (sigma_t - sigma_c) / (sigma_maj - sigma_c))`,
///
/// the control part in closed form per segment, and tentative collisions
/// drawn at the residual rate `sigma_maj - sigma_c`. Where the segment is
/// constant (`sigma_maj == sigma_c`) the residual rate is 0: no collisions,
/// and the segment's transmittance is exact. Grey media only: the
/// segments' minorant bounds the largest channel, no control for each.
pub fn residual_ratio_tracking<M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
    c: &mut Counters,
) -> f32 {
    c.shadow_rays += 1;
    let segments = medium.majorants(ray.origin, ray.dir, 0.0, t_max);
    let mut walk = Walk::new(segments, true, rng);
    let mut tr = 1.0f32;
    loop {
        match walk.next(rng, c) {
            Event::End => return tr,
            Event::Capped => return 0.0,
            Event::Enter(segment) => {
                if segment.minorant > 0.0 {
                    tr *= (-segment.minorant * (segment.t1 - segment.t0)).exp();
                    if !tr.roulette(rng) {
                        return 0.0;
                    }
                }
            }
            Event::Collision { t, segment, rate } => {
                c.shadow_collisions += 1;
                let sigma: f32 = lookup(medium, ray, t, segment.majorant, c);
                tr *= (1.0 - (sigma - segment.minorant) / rate).max(0.0);
                if !tr.roulette(rng) {
                    return 0.0;
                }
            }
        }
    }
}
