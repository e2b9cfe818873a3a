//! A camera that moves while the shutter is open, and near clipping.
//!
//! [`CameraMotion`] holds the camera's poses at a few shutter times (frames
//! relative to the frame rendered); a camera sample at time t looks from
//! the position lerped and the orientation slerped between the poses around
//! t, so every path sees the camera where it was at its own time. A fixed
//! number of poses keeps [`Camera`](crate::Camera) `Copy`.

use glam::{Quat, Vec3};

use crate::error::{Error, Result};
use crate::ray::Ray;

/// The most poses one shutter holds.
pub const MAX_POSES: usize = 8;

/// Where a camera is and how it is turned: `rotation` takes camera axes
/// (+X right, +Y up, looking along -Z) to render space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    pub position: Vec3,
    pub rotation: Quat,
}

/// Camera poses over the shutter, sorted by time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraMotion {
    times: [f32; MAX_POSES],
    poses: [CameraPose; MAX_POSES],
    len: usize,
}

impl CameraMotion {
    /// Poses at increasing, finite times; 1 to [`MAX_POSES`] of them.
    pub fn new(samples: &[(f32, CameraPose)]) -> Result<CameraMotion> {
        if samples.is_empty() || samples.len() > MAX_POSES {
            return Err(Error::invalid(format!(
                "a moving camera takes 1 to {MAX_POSES} poses, got {}",
                samples.len()
            )));
        }
        if samples
            .windows(2)
            .any(|w| w[1].0.partial_cmp(&w[0].0) != Some(std::cmp::Ordering::Greater))
            || !samples[0].0.is_finite()
        {
            return Err(Error::invalid(
                "camera pose times must be finite and increasing",
            ));
        }
        let still = CameraPose {
            position: Vec3::ZERO,
            rotation: Quat::IDENTITY,
        };
        let mut motion = CameraMotion {
            times: [0.0; MAX_POSES],
            poses: [still; MAX_POSES],
            len: samples.len(),
        };
        for (k, (t, pose)) in samples.iter().enumerate() {
            motion.times[k] = *t;
            motion.poses[k] = *pose;
        }
        Ok(motion)
    }

    /// The pose at `time`, clamped to the first and last.
    pub fn pose_at(&self, time: f32) -> CameraPose {
        let times = &self.times[..self.len];
        let i = times.partition_point(|&t| t <= time);
        if i == 0 {
            return self.poses[0];
        }
        if i == self.len {
            return self.poses[self.len - 1];
        }
        let (a, b) = (self.poses[i - 1], self.poses[i]);
        let u = (time - times[i - 1]) / (times[i] - times[i - 1]);
        let rb = if a.rotation.dot(b.rotation) < 0.0 {
            -b.rotation
        } else {
            b.rotation
        };
        CameraPose {
            position: a.position.lerp(b.position, u),
            rotation: a.rotation.slerp(rb, u).normalize(),
        }
    }

    /// The ray through the camera-space direction (`sx`, `sy`, -1) at `time`.
    #[inline]
    pub fn ray(&self, sx: f32, sy: f32, time: f32) -> Ray {
        let pose = self.pose_at(time);
        let dir = pose.rotation * Vec3::new(sx, sy, -1.0);
        Ray::new(pose.position, dir.normalize())
    }
}

/// `ray` started where it crosses the plane `near` in front of the camera
/// along `forward` (unit): what near clipping hides is never entered.
#[inline]
pub fn clip_near(ray: Ray, forward: Vec3, near: f32) -> Ray {
    let cos = ray.dir.dot(forward);
    if near <= 0.0 || cos <= 0.0 {
        return ray;
    }
    Ray::new(ray.origin + ray.dir * (near / cos), ray.dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poses_interpolate_and_clamp() {
        let a = CameraPose {
            position: Vec3::ZERO,
            rotation: Quat::IDENTITY,
        };
        let b = CameraPose {
            position: Vec3::new(2.0, 0.0, 0.0),
            rotation: Quat::from_rotation_y(1.0),
        };
        let m = CameraMotion::new(&[(-0.5, a), (0.5, b)]).unwrap();
        assert_eq!(m.pose_at(-1.0), a);
        assert_eq!(m.pose_at(0.5), b);
        let mid = m.pose_at(0.0);
        assert!((mid.position - Vec3::X).length() < 1e-6);
        assert!((mid.rotation.to_axis_angle().1 - 0.5).abs() < 1e-5);
        let r = m.ray(0.0, 0.0, -0.5);
        assert!((r.dir - Vec3::NEG_Z).length() < 1e-6);
        assert!(CameraMotion::new(&[(0.0, a), (0.0, b)]).is_err());
        assert!(CameraMotion::new(&[]).is_err());
    }

    #[test]
    fn near_clipping_moves_the_origin_to_the_plane() {
        let dir = Vec3::new(0.6, 0.0, -0.8);
        let r = clip_near(Ray::new(Vec3::ZERO, dir), Vec3::NEG_Z, 2.0);
        assert!((r.origin.z + 2.0).abs() < 1e-6, "{}", r.origin);
        let same = clip_near(Ray::new(Vec3::ONE, dir), Vec3::NEG_Z, 0.0);
        assert_eq!(same.origin, Vec3::ONE);
    }
}
