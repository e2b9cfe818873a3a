//! Single scattering by ray marching: OpenVDB `vdb_render`'s method and the
//! biased baseline.

use glam::Vec3;

use super::march::{march_camera_ray, marched_transmittance, ShadowEnd};
use super::{CameraSampler, LightParts, Sample};
use crate::counters::Counters;
use crate::light::Lights;
use crate::medium::Media;
use crate::phase::Phase;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::spectrum::Spectrum;

/// Fixed-step single-scattering ray marcher with marched shadow rays.
///
/// At every step the light arriving at the sample point is estimated with
/// one marched shadow ray per light: toward the sun (a sun with an angular
/// diameter is sampled uniformly over its disc) and, for the environment,
/// along one phase-sampled direction (the phase-to-pdf ratio is then 1). It
/// converges to the path tracer with `max_depth = 1` as the step shrinks.
/// Cost per camera ray grows with the square of the number of steps.
/// Chromatic media are marched per channel (camera and shadow rays).
pub struct RayMarcher<'a, M> {
    medium: &'a M,
    lights: Lights,
    /// Step length in render-space units.
    step: f32,
    /// Shadow rays' step length in render-space units.
    shadow_step: f32,
}

impl<'a, M: Media> RayMarcher<'a, M> {
    /// `step_voxels` is converted with the field's smallest voxel size.
    pub fn new(medium: &'a M, lights: Lights, step_voxels: f32) -> Self {
        let step = step_voxels.max(super::march::MIN_STEP_VOXELS) * medium.voxel_size();
        Self {
            medium,
            lights: lights.pruned(),
            step,
            shadow_step: step,
        }
    }

    /// Marches shadow rays with their own step (in voxels), as OpenVDB's
    /// `vdb_render -shadowstep` does: a shadow ray only needs its optical
    /// depth, which a coarser lattice estimates without bias (the jittered
    /// march is stratified sampling), only with more variance.
    pub fn with_shadow_step(self, shadow_step_voxels: f32) -> Self {
        Self {
            shadow_step: shadow_step_voxels.max(super::march::MIN_STEP_VOXELS)
                * self.medium.voxel_size(),
            ..self
        }
    }

    /// Phase-weighted light arriving at `p` for a ray travelling along `dir`.
    fn in_scatter<E: Spectrum>(
        &self,
        p: Vec3,
        dir: Vec3,
        phase: &Phase,
        rng: &mut Rng,
        c: &mut Counters,
    ) -> LightParts {
        let mut s = LightParts::default();
        for (i, light) in self.lights.iter().enumerate() {
            // A distant light's disc, a sphere light's cone and an area
            // light's shape sampled uniformly (radiance / pdf is what they
            // deliver); a dome along a phase-sampled direction.
            let (u1, u2) = (rng.uniform(), rng.uniform());
            let (w, f, radiance, t_max) = match light.march_sample(p, u1, u2) {
                Some(ls) => {
                    if ls.radiance == Vec3::ZERO {
                        continue;
                    }
                    let f = phase.eval(dir, ls.to_light) / ls.pdf.unwrap_or(1.0);
                    (ls.to_light, f, ls.radiance, ls.distance)
                }
                None => {
                    light.count_sample(c);
                    let w = phase.sample(dir, u1, u2).0;
                    (
                        w,
                        1.0,
                        light.escaped(w).map_or(Vec3::ZERO, |e| e.0),
                        f32::INFINITY,
                    )
                }
            };
            let tr: E = marched_transmittance(
                self.medium,
                p,
                w,
                t_max,
                self.shadow_step,
                ShadowEnd::Roulette,
                rng,
                c,
            );
            let l = tr.scale(f).tint(radiance);
            s.add(self.lights.group(i), l);
        }
        s
    }
}

impl<M: Media> CameraSampler for RayMarcher<'_, M> {
    fn sample(&self, ray: Ray, rng: &mut Rng, c: &mut Counters) -> Sample {
        if self.medium.chromatic() {
            self.march::<Vec3>(ray, rng, c)
        } else {
            self.march::<f32>(ray, rng, c)
        }
    }
}

impl<M: Media> RayMarcher<'_, M> {
    fn march<E: Spectrum>(&self, ray: Ray, rng: &mut Rng, c: &mut Counters) -> Sample {
        march_camera_ray::<M, E>(
            self.medium,
            &self.lights,
            &ray,
            self.step,
            rng,
            c,
            |p, phase, rng, c| self.in_scatter::<E>(p, ray.dir, phase, rng, c),
        )
    }
}
