//! Pass two of Kajiya and Von Herzen (1984): camera rays marched through the
//! cached direct light.

use super::light_grid::LightGrid;
use super::march::{march_camera_ray, MIN_STEP_VOXELS};
use super::{CameraSampler, Sample};
use crate::counters::Counters;
use crate::light::Lights;
use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::Rng;

/// Single scattering with the light looked up (trilinearly) in a
/// [`LightGrid`] built once, instead of a shadow march per step: cost per
/// camera ray is linear in its steps. Biased by the grid's resolution and
/// the truncated angular expansion as well as by the step. The grid holds
/// one transmittance per light: chromatic media are marched as grey by
/// their largest channel here, so callers refuse them (the scene crate
/// does).
pub struct TwoPassMarcher<'a, M> {
    medium: &'a M,
    lights: Lights,
    grid: &'a LightGrid,
    step: f32,
}

impl<'a, M: Media> TwoPassMarcher<'a, M> {
    pub fn new(medium: &'a M, lights: Lights, grid: &'a LightGrid, step_voxels: f32) -> Self {
        let step = step_voxels.max(MIN_STEP_VOXELS) * medium.voxel_size();
        Self {
            medium,
            lights: lights.pruned(),
            grid,
            step,
        }
    }
}

impl<M: Media> CameraSampler for TwoPassMarcher<'_, M> {
    fn sample(&self, ray: Ray, rng: &mut Rng, c: &mut Counters) -> Sample {
        march_camera_ray::<M, f32>(
            self.medium,
            &self.lights,
            &ray,
            self.step,
            rng,
            c,
            |p, phase, _, _| self.grid.in_scatter(phase, &self.lights, p, ray.dir),
        )
    }
}
