//! Which volumes of a scene must be loaded at all.
//!
//! The rule, exact (it never drops light the renderer could have found):
//! a path reaches a volume only by a camera ray, by a shadow ray, or by a
//! scattered ray from a volume it already reached. So a volume is loaded
//! when
//! 1. its world box meets the camera's frustum (of the crop window, if
//!    any), or
//! 2. paths may scatter and then travel in any direction: an environment
//!    light (its shadow rays go everywhere), a sphere light (its shadow
//!    rays converge on it from everywhere), an emitting volume anywhere
//!    (phase-sampled rays look for it), or more than one scattering event
//!    allowed (`max_depth` unset or >= 2) -- then every volume is loaded;
//!    or
//! 3. with single scattering lit by the sun alone, its box meets the
//!    shadow prism of a visible volume: the visible box swept toward the
//!    sun (widened by the sun's angular radius).
//!
//! With `max_depth = 0` only visible volumes matter. The rule is tested on
//! boxes (conservative: a box may be kept whose contents are not needed).

use cirrus_bricks::{Bounds3, DBounds3};
use cirrus_render::{Camera, Crop, LightKind, Lights};
use glam::{DVec3, Vec3};

/// Whether `b` (render space) meets the frustum of pixels `crop` of `camera`.
pub fn in_frustum(camera: &Camera, crop: Crop, b: Bounds3) -> bool {
    let (x0, y0, x1, y1) = (
        crop.x0 as f32,
        crop.y0 as f32,
        crop.x1 as f32,
        crop.y1 as f32,
    );
    let corner = |x, y| camera.ray(x, y).dir;
    let centre = camera.ray(0.5 * (x0 + x1), 0.5 * (y0 + y1)).dir;
    let rays = [
        corner(x0, y0),
        corner(x1, y0),
        corner(x1, y1),
        corner(x0, y1),
    ];
    let apex = camera.from();
    for k in 0..4 {
        // The side plane through the apex and two neighbouring corner rays,
        // normal pointing into the frustum.
        let mut n = rays[k].cross(rays[(k + 1) % 4]);
        if n.dot(centre) < 0.0 {
            n = -n;
        }
        let all_outside = b.corners().iter().all(|&p| n.dot(p - apex) < 0.0);
        if all_outside {
            return false;
        }
    }
    true
}

/// Whether box `b` meets box `a` swept from its place toward the sun
/// (direction `to_sun`), widened by `tan_half` per unit of distance.
pub fn in_sun_prism(a: DBounds3, b: DBounds3, to_sun: DVec3, tan_half: f64) -> bool {
    let (ca, ha) = (a.centre(), 0.5 * a.size());
    let cb = b.centre();
    let spread = tan_half * ((cb - ca).length() + ha.length() + (0.5 * b.size()).length());
    // The moving box meets b iff its centre's ray meets b grown by a's half size.
    let grown = DBounds3::new(b.min - ha - spread, b.max + ha + spread);
    grown
        .relative_to(ca)
        .clip_ray(Vec3::ZERO, to_sun.as_vec3(), 0.0, f32::INFINITY)
        .is_some()
}

/// Which volumes to load; `visible[i]` says whether volume `i` meets the
/// frustum. See the module doc for the rule.
pub fn needed(
    visible: &[bool],
    boxes: &[DBounds3],
    lights: &Lights,
    any_emission: bool,
    max_depth: Option<u32>,
) -> Vec<bool> {
    let n = visible.len();
    if max_depth == Some(0) {
        return visible.to_vec();
    }
    let scattered_anywhere = lights.iter().any(|l| l.kind() != LightKind::Distant)
        || any_emission
        || max_depth.is_none_or(|d| d >= 2);
    if scattered_anywhere {
        return vec![true; n];
    }
    // Single scattering under distant lights: what shadows a visible
    // volume toward any of them.
    let prisms: Vec<(DVec3, f64)> = lights
        .distant()
        .map(|(_, sun)| (-sun.direction().as_dvec3(), sun_half_angle_tan(sun)))
        .collect();
    (0..n)
        .map(|i| {
            visible[i]
                || prisms.iter().any(|&(to_sun, tan_half)| {
                    (0..n).any(|a| visible[a] && in_sun_prism(boxes[a], boxes[i], to_sun, tan_half))
                })
        })
        .collect()
}

/// Tangent of the sun's angular radius (0 for a delta sun).
fn sun_half_angle_tan(sun: &cirrus_render::Sun) -> f64 {
    let omc = sun.one_minus_cos_half_angle() as f64;
    let c = 1.0 - omc;
    if c <= 0.0 {
        f64::INFINITY
    } else {
        (omc * (2.0 - omc)).max(0.0).sqrt() / c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sun_prism_reaches_along_the_sun_only() {
        let a = DBounds3::new(DVec3::splat(-1.0), DVec3::splat(1.0));
        let above = DBounds3::new(DVec3::new(-0.5, 10.0, -0.5), DVec3::new(0.5, 11.0, 0.5));
        let beside = DBounds3::new(DVec3::new(5.0, -1.0, -1.0), DVec3::new(6.0, 1.0, 1.0));
        let up = DVec3::Y;
        assert!(in_sun_prism(a, above, up, 0.0));
        assert!(!in_sun_prism(a, beside, up, 0.0));
        assert!(
            !in_sun_prism(a, above, -up, 0.0),
            "behind the sun's direction"
        );
    }

    #[test]
    fn frustum_keeps_what_the_camera_sees() {
        let cam = Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, 40.0, 32, 32);
        let full = Crop {
            x0: 0,
            y0: 0,
            x1: 32,
            y1: 32,
        };
        let ahead = Bounds3::new(Vec3::new(-1.0, -1.0, -11.0), Vec3::new(1.0, 1.0, -9.0));
        let behind = Bounds3::new(Vec3::new(-1.0, -1.0, 9.0), Vec3::new(1.0, 1.0, 11.0));
        let aside = Bounds3::new(Vec3::new(30.0, -1.0, -11.0), Vec3::new(32.0, 1.0, -9.0));
        assert!(in_frustum(&cam, full, ahead));
        assert!(!in_frustum(&cam, full, behind));
        assert!(!in_frustum(&cam, full, aside));
        // A crop of the left half does not see a box on the right.
        let left = Crop { x1: 16, ..full };
        let right_box = Bounds3::new(Vec3::new(2.0, -0.5, -11.0), Vec3::new(3.0, 0.5, -9.0));
        assert!(in_frustum(&cam, full, right_box));
        assert!(!in_frustum(&cam, left, right_box));
    }
}
