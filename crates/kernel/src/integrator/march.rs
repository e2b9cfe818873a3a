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
//!
//! Every function is generic over [`Spectrum`]: `f32` for grey media (one
//! extinction, one transmittance) and `Vec3` for chromatic ones, where
//! each step looks the three channels up at once and attenuates them
//! apart. The grey instantiation is the scalar march itself.

use glam::Vec3;

use super::{escaped_radiance, LightParts, Sample};
use crate::counters::Counters;
use crate::light::GroupRadiance;
use crate::light::Lights;
use crate::medium::{Lattice, Media};
use crate::phase::Phase;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::spectrum::Spectrum;
use crate::tracking::{ROULETTE_Q, ROULETTE_THRESHOLD};

/// Shadow marches stop once the optical depth passes this: `exp(-30)` is
/// below 1e-13, far under any pixel's noise.
const TAU_CUTOFF: f32 = 30.0;

/// Smallest accepted step in voxels, so a bad setting cannot stall.
pub const MIN_STEP_VOXELS: f32 = 1e-3;

/// Calls `visit(t, sigma_t, counters)` at each jittered lattice point along
/// `ray` within `[0, t_max]` where the extinction may be non-zero
/// ([`Media::march_lattice`]); `visit` returns false to stop. Media whose
/// channels share one tint look one scalar up per point; others look each
/// channel up.
pub(crate) fn march<M: Media, E: Spectrum>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    h: f32,
    u: f32,
    c: &mut Counters,
    mut visit: impl FnMut(f32, E, &mut Counters) -> bool,
) {
    let lattice = Lattice::new(h, u);
    let steps = match medium.uniform_tint() {
        Some(tint) => medium.march_lattice(ray.origin, ray.dir, t_max, lattice, |t, sigma| {
            c.density_lookups += 1;
            visit(t, E::tinted(sigma, tint), c)
        }),
        None => lattice.visit_segments(medium.majorants(ray.origin, ray.dir, 0.0, t_max), |t| {
            c.density_lookups += 1;
            visit(t, medium.extinction::<E>(ray.at(t), 0.0), c)
        }),
    };
    c.dda_segments += steps;
}

/// How a marched shadow ray ends inside a dense medium.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ShadowEnd {
    /// At an optical depth of [`TAU_CUTOFF`]: deterministic, for values
    /// that are cached and reused (the light grid), where a rouletted
    /// estimate's noise would be baked in.
    Cutoff,
    /// By Russian roulette once the transmittance falls below the
    /// trackers' threshold ([`Spectrum::roulette`]): unbiased with respect to the
    /// march, and a ray into a thick cloud stops after an optical depth
    /// of about 3 (with survivors re-weighted) instead of 30. For shadow
    /// rays drawn afresh at every step, whose noise averages out.
    Roulette,
}

/// The jittered-march estimate of the transmittance from `p` toward `dir`
/// over distance `t_max` (infinite toward lights at infinity):
/// `exp(-tau)`, ended as `end` says; counts one shadow ray.
#[allow(clippy::too_many_arguments)]
pub(crate) fn marched_transmittance<M: Media, E: Spectrum>(
    medium: &M,
    p: Vec3,
    dir: Vec3,
    t_max: f32,
    h: f32,
    end: ShadowEnd,
    rng: &mut Rng,
    c: &mut Counters,
) -> E {
    c.shadow_rays += 1;
    let ray = Ray::new(p, dir);
    let u = rng.uniform();
    match end {
        ShadowEnd::Cutoff => {
            let mut tau = E::ZERO;
            march(medium, &ray, t_max, h, u, c, |_, sigma: E, _| {
                tau = tau.add(sigma.scale(h));
                tau.min_channel() < TAU_CUTOFF
            });
            tau.exp_neg()
        }
        ShadowEnd::Roulette => {
            // The estimate is `w exp(-tau)`. It is rouletted as the
            // trackers' estimates are ([`Spectrum::roulette`]) once its largest
            // channel falls below the threshold, that is once every
            // channel's optical depth passes `ln(w / threshold)`: so the
            // march sums optical depth and takes no `exp` per step.
            let mut tau = E::ZERO;
            let mut w = 1.0f32;
            let mut tau_roulette = ROULETTE_THRESHOLD.recip().ln();
            let mut survived = true;
            march(medium, &ray, t_max, h, u, c, |_, sigma: E, _| {
                if !sigma.any_positive() {
                    return true;
                }
                tau = tau.add(sigma.scale(h));
                if tau.min_channel() <= tau_roulette {
                    return true;
                }
                if rng.uniform() < ROULETTE_Q {
                    survived = false;
                    return false;
                }
                w /= 1.0 - ROULETTE_Q;
                tau_roulette = (w / ROULETTE_THRESHOLD).ln();
                true
            });
            if survived {
                tau.exp_neg().scale(w)
            } else {
                E::ZERO
            }
        }
    }
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
/// Chromatic media (`E = Vec3`) attenuate each channel by its own
/// extinction, the chosen instance's source weighted per channel by
/// [`Interaction::weight`](crate::medium::Interaction); alpha is the
/// channels' mean `1 - T`.
pub(crate) fn march_camera_ray<M: Media, E: Spectrum>(
    medium: &M,
    lights: &Lights,
    ray: &Ray,
    h: f32,
    rng: &mut Rng,
    c: &mut Counters,
    mut in_scatter: impl FnMut(Vec3, &Phase, &mut Rng, &mut Counters) -> LightParts,
) -> Sample {
    c.paths += 1;
    let emits = medium.emits();
    let chromatic = medium.chromatic();
    let mut tr = E::ONE;
    let mut l = Vec3::ZERO;
    let mut groups = GroupRadiance::default();
    // Opacity of the holdout volumes' steps: cut from alpha, as a matte.
    let mut held = 0.0f32;
    let u = rng.uniform();
    march(medium, ray, ray.t_max, h, u, c, |t, sigma: E, c| {
        if !sigma.any_positive() {
            return true;
        }
        let step_tr = sigma.scale(h).exp_neg();
        let p = ray.at(t);
        let it = medium.interaction(p, 0.0, rng);
        let parts = in_scatter(p, it.phase, rng, c);
        let mut source = it.albedo * parts.total();
        let mut emitted = Vec3::ZERO;
        if emits {
            emitted = (Vec3::ONE - it.albedo) * medium.emission(p, 0.0, it.instance, c);
            source += emitted;
        }
        let weight = if chromatic { it.weight } else { Vec3::ONE };
        if chromatic {
            source *= it.weight;
        }
        let step = tr.mul(step_tr.one_minus());
        if it.holdout {
            held += step.mean();
        } else {
            l += step.tint(source);
            parts.tag_scaled(step.tint(it.albedo * weight), &mut groups);
            groups[lights.emission_group()] += step.tint(emitted * weight);
        }
        tr = tr.mul(step_tr);
        tr.roulette(rng)
    });
    // A ray ended by a depth holdout sees nothing behind it.
    if ray.t_max.is_infinite() {
        let parts = escaped_radiance(lights, ray.dir, None, c);
        l += tr.tint(parts.total());
        parts.tag_scaled(tr.tint(Vec3::ONE), &mut groups);
    }
    Sample {
        radiance: l,
        alpha: 1.0 - tr.mean() - held,
        groups,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::medium::{GridField, Medium};
    use crate::Volumes;

    /// Rouletted shadow marches keep the march's mean: from start points
    /// whose optical depth to the far side runs from about 0.5 to 6.6 (the
    /// deeper ones rouletted, as they fall below 0.05 on the way), 40,000
    /// rouletted estimates per point average to the deterministic march
    /// within 5 standard errors, while looking up far fewer points.
    #[test]
    fn rouletted_shadow_marches_keep_the_mean_and_stop_sooner() {
        // 32^3 voxels of density rising along x; extinction 0.3 per voxel.
        let field = GridField::from_fn([32, 32, 32], Vec3::ZERO, 1.0, 4, |i, _, _| {
            0.25 + (i as f32 / 31.0)
        });
        let medium = Volumes::from(Medium::new(field, 0.3, Vec3::splat(0.9), 0.0));
        let dir = Vec3::new(1.0, 0.05, -0.02).normalize();
        let h = 1.5;
        let mut rng = Rng::new(11, 0, 0);
        let (mut cutoff_lookups, mut roulette_lookups) = (0u64, 0u64);
        for x in [2.0, 12.0, 24.0, 30.0] {
            let p = Vec3::new(x, 16.0, 16.0);
            let n = 40_000;
            let (mut exact, mut exact2, mut sum, mut sum2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
            for _ in 0..n {
                let mut c = Counters::default();
                let e: f32 = marched_transmittance(
                    &medium,
                    p,
                    dir,
                    f32::INFINITY,
                    h,
                    ShadowEnd::Cutoff,
                    &mut rng,
                    &mut c,
                );
                cutoff_lookups += c.density_lookups;
                let mut c = Counters::default();
                let r: f32 = marched_transmittance(
                    &medium,
                    p,
                    dir,
                    f32::INFINITY,
                    h,
                    ShadowEnd::Roulette,
                    &mut rng,
                    &mut c,
                );
                roulette_lookups += c.density_lookups;
                exact += f64::from(e);
                exact2 += f64::from(e) * f64::from(e);
                sum += f64::from(r);
                sum2 += f64::from(r) * f64::from(r);
            }
            let n = f64::from(n);
            // The cutoff march is itself jittered: its spread counts too.
            let mean = sum / n;
            let exact = exact / n;
            let var = (sum2 / n - mean * mean) / n + (exact2 / n - exact * exact) / n;
            let se = var.sqrt();
            assert!(exact > 1e-4, "start {x}: {exact}");
            assert!(
                (mean - exact).abs() <= 5.0 * se,
                "start {x}: rouletted {mean} +- {se}, cutoff {exact}"
            );
        }
        assert!(
            roulette_lookups * 10 < cutoff_lookups * 8,
            "{roulette_lookups} vs {cutoff_lookups}"
        );
    }
}
