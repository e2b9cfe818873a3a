//! Domes: light arriving from every direction at infinity, constant or
//! an importance-sampled HDR map.

use std::sync::Arc;

use glam::Vec3;

use super::LightSample;
use crate::env_map::EnvMap;
use crate::sampling::{uniform_sphere, UNIFORM_SPHERE_PDF};

/// Light arriving from every direction at infinity: a constant radiance,
/// or an HDR [`EnvMap`] whose texels are multiplied by `radiance` (the
/// map's intensity, per channel).
#[derive(Clone, Debug)]
pub struct Environment {
    pub radiance: Vec3,
    pub map: Option<Arc<EnvMap>>,
}

impl Environment {
    pub fn new(radiance: Vec3) -> Self {
        Self {
            radiance,
            map: None,
        }
    }

    /// An environment map scaled by `intensity`.
    pub fn from_map(map: Arc<EnvMap>, intensity: Vec3) -> Self {
        Self {
            radiance: intensity,
            map: Some(map),
        }
    }

    /// Samples a direction toward the sky: uniformly over the sphere for a
    /// constant environment (the only light-side strategy there is; MIS
    /// with phase sampling adds the rest), by the map's distribution for a
    /// map.
    #[inline]
    pub fn sample(&self, u1: f32, u2: f32) -> LightSample {
        match &self.map {
            None => LightSample {
                to_light: uniform_sphere(u1, u2),
                radiance: self.radiance,
                pdf: Some(UNIFORM_SPHERE_PDF),
                distance: f32::INFINITY,
            },
            Some(map) => {
                let (to_light, l, pdf) = map.sample(u1, u2);
                LightSample {
                    to_light,
                    radiance: l * self.radiance,
                    pdf: Some(pdf),
                    distance: f32::INFINITY,
                }
            }
        }
    }

    /// Radiance along `dir` and the solid-angle density with which
    /// [`sample`](Self::sample) would have picked it.
    #[inline]
    pub fn eval(&self, dir: Vec3) -> (Vec3, f32) {
        match &self.map {
            None => (self.radiance, UNIFORM_SPHERE_PDF),
            Some(map) => {
                let (l, pdf) = map.eval(dir);
                (l * self.radiance, pdf)
            }
        }
    }

    /// Radiance averaged over the sphere (what the two-pass light grid,
    /// which stores only the sky's transmittance, lights with).
    pub fn mean_radiance(&self) -> Vec3 {
        match &self.map {
            None => self.radiance,
            Some(map) => map.mean() * self.radiance,
        }
    }

    /// Whether it delivers no light at all.
    pub fn is_black(&self) -> bool {
        self.radiance.max_element() <= 0.0 || self.map.as_ref().is_some_and(|m| m.is_black())
    }
}
