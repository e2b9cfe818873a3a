//! Distant lights: light arriving along one direction, or from a small
//! disc about it (the sun, the moon).

use std::f32::consts::PI;

use glam::Vec3;

use super::LightSample;
use crate::sampling::uniform_cone;

/// A directional light like Mitsuba 3's `directional` emitter: `irradiance`
/// is measured on a plane perpendicular to the light's direction.
///
/// With a non-zero angular diameter the sun is a cone of uniform radiance
/// `irradiance / solid_angle`, so the light it delivers into a medium equals
/// the delta light's (`integral of L over the cone = irradiance`) and
/// changing the angle only softens shadows.
#[derive(Clone, Copy, Debug)]
pub struct Sun {
    /// Unit vector pointing FROM the light toward the scene.
    direction: Vec3,
    irradiance: Vec3,
    /// `1 - cos(half angle)`, computed as `2 sin^2(half / 2)` for precision.
    one_minus_cos: f32,
    solid_angle: f32,
}

impl Sun {
    /// `direction` points from the light toward the scene (normalised here);
    /// `angular_diameter` is the full apex angle of the disc in radians
    /// (0 = delta light; the real sun is about 0.0093; up to 2 pi, where the
    /// "disc" is the whole sphere, which the tests use as a furnace).
    pub fn new(direction: Vec3, irradiance: Vec3, angular_diameter: f32) -> Self {
        let half = if angular_diameter.is_nan() {
            0.0
        } else {
            (0.5 * angular_diameter).clamp(0.0, PI)
        };
        let one_minus_cos = 2.0 * (0.5 * half).sin().powi(2);
        Self {
            direction: direction.normalize(),
            irradiance,
            one_minus_cos,
            solid_angle: 2.0 * PI * one_minus_cos,
        }
    }

    pub fn direction(&self) -> Vec3 {
        self.direction
    }

    pub fn irradiance(&self) -> Vec3 {
        self.irradiance
    }

    /// `1 - cos` of the disc's angular radius (0 for a delta sun).
    pub fn one_minus_cos_half_angle(&self) -> f32 {
        self.one_minus_cos
    }

    /// A delta light cannot be hit by a sampled direction, so it gets
    /// next-event estimation only and no MIS.
    /// The disc's solid angle (0 for a delta light).
    pub fn solid_angle(&self) -> f32 {
        self.solid_angle
    }

    pub fn is_delta(&self) -> bool {
        self.solid_angle <= 0.0
    }

    /// Samples a direction toward the sun, uniform over its cone.
    pub fn sample(&self, u1: f32, u2: f32) -> LightSample {
        if self.is_delta() {
            return LightSample {
                to_light: -self.direction,
                radiance: self.irradiance,
                pdf: None,
                distance: f32::INFINITY,
            };
        }
        LightSample {
            to_light: uniform_cone(-self.direction, self.one_minus_cos, u1, u2),
            radiance: self.irradiance / self.solid_angle,
            pdf: Some(1.0 / self.solid_angle),
            distance: f32::INFINITY,
        }
    }

    /// Radiance and sampling pdf seen along `dir` by a ray escaping the
    /// scene, or `None` outside the disc (always `None` for a delta sun).
    pub fn hit(&self, dir: Vec3) -> Option<(Vec3, f32)> {
        if self.is_delta() {
            return None;
        }
        // 1 - cos(angle to the sun's centre) compared in the same form as
        // the cone was built, so small suns are not lost to rounding.
        let one_minus_cos = 1.0 + dir.dot(self.direction);
        (one_minus_cos <= self.one_minus_cos)
            .then(|| (self.irradiance / self.solid_angle, 1.0 / self.solid_angle))
    }
}
