//! Area lights: a rectangle or a disc (an ellipse, scaled) of uniform
//! radiance emitting from one side (UsdLux's `RectLight` and `DiskLight`,
//! Blender's area lamps), along their normal; or a cylinder's side
//! emitting outward, its caps dark (UsdLux's `CylinderLight`).
//!
//! Next-event estimation samples a rectangle uniformly in the solid angle
//! it subtends (`spherical_rect.rs`, Urena et al. 2013: density `1 / S`,
//! bounded however close the vertex), and a disc, or a rectangle too
//! small to matter, by a point uniform on the shape (the disc by Shirley
//! and Chiu's concentric map; a cylinder's side uniform in length and
//! angle), the solid-angle density toward it `d^2 / (A cos theta_l)`
//! (pbrt-v4's shapes sampled by area). A ray that
//! meets the shape's front gathers its radiance, weighed by the density
//! the vertex it left would have sampled it with.

use std::f32::consts::{FRAC_PI_4, PI, TAU};

use glam::{Vec2, Vec3};

use super::spherical_rect::SphericalRect;
use super::LightSample;

/// The outline of an area light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AreaShape {
    Rect,
    /// A disc, an ellipse where its two half-axes differ.
    Disk,
    /// A cylinder's side: its axis along the light's normal, half its
    /// length `half_u`, its radius `half_v`'s length.
    Cylinder,
}

/// A one-sided area light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaLight {
    centre: Vec3,
    /// Half the shape along its first and second axes (perpendicular).
    half_u: Vec3,
    half_v: Vec3,
    /// Unit vector the light is emitted along (a cylinder's axis).
    normal: Vec3,
    shape: AreaShape,
    radiance: Vec3,
    area: f32,
    /// Whether camera rays see the shape (off by default, as
    /// [`super::SphereLight`]'s).
    camera_visible: bool,
}

impl AreaLight {
    /// A `shape` centred at `centre` spanning `half_u` and `half_v` (half
    /// its width and height, or its two radii), emitting `radiance` along
    /// `normal`'s side (normalised here).
    pub fn new(
        shape: AreaShape,
        centre: Vec3,
        half_u: Vec3,
        half_v: Vec3,
        normal: Vec3,
        radiance: Vec3,
    ) -> Self {
        let extent = 4.0 * half_u.length() * half_v.length();
        let area = match shape {
            AreaShape::Rect => extent,
            AreaShape::Disk => FRAC_PI_4 * extent,
            AreaShape::Cylinder => PI * extent,
        };
        Self {
            centre,
            half_u,
            half_v,
            normal: normal.normalize(),
            shape,
            radiance,
            area,
            camera_visible: false,
        }
    }

    /// The side of a cylinder centred at `centre` along `axis` of
    /// `length` and `radius`, emitting `radiance` outward.
    pub fn cylinder(centre: Vec3, axis: Vec3, length: f32, radius: f32, radiance: Vec3) -> Self {
        let axis = axis.normalize();
        let across = axis.any_orthonormal_vector();
        let half_u = 0.5 * length * axis;
        Self::new(
            AreaShape::Cylinder,
            centre,
            half_u,
            radius * across,
            axis,
            radiance,
        )
    }

    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    pub fn radiance(&self) -> Vec3 {
        self.radiance
    }

    /// Its half axes: a rect's or disc's (`u`, `v`), a cylinder's half
    /// length along its axis and radius across (for backends that sample
    /// it themselves).
    pub fn half_axes(&self) -> (Vec3, Vec3) {
        (self.half_u, self.half_v)
    }

    pub fn area(&self) -> f32 {
        self.area
    }

    pub fn shape(&self) -> AreaShape {
        self.shape
    }

    /// Half the sides of a box about its centre holding the shape.
    pub fn half_extent(&self) -> Vec3 {
        match self.shape {
            // Its radius turns about the axis.
            AreaShape::Cylinder => self.half_u.abs() + Vec3::splat(self.half_v.length()),
            AreaShape::Rect | AreaShape::Disk => self.half_u.abs() + self.half_v.abs(),
        }
    }

    /// The same light, seen by camera rays where `visible`.
    pub fn seen_by_camera(self, visible: bool) -> Self {
        Self {
            camera_visible: visible,
            ..self
        }
    }

    /// Whether camera rays see it.
    pub fn camera_visible(&self) -> bool {
        self.camera_visible
    }

    /// The same light moved to `centre`.
    pub fn moved_to(self, centre: Vec3) -> Self {
        Self { centre, ..self }
    }

    /// The point of the shape at `(a, b)` in `[-1, 1]^2` coordinates.
    #[inline]
    fn at(&self, a: f32, b: f32) -> Vec3 {
        self.centre + a * self.half_u + b * self.half_v
    }

    /// The rectangle as seen from `p` in front of it, where it subtends
    /// enough to be sampled by solid angle.
    #[inline]
    fn spherical_from(&self, p: Vec3) -> Option<SphericalRect> {
        let in_front = (p - self.centre).dot(self.normal) > 0.0;
        (self.shape == AreaShape::Rect && in_front).then(|| {
            let corner = self.centre - self.half_u - self.half_v;
            SphericalRect::seen_from(corner, 2.0 * self.half_u, 2.0 * self.half_v, p)
        })?
    }

    /// Samples the light from `p`: a direction uniform in a rectangle's
    /// solid angle, or a point uniform on the shape, with the solid-angle
    /// density toward it; a zero-density sample from behind.
    #[inline]
    pub fn sample(&self, p: Vec3, u1: f32, u2: f32) -> LightSample {
        let spherical = self.spherical_from(p);
        let (q, normal) = match (spherical, self.shape) {
            (Some(rect), _) => (rect.sample(u1, u2), self.normal),
            (None, AreaShape::Rect) => (self.at(2.0 * u1 - 1.0, 2.0 * u2 - 1.0), self.normal),
            (None, AreaShape::Disk) => {
                let ab = concentric_disk(u1, u2);
                (self.at(ab.x, ab.y), self.normal)
            }
            (None, AreaShape::Cylinder) => self.on_cylinder(u1, u2),
        };
        let to = q - p;
        let d2 = to.length_squared();
        let d = d2.sqrt();
        let to_light = to / d;
        let cos_l = -to_light.dot(normal);
        if !(cos_l > 0.0 && d > 0.0) {
            return LightSample {
                to_light,
                radiance: Vec3::ZERO,
                pdf: Some(0.0),
                distance: 0.0,
            };
        }
        let pdf = match spherical {
            Some(rect) => (1.0 / rect.solid_angle()) as f32,
            None => d2 / (self.area * cos_l),
        };
        LightSample {
            to_light,
            radiance: self.radiance,
            pdf: Some(pdf),
            distance: d,
        }
    }

    /// Where a ray from `p` along unit `dir` meets the shape's front within
    /// `t_max`: the distance, the radiance and the density with which
    /// [`Self::sample`] at `p` draws `dir`.
    #[inline]
    pub fn hit(&self, p: Vec3, dir: Vec3, t_max: f32) -> Option<(f32, Vec3, f32)> {
        if self.shape == AreaShape::Cylinder {
            let (t, cos_l) = self.cylinder_hit(p, dir, t_max)?;
            return Some((t, self.radiance, t * t / (self.area * cos_l)));
        }
        let cos_l = -dir.dot(self.normal);
        if cos_l <= 0.0 {
            return None;
        }
        let t = (p - self.centre).dot(self.normal) / cos_l;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let r = p + t * dir - self.centre;
        let a = r.dot(self.half_u) / self.half_u.length_squared();
        let b = r.dot(self.half_v) / self.half_v.length_squared();
        let inside = if self.shape == AreaShape::Rect {
            a.abs() <= 1.0 && b.abs() <= 1.0
        } else {
            a * a + b * b <= 1.0
        };
        inside.then(|| {
            let pdf = match self.spherical_from(p) {
                Some(rect) => (1.0 / rect.solid_angle()) as f32,
                None => t * t / (self.area * cos_l),
            };
            (t, self.radiance, pdf)
        })
    }

    /// A point uniform on the cylinder's side at `(u1, u2)` (along the
    /// axis, around it) and its outward normal there.
    #[inline]
    fn on_cylinder(&self, u1: f32, u2: f32) -> (Vec3, Vec3) {
        let radius = self.half_v.length();
        let e1 = self.half_v / radius;
        let e2 = self.normal.cross(e1);
        let (sin, cos) = (TAU * u2).sin_cos();
        let n = cos * e1 + sin * e2;
        (self.centre + (2.0 * u1 - 1.0) * self.half_u + radius * n, n)
    }

    /// Where a ray from `p` outside the cylinder along unit `dir` enters
    /// its side within `t_max`, and the cosine there; rays from inside
    /// meet the side's back, which is dark.
    #[inline]
    fn cylinder_hit(&self, p: Vec3, dir: Vec3, t_max: f32) -> Option<(f32, f32)> {
        // In f64: near grazing the discriminant is a small difference,
        // and it gives the cosine (`sqrt(disc) / r`, for a unit `dir`) that
        // the density must share with the sample's.
        let axis = self.normal.as_dvec3();
        let radius = self.half_v.length() as f64;
        let (o, d) = ((p - self.centre).as_dvec3(), dir.as_dvec3());
        let (oa, da) = (o.dot(axis), d.dot(axis));
        // The ray and its origin across the axis: a quadratic in t.
        let (op, dp) = (o - oa * axis, d - da * axis);
        let a = dp.length_squared();
        let b = op.dot(dp);
        let c = op.length_squared() - radius * radius;
        let disc = b * b - a * c;
        if !(a > 0.0 && c > 0.0 && disc > 0.0) {
            return None;
        }
        let t = (-b - disc.sqrt()) / a;
        let in_length = (oa + t * da).abs() <= self.half_u.length() as f64;
        let cos_l = (disc.sqrt() / radius) as f32;
        (t > 0.0 && t < t_max as f64 && in_length).then_some((t as f32, cos_l))
    }

    /// The luminance of what the light sends toward `p` unoccluded, as an
    /// irradiance (`L A cos theta_l / d^2`, the shape taken for a point at
    /// its centre, bounded near it by its size), for a light choice.
    #[inline]
    pub fn luminance_at(&self, p: Vec3, luminance: f32) -> f32 {
        let to_p = p - self.centre;
        let d2 = to_p.length_squared();
        let cos = self.normal.dot(to_p) / d2.sqrt();
        // The shape's area projected toward `p`: a flat shape's in front
        // of it (nothing behind), a cylinder's side `2 r l sin theta`.
        let projected = match self.shape {
            AreaShape::Cylinder => self.area * (1.0 - cos * cos).max(0.0).sqrt() / PI,
            _ => self.area * cos,
        };
        // At its centre (NaN): nothing.
        if projected.is_nan() || projected <= 0.0 {
            return 0.0;
        }
        luminance * projected / d2.max(0.25 * self.area)
    }
}

/// Shirley and Chiu's concentric map of `[0, 1)^2` onto the unit disc.
#[inline]
pub(super) fn concentric_disk(u1: f32, u2: f32) -> Vec2 {
    let (a, b) = (2.0 * u1 - 1.0, 2.0 * u2 - 1.0);
    if a == 0.0 && b == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else {
        (b, 0.5 * PI - FRAC_PI_4 * (a / b))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lights() -> [AreaLight; 2] {
        [AreaShape::Rect, AreaShape::Disk].map(|shape| {
            AreaLight::new(
                shape,
                Vec3::new(0.0, 3.0, 0.0),
                Vec3::new(0.8, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 0.4),
                Vec3::NEG_Y,
                Vec3::splat(2.0),
            )
        })
    }

    #[test]
    fn samples_lie_on_the_front_and_the_hit_agrees() {
        for l in lights() {
            let p = Vec3::new(0.3, 0.0, -0.2);
            for k in 0..64 {
                let s = l.sample(p, (k as f32 + 0.5) / 64.0, (k as f32 * 0.618).fract());
                let (t, radiance, pdf) = l.hit(p, s.to_light, f32::INFINITY).unwrap();
                assert!((t - s.distance).abs() < 1e-4 * t, "{t} {}", s.distance);
                assert_eq!(radiance, s.radiance);
                assert!((pdf / s.pdf.unwrap() - 1.0).abs() < 1e-3);
            }
            // From behind: nothing.
            let behind = l.sample(Vec3::new(0.0, 5.0, 0.0), 0.3, 0.6);
            assert_eq!(behind.radiance, Vec3::ZERO);
            assert!(l
                .hit(Vec3::new(0.0, 5.0, 0.0), Vec3::NEG_Y, f32::INFINITY)
                .is_none());
            assert!(l
                .hit(
                    Vec3::ZERO,
                    Vec3::new(1.0, 0.2, 0.0).normalize(),
                    f32::INFINITY
                )
                .is_none());
        }
    }

    #[test]
    fn the_sampled_solid_angle_is_the_shapes() {
        // E[1 / pdf] over the samples is the solid angle the shape
        // subtends; from far away, A cos / d^2.
        for l in lights() {
            let p = Vec3::new(0.0, -97.0, 0.0);
            let n = 256;
            let mut omega = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let s = l.sample(p, (i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    omega += 1.0 / s.pdf.unwrap() as f64;
                }
            }
            omega /= (n * n) as f64;
            let expected = l.area() as f64 / 100.0f64.powi(2);
            assert!(
                (omega / expected - 1.0).abs() < 1e-3,
                "{omega} vs {expected}"
            );
        }
        assert!((lights()[1].area() - PI * 0.8 * 0.4).abs() < 1e-6);
    }

    fn cylinder() -> AreaLight {
        AreaLight::cylinder(
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::new(1.0, 0.0, 1.0),
            1.2,
            0.1,
            Vec3::splat(2.0),
        )
    }

    #[test]
    fn a_cylinders_samples_lie_on_its_side_and_the_hit_agrees() {
        let l = cylinder();
        assert!((l.area() - 2.0 * PI * 0.1 * 1.2).abs() < 1e-6);
        let p = Vec3::new(0.3, 0.0, -0.2);
        let mut lit = 0;
        for k in 0..256 {
            let s = l.sample(p, (k as f32 + 0.5) / 256.0, (k as f32 * 0.618).fract());
            let hit = l.hit(p, s.to_light, f32::INFINITY);
            if s.radiance == Vec3::ZERO {
                // The far side, facing away: the ray meets the near side
                // first, or nothing.
                continue;
            }
            lit += 1;
            // Where the ray grazes the side, an f32 direction cannot say
            // where it touches: check the others.
            let cos_l = s.distance * s.distance / (l.area() * s.pdf.unwrap());
            if cos_l < 0.05 {
                continue;
            }
            let (t, radiance, pdf) = hit.unwrap();
            assert!((t - s.distance).abs() < 1e-4 * t, "{t} {}", s.distance);
            assert_eq!(radiance, s.radiance);
            assert!(
                (pdf / s.pdf.unwrap() - 1.0).abs() < 1e-3,
                "{k}: {pdf} {:?}",
                s.pdf
            );
            // On the side: at the radius from the axis, within its length.
            let o = p + t * s.to_light - l.centre();
            let along = o.dot(l.normal());
            assert!(along.abs() <= 0.6 + 1e-4);
            assert!(((o - along * l.normal()).length() - 0.1).abs() < 1e-4);
        }
        assert!((96..=160).contains(&lit), "{lit} of 256 on the near side");
        // From inside, along the axis beyond a cap, or past its end: dark.
        let inside = l.centre() + 0.05 * Vec3::Y;
        assert!(l.hit(inside, Vec3::Y, f32::INFINITY).is_none());
        assert_eq!(l.sample(inside, 0.3, 0.6).radiance, Vec3::ZERO);
        let beyond = l.centre() + 2.0 * l.normal();
        assert!(l.hit(beyond, -l.normal(), f32::INFINITY).is_none());
        assert!(l
            .hit(p, Vec3::new(-1.0, 3.0, 0.2).normalize(), 0.5)
            .is_none());
    }

    #[test]
    fn a_far_cylinder_subtends_its_projected_side() {
        // E[1 / pdf] over the samples (the far side's count 0) is the
        // solid angle the side subtends: from far away, 2 r l sin theta
        // / d^2, theta the angle off the axis (nearer, the caps' rims
        // seen at different distances add (r / d)^2 terms: 0.7% at 100
        // units seen 12 degrees off the axis).
        let l = cylinder();
        for dir in [
            Vec3::NEG_Y,
            Vec3::new(0.6, -0.8, 0.0),
            Vec3::new(1.0, -0.3, 1.0),
        ] {
            let dir = dir.normalize();
            let p = l.centre() - 1000.0 * dir;
            let n = 256;
            let mut omega = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let s = l.sample(p, (i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    if s.radiance != Vec3::ZERO {
                        omega += 1.0 / s.pdf.unwrap() as f64;
                    }
                }
            }
            omega /= (n * n) as f64;
            let sin = dir.cross(l.normal()).length() as f64;
            let expected = 2.0 * 0.1 * 1.2 * sin / 1000.0f64.powi(2);
            assert!(
                (omega / expected - 1.0).abs() < 2e-3,
                "{dir}: {omega} vs {expected}"
            );
            let lum = l.luminance_at(p, 1.0) as f64;
            assert!((lum / expected - 1.0).abs() < 1e-3, "{lum} vs {expected}");
        }
    }
}
