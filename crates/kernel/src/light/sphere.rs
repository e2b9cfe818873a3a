//! Sphere lights: a ball of uniform radiance emitting outward (UsdLux's
//! `SphereLight`, Blender's point lamp), a true point where its radius is
//! zero, and shaped into a spot light by a cone.
//!
//! A light is described by its radiant intensity `I` (W/sr per channel):
//! what it sends toward any direction far away. A ball of radius `r` and
//! radiance `L` sends `I = L pi r^2` (its projected area times `L`), so
//! the same `I` lights the far field alike at any radius and the radius
//! only softens shadows and near light.
//!
//! Sampling from a point `p` outside the ball draws directions uniformly
//! inside the cone the ball subtends (pbrt-v4's `SphereLight` and
//! Cycles' point lights do the same): density `1 / (2 pi (1 - cos
//! theta_max))` with `sin theta_max = r / d`, the radiance `L` along each
//! (a sphere of uniform radiance looks like a disc of uniform radiance).
//! A point light is a delta: `I / d^2` along the one direction. A point
//! inside the ball receives its radiance from every direction, as inside
//! Cycles' point lamps (fog within a lamp's radius glows): directions are
//! drawn uniformly over the sphere, density `1 / 4 pi`, each to where it
//! leaves the ball. Whether a direction brings light thus depends only on
//! where it starts (outside: if it meets the ball; inside: always), which
//! sampling and rays that meet the ball share, so the two weigh alike.
//! Inside a spot's ball the cone does not apply (as in Cycles: every
//! direction brings the ball's full radiance).
//!
//! With soft falloff (Blender's Soft Falloff, `facing_disk.rs`) the light
//! is instead the disc of the same radius and radiance through its centre
//! facing the lit point, sampled and met with Cycles' densities.

use std::f32::consts::PI;

use glam::Vec3;

use super::facing_disk::FacingDisk;
use super::LightSample;
use crate::sampling::{uniform_cone, uniform_sphere, UNIFORM_SPHERE_PDF};

/// A spot light's cone about its axis. The light's radiance along a
/// direction `theta` off the axis (from the light toward what it lights;
/// for a ball, each of its points' emission, as Cycles' spot lamps) is
/// scaled by `smoothstep(cos_outer, cos_inner, cos theta)`, where
/// `cos_inner = cos_outer + softness (1 - cos_outer)`: full inside the
/// inner cone, none outside the cone's angle (Cycles' spot
/// blend, UsdLux ShapingAPI's cone angle and softness).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    /// Unit vector along which the spot points, from the light outward.
    axis: Vec3,
    cos_outer: f32,
    cos_inner: f32,
}

impl Spot {
    /// A cone of half-angle `half_angle` (radians, in [0, pi]) about
    /// `axis`, its edge softened over the fraction `softness` (in [0, 1])
    /// of `1 - cos(half_angle)`.
    pub fn new(axis: Vec3, half_angle: f32, softness: f32) -> Self {
        let cos_outer = half_angle.clamp(0.0, PI).cos();
        let softness = softness.clamp(0.0, 1.0);
        Self {
            axis: axis.normalize(),
            cos_outer,
            cos_inner: cos_outer + softness * (1.0 - cos_outer),
        }
    }

    pub fn axis(&self) -> Vec3 {
        self.axis
    }

    /// The cosine of the cone's half-angle, past which it sends nothing.
    pub fn cos_outer(&self) -> f32 {
        self.cos_outer
    }

    /// The cosines of its outer and inner angles, between which
    /// [`Self::falloff`] blends (for backends that evaluate it
    /// themselves).
    pub fn cosines(&self) -> (f32, f32) {
        (self.cos_outer, self.cos_inner)
    }

    /// The fraction of the intensity sent along `dir` (unit, from the light).
    #[inline]
    pub fn falloff(&self, dir: Vec3) -> f32 {
        let c = self.axis.dot(dir);
        if c <= self.cos_outer {
            0.0
        } else if c >= self.cos_inner {
            1.0
        } else {
            let t = (c - self.cos_outer) / (self.cos_inner - self.cos_outer);
            t * t * (3.0 - 2.0 * t)
        }
    }
}

/// A sphere (or point) light, optionally shaped by a spot cone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereLight {
    position: Vec3,
    radius: f32,
    /// Radiant intensity, W/sr per channel.
    intensity: Vec3,
    spot: Option<Spot>,
    /// Whether camera rays see the ball (off by default, as Arnold's and
    /// Cycles' lamps: the light shows in the media it lights, not as a
    /// bright disc in the image); scattered rays always meet it.
    camera_visible: bool,
    /// Whether it lights a point from the disc through its centre facing
    /// the point rather than from its ball (`facing_disk.rs`).
    soft_falloff: bool,
}

impl SphereLight {
    /// A light at `position` of radius `radius` (0: a point) sending the
    /// radiant intensity `intensity` (W/sr per channel) toward every
    /// direction.
    pub fn new(position: Vec3, radius: f32, intensity: Vec3) -> Self {
        Self {
            position,
            radius: radius.max(0.0),
            intensity,
            spot: None,
            camera_visible: false,
            soft_falloff: false,
        }
    }

    /// The same light, lighting each point from the disc through its
    /// centre facing the point where `soft` (Blender's Soft Falloff).
    pub fn with_soft_falloff(self, soft: bool) -> Self {
        Self {
            soft_falloff: soft,
            ..self
        }
    }

    /// Whether it lights from a facing disc ([`Self::with_soft_falloff`]).
    pub fn soft_falloff(&self) -> bool {
        self.soft_falloff
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

    /// The same light shaped by `spot`'s cone.
    pub fn with_spot(self, spot: Spot) -> Self {
        Self {
            spot: Some(spot),
            ..self
        }
    }

    /// The same light at `position`.
    pub fn moved_to(self, position: Vec3) -> Self {
        Self { position, ..self }
    }

    pub fn position(&self) -> Vec3 {
        self.position
    }

    pub fn radius(&self) -> f32 {
        self.radius
    }

    pub fn intensity(&self) -> Vec3 {
        self.intensity
    }

    pub fn spot(&self) -> Option<&Spot> {
        self.spot.as_ref()
    }

    /// Whether it is a point, which no ray can hit.
    pub fn is_point(&self) -> bool {
        self.radius <= 0.0
    }

    /// The radiance of its surface, `I / (pi r^2)` (infinite for a point).
    pub fn radiance(&self) -> Vec3 {
        self.intensity / (PI * self.radius * self.radius)
    }

    /// The spot's falloff toward unit direction `dir` from the light's
    /// centre (1 without a spot).
    #[inline]
    pub fn falloff(&self, dir: Vec3) -> f32 {
        self.spot.map_or(1.0, |s| s.falloff(dir))
    }

    /// `1 - cos theta_max` of the cone the ball subtends from distance
    /// `d2.sqrt()` to its centre, as `sin^2 / (1 + cos)` so that a small
    /// far ball keeps its solid angle; `None` from inside the ball (every
    /// direction sees it).
    #[inline]
    fn cone(&self, d2: f32) -> Option<f32> {
        let r2 = self.radius * self.radius;
        if d2 <= r2 {
            return None;
        }
        let sin2 = r2 / d2;
        Some(sin2 / (1.0 + (1.0 - sin2).sqrt()))
    }

    /// Samples the light from `p`: a point's one direction, or a direction
    /// uniform in the cone the ball subtends with the distance to its near
    /// surface; from inside the ball, a direction uniform over the sphere
    /// with the distance to where it leaves the ball (and no spot cone);
    /// with soft falloff, a point uniform on the disc facing `p`.
    #[inline]
    pub fn sample(&self, p: Vec3, u1: f32, u2: f32) -> LightSample {
        let to_centre = self.position - p;
        let d2 = to_centre.length_squared();
        let d = d2.sqrt();
        let axis = to_centre / d;
        if self.is_point() {
            return LightSample {
                to_light: axis,
                radiance: self.intensity * (self.falloff(-axis) / d2),
                pdf: None,
                distance: d,
            };
        }
        if self.soft_falloff {
            let disk = FacingDisk::facing(p, self.position, self.radius);
            return match disk.sample(p, u1, u2) {
                Some((to_light, distance, pdf)) => LightSample {
                    to_light,
                    radiance: self.radiance() * self.falloff(-to_light),
                    pdf: Some(pdf),
                    distance,
                },
                None => LightSample {
                    to_light: axis,
                    radiance: Vec3::ZERO,
                    pdf: Some(0.0),
                    distance: 0.0,
                },
            };
        }
        let Some(one_minus_cos) = self.cone(d2) else {
            let to_light = uniform_sphere(u1, u2);
            return LightSample {
                to_light,
                radiance: self.radiance(),
                pdf: Some(UNIFORM_SPHERE_PDF),
                distance: self.exit_distance(to_centre, to_light),
            };
        };
        let to_light = uniform_cone(axis, one_minus_cos, u1, u2);
        let distance = self.hit_distance(to_centre, to_light).unwrap_or(d);
        LightSample {
            to_light,
            radiance: self.radiance() * self.falloff(-to_light),
            pdf: Some(1.0 / (2.0 * PI * one_minus_cos)),
            distance,
        }
    }

    /// Where a ray from `p` along unit `dir` first meets the ball within
    /// `t_max` (its outside; from inside, where it leaves): the distance,
    /// the radiance it sees there and the density with which
    /// [`Self::sample`] at `p` draws `dir`; with soft falloff, where it
    /// meets the disc facing `p`. `None` for a point or a miss.
    #[inline]
    pub fn hit(&self, p: Vec3, dir: Vec3, t_max: f32) -> Option<(f32, Vec3, f32)> {
        if self.is_point() {
            return None;
        }
        if self.soft_falloff {
            let disk = FacingDisk::facing(p, self.position, self.radius);
            let (t, pdf) = disk.hit(p, dir, t_max)?;
            return Some((t, self.radiance() * self.falloff(-dir), pdf));
        }
        let to_centre = self.position - p;
        let d2 = to_centre.length_squared();
        let (t, pdf, falloff) = match self.cone(d2) {
            Some(one_minus_cos) => (
                self.hit_distance(to_centre, dir)?,
                1.0 / (2.0 * PI * one_minus_cos),
                self.falloff(-dir),
            ),
            None => (self.exit_distance(to_centre, dir), UNIFORM_SPHERE_PDF, 1.0),
        };
        (t < t_max).then(|| (t, self.radiance() * falloff, pdf))
    }

    /// The near root of the ray from the ball's outside (`to_centre` from
    /// the origin to the centre) along unit `dir`, if it meets the ball
    /// ahead.
    #[inline]
    fn hit_distance(&self, to_centre: Vec3, dir: Vec3) -> Option<f32> {
        let b = to_centre.dot(dir);
        // The squared distance from the centre to the line, taken from
        // the perpendicular component so it does not cancel for a small
        // far ball.
        let perp2 = (to_centre - b * dir).length_squared();
        let h2 = self.radius * self.radius - perp2;
        (b > 0.0 && h2 >= 0.0).then(|| (b - h2.sqrt()).max(0.0))
    }

    /// The far root of the ray from inside the ball (`to_centre` from the
    /// origin to the centre) along unit `dir`: where it leaves.
    #[inline]
    fn exit_distance(&self, to_centre: Vec3, dir: Vec3) -> f32 {
        let b = to_centre.dot(dir);
        let perp2 = (to_centre - b * dir).length_squared();
        b + (self.radius * self.radius - perp2).max(0.0).sqrt()
    }

    /// What the light sends toward `p` unoccluded, in luminance of the
    /// irradiance at `p` (`I / d^2`, the spot's falloff, bounded near the
    /// ball by its radius): what a light choice weighs it by.
    #[inline]
    pub fn luminance_at(&self, p: Vec3, luminance: f32) -> f32 {
        let to_p = p - self.position;
        let d2 = to_p.length_squared().max(self.radius * self.radius);
        let falloff = match &self.spot {
            Some(s) => s.falloff(to_p.normalize_or_zero()),
            None => 1.0,
        };
        luminance * falloff / d2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_far_ball_subtends_its_projected_area() {
        let l = SphereLight::new(Vec3::ZERO, 0.01, Vec3::ONE);
        let omc = l.cone(100.0 * 100.0).unwrap();
        let solid_angle = 2.0 * PI * omc;
        let expected = PI * 1e-4 / 1e4;
        assert!((solid_angle / expected - 1.0).abs() < 1e-4, "{solid_angle}");
        // Radiance over the solid angle is the point light's I / d^2.
        let e = l.radiance().x * solid_angle;
        assert!((e / 1e-4 - 1.0).abs() < 1e-3, "{e}");
    }

    #[test]
    fn sampled_directions_meet_the_ball_and_the_hit_agrees() {
        let l = SphereLight::new(Vec3::new(1.0, 2.0, 3.0), 0.7, Vec3::splat(2.0));
        // From outside, and from inside (where every direction sees it).
        let inside = l.position() + Vec3::new(0.2, -0.3, 0.1);
        for p in [Vec3::new(-1.0, 0.5, 0.0), inside] {
            for k in 0..64 {
                let (u1, u2) = ((k as f32 + 0.5) / 64.0, (k as f32 * 0.618).fract());
                let s = l.sample(p, u1, u2);
                let on = p + s.distance * s.to_light;
                assert!(((on - l.position()).length() - 0.7).abs() < 1e-4);
                let (t, radiance, pdf) = l.hit(p, s.to_light, f32::INFINITY).unwrap();
                assert!((t - s.distance).abs() < 1e-4);
                assert_eq!(radiance, s.radiance);
                assert_eq!(Some(pdf), s.pdf);
            }
        }
        assert!(
            l.hit(Vec3::new(-1.0, 0.5, 0.0), -Vec3::X, f32::INFINITY)
                .is_none(),
            "a miss"
        );
        let (_, radiance, pdf) = l.hit(inside, Vec3::X, f32::INFINITY).unwrap();
        assert_eq!((radiance, pdf), (l.radiance(), 1.0 / (4.0 * PI)));
        let p = Vec3::new(-1.0, 0.5, 0.0);
        assert!(
            l.hit(p, (l.position() - p).normalize(), 1.0).is_none(),
            "beyond t_max"
        );
    }

    #[test]
    fn a_point_is_a_delta_of_intensity_over_distance_squared() {
        let l = SphereLight::new(Vec3::new(0.0, 4.0, 0.0), 0.0, Vec3::new(8.0, 4.0, 2.0));
        let s = l.sample(Vec3::ZERO, 0.3, 0.9);
        assert_eq!(s.pdf, None);
        assert_eq!(s.to_light, Vec3::Y);
        assert_eq!(s.distance, 4.0);
        assert_eq!(s.radiance, Vec3::new(0.5, 0.25, 0.125));
        assert!(l.hit(Vec3::ZERO, Vec3::Y, f32::INFINITY).is_none());
    }

    #[test]
    fn a_spot_lights_its_cone_and_softens_its_edge() {
        let spot = Spot::new(-Vec3::Y, 30f32.to_radians(), 0.5);
        assert_eq!(spot.falloff(-Vec3::Y), 1.0);
        assert_eq!(spot.falloff(Vec3::X), 0.0);
        let at = |deg: f32| {
            let a = deg.to_radians();
            spot.falloff(Vec3::new(a.sin(), -a.cos(), 0.0))
        };
        assert_eq!(at(31.0), 0.0);
        assert_eq!(at(10.0), 1.0);
        let (mid, inner) = (at(25.0), at(15.0));
        assert!(mid > 0.0 && mid < inner && inner <= 1.0, "{mid} {inner}");
        let l = SphereLight::new(Vec3::Y, 0.0, Vec3::ONE).with_spot(spot);
        assert_eq!(
            l.sample(Vec3::new(0.0, -1.0, 0.0), 0.5, 0.5).radiance,
            Vec3::splat(0.25)
        );
        assert_eq!(
            l.sample(Vec3::new(5.0, 1.0, 0.0), 0.5, 0.5).radiance,
            Vec3::ZERO
        );
    }

    /// With soft falloff the light is the disc facing the point: the
    /// irradiance-like integral of its radiance over the directions it
    /// samples (the mean of `L / pdf`) is `2 pi L (1 - d / sqrt(d^2 +
    /// r^2))` at distance `d`, inside the ball's radius too, and a ray
    /// meets it where the sample lies.
    #[test]
    fn soft_falloff_lights_from_the_facing_disc() {
        let (r, d) = (2.0f32, 0.5f32);
        let l = SphereLight::new(Vec3::ZERO, r, Vec3::splat(PI * r * r)).with_soft_falloff(true);
        assert_eq!(l.radiance(), Vec3::ONE);
        let p = Vec3::new(d, 0.0, 0.0);
        let n = 128;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let (u1, u2) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let s = l.sample(p, u1, u2);
                let pdf = s.pdf.unwrap();
                if pdf > 0.0 {
                    sum += (s.radiance.x / pdf) as f64;
                    let (t, radiance, hit_pdf) = l.hit(p, s.to_light, f32::INFINITY).unwrap();
                    assert!((t - s.distance).abs() < 1e-4 && radiance == s.radiance);
                    assert!((hit_pdf / pdf - 1.0).abs() < 1e-3);
                }
            }
        }
        let exact = 2.0 * std::f64::consts::PI * (1.0 - 0.5 / (0.25f64 + 4.0).sqrt());
        let mean = sum / (n * n) as f64;
        assert!((mean / exact - 1.0).abs() < 2e-3, "{mean} {exact}");
        // Rays away from the centre miss it: no point is inside a disc.
        assert!(l.hit(p, Vec3::X, f32::INFINITY).is_none());
    }

    /// Inside a spot's ball every direction brings the ball's radiance,
    /// the cone notwithstanding (Cycles' spot lamps); outside, the cone
    /// shapes it.
    #[test]
    fn inside_a_spots_ball_the_cone_does_not_apply() {
        let spot = Spot::new(-Vec3::Y, 20f32.to_radians(), 0.0);
        let l = SphereLight::new(Vec3::ZERO, 1.0, Vec3::splat(PI)).with_spot(spot);
        let inside = Vec3::new(0.0, 0.5, 0.0);
        let s = l.sample(inside, 0.3, 0.7);
        assert_eq!(s.radiance, Vec3::ONE);
        let (_, radiance, _) = l.hit(inside, Vec3::X, f32::INFINITY).unwrap();
        assert_eq!(radiance, Vec3::ONE);
        let above = Vec3::new(0.0, 3.0, 0.0);
        assert_eq!(l.sample(above, 0.3, 0.7).radiance, Vec3::ZERO);
    }
}
