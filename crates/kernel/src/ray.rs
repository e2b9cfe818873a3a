//! Rays. Clipping one to a box is `Bounds3::clip_ray` (`cirrus-bricks`).

use glam::Vec3;

/// A ray `origin + t * dir` at a shutter `time`. The integrators keep `dir`
/// normalised so t is a distance in render-space units.
///
/// `time` is in frames relative to the frame being rendered (0: the frame's
/// own instant). Every ray of a camera path carries the time drawn for its
/// camera sample, so moving media are seen at one instant per path; media
/// without motion ignore it.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub time: f32,
    /// Where the ray ends: infinity, except for a camera ray ending at a
    /// holdout's depth. Rays spawned from it go on to infinity.
    pub t_max: f32,
}

impl Ray {
    /// A ray at time 0.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self {
            origin,
            dir,
            time: 0.0,
            t_max: f32::INFINITY,
        }
    }

    /// The same ray at shutter time `time`.
    #[inline]
    pub fn with_time(self, time: f32) -> Self {
        Self { time, ..self }
    }

    /// A ray from `origin` along `dir` at this ray's time (the next ray of
    /// the same path, or a shadow ray from it).
    #[inline]
    pub fn spawn(&self, origin: Vec3, dir: Vec3) -> Self {
        Self {
            origin,
            dir,
            time: self.time,
            t_max: f32::INFINITY,
        }
    }

    /// The same ray ending at `t_max` (a holdout's depth).
    #[inline]
    pub fn with_t_max(self, t_max: f32) -> Self {
        Self { t_max, ..self }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}
