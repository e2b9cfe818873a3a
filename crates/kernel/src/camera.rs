//! A pinhole camera.

use glam::Vec3;

use crate::camera_motion::{clip_near, CameraMotion};
use crate::medium::Bounds3;
use crate::ray::Ray;

/// A pinhole camera at `from` looking at `to`; pixel `(0, 0)` is the top-left
/// corner of the image and `y` grows downward.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    from: Vec3,
    to: Vec3,
    up: Vec3,
    vfov_degrees: f32,
    width: u32,
    height: u32,
    // Derived frame, hence the private fields.
    forward: Vec3,
    right: Vec3,
    true_up: Vec3,
    tan_half: f32,
    /// Poses over the shutter (`camera_motion.rs`); `None`: still.
    motion: Option<CameraMotion>,
    /// Near clipping distance along the view axis (0: none).
    near: f32,
}

impl Camera {
    pub fn new(from: Vec3, to: Vec3, up: Vec3, vfov_degrees: f32, width: u32, height: u32) -> Self {
        let forward = (to - from).normalize();
        // Fall back to another up vector when looking straight along `up`.
        let mut right = forward.cross(up);
        if right.length_squared() < 1e-12 {
            right = forward.cross(forward.any_orthonormal_vector());
        }
        let right = right.normalize();
        let true_up = right.cross(forward);
        Self {
            from,
            to,
            up,
            vfov_degrees,
            width: width.max(1),
            height: height.max(1),
            forward,
            right,
            true_up,
            tan_half: (0.5 * vfov_degrees.to_radians()).tan(),
            motion: None,
            near: 0.0,
        }
    }

    /// This camera moving through `motion`'s poses over the shutter.
    pub fn with_motion(self, motion: CameraMotion) -> Self {
        Self {
            motion: Some(motion),
            ..self
        }
    }

    /// This camera seeing nothing nearer than `near` along its view axis.
    pub fn with_near_clip(self, near: f32) -> Self {
        Self { near, ..self }
    }

    /// Whether the camera moves while the shutter is open.
    /// The near clipping distance (0: none).
    pub fn near(&self) -> f32 {
        self.near
    }

    pub fn moves(&self) -> bool {
        self.motion.is_some()
    }

    /// [`Camera::framing_with_fov`] at a 35-degree vertical field of view
    /// (the renderer's own test scenes).
    pub fn framing(bounds: Bounds3, width: u32, height: u32) -> Self {
        Self::framing_with_fov(bounds, width, height, 35.0)
    }

    /// Frames the box `bounds` from a three-quarter view above and to the
    /// side (azimuth 40 degrees, elevation 20 degrees, +Y up as in most VDB
    /// clouds) through a vertical field of view of `vfov_degrees`, at the
    /// smallest distance from which all eight corners fall inside the
    /// frame, plus a 5% margin.
    pub fn framing_with_fov(bounds: Bounds3, width: u32, height: u32, vfov_degrees: f32) -> Self {
        let vfov = vfov_degrees;
        const MARGIN: f32 = 1.05;
        let centre = bounds.centre();
        let (az, el) = (40f32.to_radians(), 20f32.to_radians());
        let view = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
        let aspect = width.max(1) as f32 / height.max(1) as f32;
        let tan_v = (0.5 * vfov.to_radians()).tan() / MARGIN;
        let tan_h = tan_v * aspect;
        // Camera at centre + D view looking along -view: a corner at offset
        // c has depth D - c.view and must satisfy |c.right| <= tan_h depth
        // and |c.up| <= tan_v depth.
        let forward = -view;
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        let mut distance = 1e-6f32;
        for corner in bounds.corners() {
            let c = corner - centre;
            let need = (c.dot(right).abs() / tan_h).max(c.dot(up).abs() / tan_v) + c.dot(view);
            distance = distance.max(need);
        }
        Self::new(
            centre + distance * view,
            centre,
            Vec3::Y,
            vfov,
            width,
            height,
        )
    }

    pub fn from(&self) -> Vec3 {
        self.from
    }
    pub fn to(&self) -> Vec3 {
        self.to
    }
    pub fn up(&self) -> Vec3 {
        self.up
    }
    /// The unit view axis (depth holdouts measure depth along it).
    pub fn forward(&self) -> Vec3 {
        self.forward
    }
    /// Vertical field of view in degrees.
    pub fn vfov_degrees(&self) -> f32 {
        self.vfov_degrees
    }
    pub fn width(&self) -> u32 {
        self.width
    }
    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// The ray through the film position `(px, py)` in pixel units
    /// (`(x + 0.5, y + 0.5)` is pixel `(x, y)`'s centre); unit direction.
    #[inline]
    pub fn ray(&self, px: f32, py: f32) -> Ray {
        let sx = (2.0 * px / self.width as f32 - 1.0) * self.tan_half * self.aspect();
        let sy = (1.0 - 2.0 * py / self.height as f32) * self.tan_half;
        let dir = (self.forward + sx * self.right + sy * self.true_up).normalize();
        Ray::new(self.from, dir)
    }

    /// The ray of [`ray`](Self::ray) at shutter time `time`, from the
    /// camera's pose then (`camera_motion.rs`) and clipped to its near
    /// distance; exactly `ray` for a still, unclipped camera.
    #[inline]
    pub fn ray_at(&self, px: f32, py: f32, time: f32) -> Ray {
        let (ray, forward) = match &self.motion {
            None => (self.ray(px, py), self.forward),
            Some(m) => {
                let sx = (2.0 * px / self.width as f32 - 1.0) * self.tan_half * self.aspect();
                let sy = (1.0 - 2.0 * py / self.height as f32) * self.tan_half;
                let ray = m.ray(sx, sy, time);
                (ray, m.pose_at(time).rotation * Vec3::NEG_Z)
            }
        };
        clip_near(ray, forward, self.near).with_time(time)
    }
}
