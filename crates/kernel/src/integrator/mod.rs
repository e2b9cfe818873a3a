//! Integrators: what one camera sample returns.
//!
//! - `path`: unbiased volumetric path tracing (delta tracking, NEE + MIS).
//! - `raymarch`: single scattering by fixed-step marching with marched
//!   shadow rays (OpenVDB `vdb_render`'s method; the biased baseline).
//! - `raymarch2pass`: Kajiya and Von Herzen's two passes, lighting cached
//!   in a sparse grid (`light_grid`) and camera rays marched through it.
//! - `march`: the jittered fixed-step quadrature both marchers share.

mod distance_sampling;
mod light_choice;
mod light_grid;
mod light_sampling;
mod light_tree;
mod many_lights;
mod march;
mod mis;
mod path;
mod path_equiangular;
mod path_flight;
mod path_light;
mod path_state;
mod path_sunward;
mod per_light;
mod raymarch;
mod raymarch2pass;
mod sunward_mode;

pub use distance_sampling::DistanceSampling;
pub use light_grid::{LightGrid, LightGridSettings};
pub use light_sampling::LightSampling;
pub use path::PathTracer;
pub use path_sunward::KEEP_THRESHOLD;
pub use raymarch::RayMarcher;
pub use raymarch2pass::TwoPassMarcher;
pub use sunward_mode::{Sunward, FORWARD_MEAN_COSINE};

use glam::Vec3;

use crate::counters::Counters;
use crate::light::GroupRadiance;
use crate::light::Lights;
use crate::ray::Ray;
use crate::sampling::{Rng, SampleStream};
use light_choice::{LightChoice, LightSampler};
use mis::Strategies;

settings_enum! {
    /// Which integrator renders the image.
    pub enum IntegratorKind {
        /// Unbiased volumetric path tracing (delta tracking, NEE with MIS).
        #[default]
        Path = "path",
        /// Single scattering by ray marching with jittered steps (biased preview).
        RayMarch = "raymarch",
        /// Two-pass ray marching over a cached light grid (Kajiya and Von Herzen).
        RayMarch2Pass = "raymarch2pass",
    }
}

impl IntegratorKind {
    /// Whether the integrator marches fixed steps (and so needs only where
    /// density is, not tight majorants).
    pub fn marches(self) -> bool {
        matches!(self, Self::RayMarch | Self::RayMarch2Pass)
    }
}

/// One camera sample's estimate: radiance, `1 - T` of the camera ray, and
/// the parts the compositing passes (AOVs) show apart.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    pub radiance: Vec3,
    pub alpha: f32,
    pub aov: AovSample,
    /// `radiance` split by light group ([`crate::light::GroupRadiance`]): the same
    /// contributions, each added to its light's group as well.
    pub groups: GroupRadiance,
}

/// The AOV parts of one sample (filled by the path tracer; the marchers
/// leave them zero). Each is an unbiased estimate of its pass except
/// `depth`, which is the sampled distance to the first real collision,
/// `None` when the camera ray escaped (the film averages it over the
/// samples that collided).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AovSample {
    /// Albedo of the instance at the first real collision (0 if none).
    pub albedo: Vec3,
    pub depth: Option<f32>,
    /// Emitted light alone (every vertex of the path).
    pub emission: Vec3,
    /// Light scattered once toward the camera: next-event estimation and
    /// the MIS-weighted light hit by the phase-sampled ray at the first
    /// scattering event (no background, no emission, no multiple scattering).
    pub direct: Vec3,
    /// The instance of the camera ray's first real collision, if it was a
    /// visible one (not a holdout); Cryptomatte's coverage and the deep
    /// bins count it.
    pub instance: Option<u32>,
}

/// Anything that turns a camera ray into a [`Sample`]; `Sync` so tiles can
/// share it across rayon's workers.
pub trait CameraSampler: Sync {
    fn sample(&self, ray: Ray, rng: &mut Rng, c: &mut Counters) -> Sample;

    /// [`sample`](Self::sample) drawing from a [`SampleStream`]: an
    /// integrator that places low-discrepancy draws (the path tracer)
    /// overrides it; the others take every number from the hashed stream.
    fn sample_stream(&self, ray: Ray, stream: &mut SampleStream, c: &mut Counters) -> Sample {
        self.sample(ray, stream.rng(), c)
    }
}

/// Radiance reaching an escaping ray along `dir` from lights at infinity.
///
/// `phase_pdf` is the solid-angle pdf with which `dir` was phase-sampled,
/// with the light choice at its vertex, `None` for camera rays (which no
/// light strategy could have produced, so they take the full radiance).
/// Otherwise each light's radiance is weighted by the power heuristic
/// against that light's own sampling pdf times the probability that the
/// vertex sampled it (`light_choice.rs`), the counterpart of the weights in
/// next-event estimation.
pub(crate) fn escaped_radiance(
    lights: &Lights,
    dir: Vec3,
    phase_pdf: Option<(f32, &LightChoice, &LightSampler)>,
    c: &mut Counters,
) -> LightParts {
    let mut l = LightParts::default();
    for &i in lights.at_infinity() {
        let i = i as usize;
        let light = lights.get(i);
        light.count_sample(c);
        if let Some((radiance, pdf)) = light.escaped(dir) {
            let weight = phase_pdf.map_or(1.0, |(p, choice, sampler)| {
                Strategies::drawn_with(p)
                    .or(sampler.probability(choice, i) * pdf)
                    .weight()
            });
            l.add(lights.group(i), radiance * weight);
        }
    }
    l
}

/// Light gathered from the lights, in all and by light group; the
/// integrators add [`LightParts::total`], the film's light groups the
/// parts.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LightParts {
    total: Vec3,
    groups: GroupRadiance,
}

impl LightParts {
    /// Adds `l`, from a light of group `group`.
    #[inline]
    pub fn add(&mut self, group: usize, l: Vec3) {
        self.total += l;
        self.groups[group] += l;
    }

    #[inline]
    pub fn total(&self) -> Vec3 {
        self.total
    }

    /// The part of light group `g`.
    #[cfg(test)]
    pub fn group(&self, g: usize) -> Vec3 {
        self.groups[g]
    }

    /// Adds each group's part, times `w`, to `groups`.
    #[inline]
    pub fn tag_scaled(&self, w: Vec3, groups: &mut GroupRadiance) {
        for (g, part) in groups.iter_mut().zip(&self.groups) {
            *g += *part * w;
        }
    }
}
