//! The direction a path scatters into: the phase function's, or, where the
//! radiance cache has learned, one resampled toward the learned incident
//! light (`crate::guiding::resample`).

use glam::Vec3;

use super::path::PathTracer;
use crate::guiding::{resample, IncidentLight, CANDIDATES};
use crate::medium::Media;
use crate::phase::Phase;
use crate::ray::Ray;
use crate::sampling::{Draw, SampleStream};

/// A scattered direction with what the path needs of it.
pub(super) struct Scattered {
    pub dir: Vec3,
    /// The density it was sampled with, for the MIS weights of the lights
    /// it may escape to; `None` for a resampled direction, which has none
    /// in closed form (its vertex took those lights by next-event
    /// estimation alone).
    pub pdf: Option<f32>,
    /// The factor the path's throughput takes: the phase function over
    /// the density, 1 for phase sampling.
    pub weight: f32,
}

impl<M: Media> PathTracer<'_, M> {
    /// Samples the direction out of a vertex reached along `ray_in`. A
    /// guided vertex's first candidate takes the phase draw (keeping its
    /// stratification), the others and the choice the hashed stream.
    pub(super) fn scatter(
        &self,
        ray_in: &Ray,
        phase: &Phase,
        light: Option<&IncidentLight>,
        vertex: u32,
        draws: &mut SampleStream,
    ) -> Scattered {
        let (u1, u2) = draws.get_2d(Draw::Phase, vertex);
        let Some(light) = light else {
            let (dir, pdf) = phase.sample(ray_in.dir, u1, u2);
            return Scattered {
                dir,
                pdf: Some(pdf),
                weight: 1.0,
            };
        };
        let rng = draws.rng();
        let dirs: [Vec3; CANDIDATES] = std::array::from_fn(|k| {
            let (v1, v2) = match k {
                0 => (u1, u2),
                _ => (rng.uniform(), rng.uniform()),
            };
            phase.sample(ray_in.dir, v1, v2).0
        });
        let (kept, weight) = resample(light, &dirs, rng.uniform());
        Scattered {
            dir: dirs[kept],
            pdf: None,
            weight,
        }
    }
}
