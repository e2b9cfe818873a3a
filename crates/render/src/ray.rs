//! Rays. Clipping one to a box is `Bounds3::clip_ray` (`cirrus-bricks`).

use glam::Vec3;

/// A ray `origin + t * dir`. The integrators keep `dir` normalised so t is a
/// distance in render-space units.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self { origin, dir }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}
