//! Jittered fixed-step ray marching, shared by both marchers.
//!
//! Sample points sit on the lattice `t_k = t_org + (k + u) h` with one
//! uniform `u` per ray, so that `sum of sigma(t_k) h` is an unbiased
//! estimate of the optical depth (stratified sampling); the marchers' only
//! bias is the step's quadrature of `exp` (Jensen), which vanishes as
//! `h -> 0`. Only lattice points inside segments with a non-zero majorant are
//! visited: every other point has density 0 and would add nothing, so
//! skipping empty space leaves the estimate unchanged and only saves
//! lookups (OpenVDB's `vdb_render` marches through everything).

use glam::Vec3;

use super::{escaped_radiance, Sample};
use crate::light::Lights;
use crate::medium::Media;
use crate::phase::Phase;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::stats::Counters;
use crate::tracking::roulette;

/// Shadow marches stop once the optical depth passes this: `exp(-30)` is
/// below 1e-13, far under any pixel's noise.
const TAU_CUTOFF: f32 = 30.0;

/// Smallest accepted step in voxels, so a bad setting cannot stall.
pub const MIN_STEP_VOXELS: f32 = 1e-3;

/// Calls `visit(t, sigma_t, counters)` at each jittered lattice point along
/// `ray` within `[0, t_max]`; `visit` returns false to stop.
pub(crate) fn march<M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    h: f32,
    u: f32,
    c: &mut Counters,
    mut visit: impl FnMut(f32, f32, &mut Counters) -> bool,
) {
    let mut origin = None;
    let mut next_k = 0i64;
    for s in medium.majorants(ray.origin, ray.dir, 0.0, t_max) {
        c.dda_segments += 1;
        if s.majorant.is_nan() || s.majorant <= 0.0 {
            continue;
        }
        let org = *origin.get_or_insert(s.t0);
        // First lattice point at or after the segment's start; never revisit
        // one that rounding placed in the previous segment too.
        let mut k = next_k.max(((s.t0 - org) / h - u).ceil() as i64);
        loop {
            let t = org + (k as f32 + u) * h;
            if t >= s.t1 {
                break;
            }
            k += 1;
            c.density_lookups += 1;
            let sigma = medium.sigma_t(ray.at(t));
            if !visit(t, sigma, c) {
                return;
            }
        }
        next_k = k;
    }
}

/// `exp(-tau)` with `tau` the jittered-march estimate of the optical depth
/// from `p` toward `dir` (to infinity); counts one shadow ray.
pub(crate) fn marched_transmittance<M: Media>(
    medium: &M,
    p: Vec3,
    dir: Vec3,
    h: f32,
    rng: &mut Rng,
    c: &mut Counters,
) -> f32 {
    c.shadow_rays += 1;
    let mut tau = 0.0;
    let ray = Ray::new(p, dir);
    march(
        medium,
        &ray,
        f32::INFINITY,
        h,
        rng.uniform(),
        c,
        |_, sigma, _| {
            tau += sigma * h;
            tau < TAU_CUTOFF
        },
    );
    (-tau).exp()
}

/// Marches a camera ray, accumulating single scattering step by step:
/// `L += T * (1 - exp(-sigma h)) * albedo * S(p)`, then `T *= exp(-sigma h)`
/// (the step treated as homogeneous, which stays energy-conserving when a
/// step is optically thick), where `in_scatter(p, dir)` returns `S`, the
/// phase-weighted light arriving at `p` for the given phase function. With
/// several media the instance at each step is chosen with probability
/// `sigma_t,i / sigma_t` (its albedo and phase are then unbiased for the
/// mixture's); emission adds `(1 - albedo) * Le` to the step's source,
/// the marched form of `sigma_a Le`. The background is added through the
/// final `T`; `T` is Russian-rouletted like the trackers' estimates, so the
/// march stops early in dense media without bias with respect to the march.
pub(crate) fn march_camera_ray<M: Media>(
    medium: &M,
    lights: &Lights,
    ray: &Ray,
    h: f32,
    rng: &mut Rng,
    c: &mut Counters,
    mut in_scatter: impl FnMut(Vec3, &Phase, &mut Rng, &mut Counters) -> Vec3,
) -> Sample {
    c.paths += 1;
    let emits = medium.emits();
    let mut tr = 1.0f32;
    let mut l = Vec3::ZERO;
    let u = rng.uniform();
    march(medium, ray, f32::INFINITY, h, u, c, |t, sigma, c| {
        if sigma.is_nan() || sigma <= 0.0 {
            return true;
        }
        let step_tr = (-sigma * h).exp();
        let p = ray.at(t);
        let it = medium.interaction(p, rng);
        let mut source = it.albedo * in_scatter(p, it.phase, rng, c);
        if emits {
            source += (Vec3::ONE - it.albedo) * medium.emission(p, it.instance, c);
        }
        l += (tr * (1.0 - step_tr)) * source;
        tr *= step_tr;
        roulette(&mut tr, rng)
    });
    l += tr * escaped_radiance(lights, ray.dir, None, c);
    Sample {
        radiance: l,
        alpha: 1.0 - tr,
        ..Default::default()
    }
}
