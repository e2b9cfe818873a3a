//! The disc a sphere light with soft falloff shows a point: Blender's
//! Soft Falloff (on by default for point and spot lamps) lights a point
//! `p` not from the ball but from the disc of the same radius through the
//! light's centre facing `p` (Cycles' point and spot lights with
//! `is_sphere` false). The disc has the ball's radiance `I / (pi r^2)`, so
//! it sends the same intensity far away; near the light it brings less
//! (at most `2 pi L` at the centre, where the ball brings `4 pi L`), and
//! no point is ever inside it.
//!
//! Sampled as Cycles samples it: a point uniform on the disc, density
//! `t^2 / (pi r^2 cos)` per solid angle at distance `t` and cosine `cos`
//! to the disc's normal; a ray from `p` meets the disc facing its own
//! origin, with the same density.

use std::f32::consts::PI;

use glam::Vec3;

use super::area::concentric_disk;

/// The disc of radius `radius` through `centre` facing a point.
#[derive(Clone, Copy, Debug)]
pub(super) struct FacingDisk {
    centre: Vec3,
    /// Unit normal from the centre toward the point it faces.
    normal: Vec3,
    radius: f32,
}

impl FacingDisk {
    /// The disc through `centre` facing `p` (any orientation where `p` is
    /// the centre itself, a set of no measure).
    #[inline]
    pub(super) fn facing(p: Vec3, centre: Vec3, radius: f32) -> Self {
        Self {
            centre,
            normal: (p - centre).normalize_or(Vec3::Z),
            radius,
        }
    }

    /// The density per solid angle of a direction that meets the disc at
    /// distance `t` at cosine `cos` to its normal.
    #[inline]
    fn pdf(&self, t: f32, cos: f32) -> f32 {
        t * t / (PI * self.radius * self.radius * cos)
    }

    /// A direction from `p` toward a point uniform on the disc: the unit
    /// direction, its distance and density; `None` where it grazes the
    /// disc (no light).
    #[inline]
    pub(super) fn sample(&self, p: Vec3, u1: f32, u2: f32) -> Option<(Vec3, f32, f32)> {
        let (s, t) = self.normal.any_orthonormal_pair();
        let ab = concentric_disk(u1, u2) * self.radius;
        let q = self.centre + ab.x * s + ab.y * t;
        let to = q - p;
        let dist = to.length();
        let dir = to / dist;
        let cos = -dir.dot(self.normal);
        (cos > 0.0 && dist > 0.0).then(|| (dir, dist, self.pdf(dist, cos)))
    }

    /// Where a ray from `p` (the point the disc faces) along unit `dir`
    /// meets it within `t_max`: the distance and the density with which
    /// [`Self::sample`] draws `dir`.
    #[inline]
    pub(super) fn hit(&self, p: Vec3, dir: Vec3, t_max: f32) -> Option<(f32, f32)> {
        let height = (p - self.centre).dot(self.normal);
        let cos = -dir.dot(self.normal);
        if !(height > 0.0 && cos > 0.0) {
            return None;
        }
        let t = height / cos;
        let off = p + t * dir - self.centre;
        (off.length_squared() < self.radius * self.radius && t < t_max)
            .then(|| (t, self.pdf(t, cos)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampled_directions_meet_the_disc_and_the_hit_agrees() {
        let (p, centre) = (Vec3::new(0.3, -0.2, 0.4), Vec3::new(1.0, 2.0, 3.0));
        let disk = FacingDisk::facing(p, centre, 1.5);
        for k in 0..64 {
            // Inside the rim (where rounding may put the hit either side).
            let (u1, u2) = (
                (k as f32 + 0.5) / 64.0,
                0.01 + 0.98 * (k as f32 * 0.618).fract(),
            );
            let (dir, dist, pdf) = disk.sample(p, u1, u2).unwrap();
            let (t, hit_pdf) = disk.hit(p, dir, f32::INFINITY).unwrap();
            assert!((t - dist).abs() < 1e-4 * dist, "{t} {dist}");
            assert!((hit_pdf / pdf - 1.0).abs() < 1e-4, "{hit_pdf} {pdf}");
        }
        assert!(disk
            .hit(p, (p - centre).normalize(), f32::INFINITY)
            .is_none());
    }

    /// The solid angle the disc subtends from the axis at height `h`,
    /// `2 pi (1 - h / sqrt(h^2 + r^2))`, is the mean of `1 / pdf` over
    /// its samples.
    #[test]
    fn its_samples_weigh_its_solid_angle() {
        let (r, h) = (2.0f32, 0.5f32);
        let p = Vec3::new(0.0, h, 0.0);
        let disk = FacingDisk::facing(p, Vec3::ZERO, r);
        let n = 256;
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let (u1, u2) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                sum += disk.sample(p, u1, u2).map_or(0.0, |s| 1.0 / s.2 as f64);
            }
        }
        let mean = sum / (n * n) as f64;
        let exact = 2.0 * std::f64::consts::PI * (1.0 - h as f64 / ((h * h + r * r) as f64).sqrt());
        assert!((mean / exact - 1.0).abs() < 1e-3, "{mean} {exact}");
    }
}
