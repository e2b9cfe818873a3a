//! Time-sampled values of a scene description: volume transforms, the
//! camera and volume files given per time (in frames), read at the frame
//! being rendered (`[render] frame`, which `--frames` sets) and, for motion
//! blur, over its shutter.
//!
//! Matrices are interpolated as renderers interpolate animated transforms
//! (pbrt's `AnimatedTransform`): each sample is split into translation,
//! rotation and scale, translation and scale are lerped and the rotation
//! slerped. A time at or outside a sample's own time reads that sample's
//! matrix exactly, so a still frame sees the authored numbers bit for bit.

use glam::{DMat4, DQuat, DVec3};

use crate::description::{CameraSpec, SceneDescription};
use crate::values::{Matrix, MatrixSample};

/// More samples than this inside one shutter are resampled uniformly.
pub const MAX_SHUTTER_POSES: usize = 64;

/// The glam matrix of rows `m` (column vectors).
pub fn to_dmat4(m: &Matrix) -> DMat4 {
    DMat4::from_cols_array_2d(m).transpose()
}

/// The rows of `m`.
pub fn from_dmat4(m: DMat4) -> Matrix {
    m.transpose().to_cols_array_2d()
}

/// The matrix of `samples` at `time` (clamped to the first and last).
pub fn matrix_at(samples: &[MatrixSample], time: f64) -> DMat4 {
    let i = samples.partition_point(|s| s.time <= time);
    if i == 0 {
        return to_dmat4(&samples[0].matrix);
    }
    let a = &samples[i - 1];
    if i == samples.len() || a.time == time {
        return to_dmat4(&a.matrix);
    }
    let b = &samples[i];
    let u = (time - a.time) / (b.time - a.time);
    interpolate(to_dmat4(&a.matrix), to_dmat4(&b.matrix), u)
}

/// Translation and scale lerped, rotation slerped (the shorter way).
fn interpolate(a: DMat4, b: DMat4, u: f64) -> DMat4 {
    let (sa, ra, ta) = a.to_scale_rotation_translation();
    let (sb, rb, tb) = b.to_scale_rotation_translation();
    let rb = if ra.dot(rb) < 0.0 { -rb } else { rb };
    DMat4::from_scale_rotation_translation(sa.lerp(sb, u), ra.slerp(rb, u), ta.lerp(tb, u))
}

/// Poses over a shutter: `(time relative to the frame, matrix)`, sorted,
/// covering `[open, close]`; one pose when nothing moves in it.
pub fn shutter_poses(samples: &[MatrixSample], frame: f64, shutter: [f32; 2]) -> Vec<(f32, DMat4)> {
    let [open, close] = shutter.map(f64::from);
    let at = |t: f64| (t as f32, matrix_at(samples, frame + t));
    let inside: Vec<f64> = samples
        .iter()
        .map(|s| s.time - frame)
        .filter(|&t| t > open && t < close)
        .collect();
    let mut poses = vec![at(open)];
    if close > open {
        if inside.len() + 2 <= MAX_SHUTTER_POSES {
            poses.extend(inside.into_iter().map(at));
        } else {
            let n = MAX_SHUTTER_POSES - 1;
            poses.extend((1..n).map(|k| at(open + (close - open) * k as f64 / n as f64)));
        }
        poses.push(at(close));
    }
    if poses.iter().all(|(_, m)| *m == poses[0].1) {
        poses.truncate(1);
    }
    poses
}

/// The description with every volume's transform read at the frame
/// (`transform.samples` become `transform.matrix`).
pub fn at_frame(desc: &SceneDescription) -> SceneDescription {
    let frame = desc.frame();
    let mut out = desc.clone();
    for v in &mut out.volumes {
        if let Some(samples) = v.transform.samples.take() {
            v.transform.matrix = Some(from_dmat4(matrix_at(&samples, frame)));
        }
    }
    out
}

/// A camera's placement and lens from the description's matrix fields:
/// `(eye, target, up)` in world space at the frame, and the vertical field
/// of view in degrees for an image of `aspect` (width / height).
pub struct CameraPlacement {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    /// Camera-to-world rotations over the shutter, when the camera moves.
    pub poses: Vec<(f32, DVec3, DQuat)>,
}

/// The camera of `c` placed by a matrix or samples, if it is.
pub fn camera_placement(c: &CameraSpec, frame: f64, shutter: [f32; 2]) -> Option<CameraPlacement> {
    let m = match (&c.matrix, &c.samples) {
        (Some(m), _) => to_dmat4(m),
        (None, Some(s)) => matrix_at(s, frame),
        (None, None) => return None,
    };
    let eye = m.w_axis.truncate();
    let forward = -m.z_axis.truncate().normalize();
    let up = m.y_axis.truncate().normalize();
    let poses = match &c.samples {
        Some(s) => shutter_poses(s, frame, shutter)
            .into_iter()
            .map(|(t, m)| {
                let (_, r, p) = m.to_scale_rotation_translation();
                (t, p, r)
            })
            .collect(),
        None => Vec::new(),
    };
    Some(CameraPlacement {
        eye,
        target: eye + forward,
        up,
        poses,
    })
}

/// The vertical field of view (degrees) of a lens of `focal_length` with
/// the given apertures for an image of `aspect`, the aperture expanded to
/// the image's aspect (USD's default `expandAperture`). Missing apertures
/// take USD's fallbacks (20.955 x 15.2908).
pub fn lens_fov(c: &CameraSpec, aspect: f64) -> Option<f32> {
    let focal = f64::from(c.focal_length?);
    let h = f64::from(c.horizontal_aperture.unwrap_or(20.955));
    let v = f64::from(c.vertical_aperture.unwrap_or(15.2908));
    let v = if h / v > aspect { h / aspect } else { v };
    Some((2.0 * (0.5 * v / focal).atan()).to_degrees() as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(time: f64, m: DMat4) -> MatrixSample {
        MatrixSample {
            time,
            matrix: from_dmat4(m),
        }
    }

    #[test]
    fn samples_read_exactly_at_their_times_and_interpolate_between() {
        let a = DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0));
        let b = DMat4::from_rotation_y(1.0) * DMat4::from_scale(DVec3::splat(2.0));
        let s = [sample(1.0, a), sample(3.0, b)];
        assert_eq!(matrix_at(&s, 1.0), a);
        assert_eq!(matrix_at(&s, 0.0), a);
        assert_eq!(matrix_at(&s, 3.0), b);
        assert_eq!(matrix_at(&s, 7.0), b);
        let mid = matrix_at(&s, 2.0);
        let (scale, rot, t) = mid.to_scale_rotation_translation();
        assert!((scale - DVec3::splat(1.5)).length() < 1e-12, "{scale}");
        assert!((t - DVec3::new(0.5, 1.0, 1.5)).length() < 1e-12, "{t}");
        assert!((rot.to_axis_angle().1 - 0.5).abs() < 1e-12);
    }

    #[test]
    fn shutter_poses_include_samples_inside_and_collapse_when_still() {
        let a = DMat4::from_translation(DVec3::X);
        let b = DMat4::from_translation(DVec3::Y);
        let s = [sample(1.0, a), sample(2.0, b), sample(3.0, a)];
        let poses = shutter_poses(&s, 2.0, [-0.25, 0.25]);
        assert_eq!(
            poses.iter().map(|p| p.0).collect::<Vec<_>>(),
            [-0.25, 0.0, 0.25]
        );
        assert_eq!(poses[1].1, b);
        assert_eq!(shutter_poses(&s, 2.0, [0.0, 0.0]).len(), 1);
        assert_eq!(shutter_poses(&[sample(0.0, a)], 5.0, [-1.0, 1.0]).len(), 1);
    }

    #[test]
    fn lens_fov_expands_the_aperture_to_the_image() {
        let c = CameraSpec {
            focal_length: Some(50.0),
            horizontal_aperture: Some(36.0),
            vertical_aperture: Some(24.0),
            ..Default::default()
        };
        let expected = |v: f64| (2.0 * (0.5 * v / 50.0f64).atan()).to_degrees() as f32;
        assert_eq!(lens_fov(&c, 1.5), Some(expected(24.0)));
        // A square image keeps the width: the height grows to 36.
        assert_eq!(lens_fov(&c, 1.0), Some(expected(36.0)));
        // A wide image keeps the height.
        assert_eq!(lens_fov(&c, 3.0), Some(expected(24.0)));
    }
}
