//! Sampling a rectangle uniformly in the solid angle it subtends from a
//! point (Urena, Fajardo and King 2013, "An Area-Preserving
//! Parametrization for Spherical Rectangles", section 4 and its listing).
//!
//! The rectangle's projection on the unit sphere about the point is a
//! spherical quadrilateral of solid angle `S = g0 + g1 + g2 + g3 - 2 pi`
//! (its interior angles); a first number picks the sub-area swept from
//! one edge (an angle, inverted in closed form), a second the height
//! along the chosen line, so the density is `1 / S` everywhere and the
//! samples follow the light's visible extent however close the point is,
//! where a uniform point on the area would give `d^2 / (A cos)`, unbounded
//! near an edge.
//!
//! The angles are summed in f64: `S` is a small difference of angles near
//! `pi`, and in f32 it loses all its digits once the light subtends less
//! than about 1e-6 sr. Below [`SphericalRect::MIN_SOLID_ANGLE`] the
//! caller samples the area instead (the two densities agree there to
//! within the rectangle's angular size squared).

use std::f64::consts::TAU;

use glam::{DVec3, Vec3};

/// A rectangle as seen from a point, ready to be sampled.
#[derive(Clone, Copy, Debug)]
pub struct SphericalRect {
    o: DVec3,
    x: DVec3,
    y: DVec3,
    z: DVec3,
    z0: f64,
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
    b0: f64,
    b1: f64,
    k: f64,
    solid_angle: f64,
}

impl SphericalRect {
    /// Solid angles under which the rectangle is sampled by area instead.
    pub const MIN_SOLID_ANGLE: f64 = 1e-5;

    /// The rectangle `corner + a ex + b ey` (`a, b` in `[0, 1]`, `ex`
    /// perpendicular to `ey`) seen from `o`; `None` where it subtends
    /// less than [`Self::MIN_SOLID_ANGLE`] or `o` lies in its plane.
    pub fn seen_from(corner: Vec3, ex: Vec3, ey: Vec3, o: Vec3) -> Option<Self> {
        let (ex, ey, o) = (ex.as_dvec3(), ey.as_dvec3(), o.as_dvec3());
        let (exl, eyl) = (ex.length(), ey.length());
        let x = ex / exl;
        let y = ey / eyl;
        let mut z = x.cross(y);
        let d = corner.as_dvec3() - o;
        let mut z0 = d.dot(z);
        // The local frame has the rectangle below the point (z0 < 0).
        if z0 > 0.0 {
            z = -z;
            z0 = -z0;
        }
        let (x0, y0) = (d.dot(x), d.dot(y));
        let (x1, y1) = (x0 + exl, y0 + eyl);
        // The normals of the four planes through `o` and an edge.
        let n0 = DVec3::new(0.0, z0, -y0).normalize();
        let n1 = DVec3::new(-z0, 0.0, x1).normalize();
        let n2 = DVec3::new(0.0, -z0, y1).normalize();
        let n3 = DVec3::new(z0, 0.0, -x0).normalize();
        let g0 = (-n0.dot(n1)).clamp(-1.0, 1.0).acos();
        let g1 = (-n1.dot(n2)).clamp(-1.0, 1.0).acos();
        let g2 = (-n2.dot(n3)).clamp(-1.0, 1.0).acos();
        let g3 = (-n3.dot(n0)).clamp(-1.0, 1.0).acos();
        let k = TAU - g2 - g3;
        let solid_angle = g0 + g1 - k;
        (solid_angle >= Self::MIN_SOLID_ANGLE).then_some(Self {
            o,
            x,
            y,
            z,
            z0,
            x0,
            y0,
            x1,
            y1,
            b0: n0.z,
            b1: n2.z,
            k,
            solid_angle,
        })
    }

    /// The solid angle the rectangle subtends: `1 / pdf` of its samples.
    pub fn solid_angle(&self) -> f64 {
        self.solid_angle
    }

    /// The point of the rectangle whose direction from `o` is the sample
    /// `(u, v)` in `[0, 1)^2` of the uniform density over the solid angle.
    pub fn sample(&self, u: f32, v: f32) -> Vec3 {
        let (u, v) = (u as f64, v as f64);
        // The sub-area `u S` fixes the angle `au`, whose line across the
        // rectangle is at `xu`.
        let au = u * self.solid_angle + self.k;
        let fu = (au.cos() * self.b0 - self.b1) / au.sin();
        let cu = (fu.signum() / (fu * fu + self.b0 * self.b0).sqrt()).clamp(-1.0, 1.0);
        let xu = (-(cu * self.z0) / (1.0 - cu * cu).sqrt()).clamp(self.x0, self.x1);
        // Along that line, uniform in the sine of the elevation.
        let d = (xu * xu + self.z0 * self.z0).sqrt();
        let h0 = self.y0 / (d * d + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (d * d + self.y1 * self.y1).sqrt();
        let hv = h0 + v * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-12 {
            (hv * d / (1.0 - hv2).sqrt()).clamp(self.y0, self.y1)
        } else {
            self.y1
        };
        (self.o + xu * self.x + yv * self.y + self.z0 * self.z).as_vec3()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1.6 x 0.8 rectangle in the plane y = 1, seen from `o`.
    fn rect(o: Vec3) -> Option<SphericalRect> {
        SphericalRect::seen_from(
            Vec3::new(-0.8, 1.0, -0.4),
            Vec3::new(1.6, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.8),
            o,
        )
    }

    /// The integral of `f` over the directions from `o` to the rectangle,
    /// by quadrature of `f cos / d^2` over its area (`n^2` points).
    fn over_area(o: Vec3, n: usize, f: impl Fn(DVec3) -> f64) -> f64 {
        let mut sum = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let p = DVec3::new(
                    -0.8 + 1.6 * (i as f64 + 0.5) / n as f64,
                    1.0,
                    -0.4 + 0.8 * (j as f64 + 0.5) / n as f64,
                );
                let to = p - o.as_dvec3();
                sum += f(to.normalize()) * to.y.abs() / to.length().powi(3);
            }
        }
        sum * 1.28 / (n * n) as f64
    }

    #[test]
    fn the_solid_angle_is_the_rectangles() {
        for o in [
            Vec3::new(0.1, 0.0, 0.05),
            Vec3::new(0.7, 0.95, 0.3),
            Vec3::new(-2.0, 3.0, 1.0),
        ] {
            let s = rect(o).unwrap().solid_angle();
            let q = over_area(o, 2000, |_| 1.0);
            assert!((s / q - 1.0).abs() < 2e-4, "{o}: {s} against {q}");
        }
        // Above the centre at height h, in closed form:
        // 4 asin(a b / sqrt((a^2 + h^2) (b^2 + h^2))) for half sides a, b.
        for h in [1e-3f64, 0.3, 5.0] {
            let s = rect(Vec3::new(0.0, (1.0 - h) as f32, 0.0))
                .unwrap()
                .solid_angle();
            let (a, b) = (0.8f64, 0.4f64);
            let exact = 4.0 * (a * b / ((a * a + h * h) * (b * b + h * h)).sqrt()).asin();
            assert!((s / exact - 1.0).abs() < 1e-5, "{h}: {s} against {exact}");
        }
    }

    #[test]
    fn samples_lie_on_the_rectangle_with_density_one_over_the_solid_angle() {
        // Any function of the direction integrates the same over the
        // solid angle by these samples (S times their mean) and by
        // quadrature over the area (cos / d^2 dA): only if the samples'
        // density is 1 / S. From near a corner the extent is lopsided.
        let f = |w: DVec3| 1.0 + 3.0 * w.x * w.x + w.z;
        for o in [Vec3::new(0.7, 0.9, 0.3), Vec3::new(-0.2, -0.5, 0.1)] {
            let r = rect(o).unwrap();
            let n = 400;
            let mut by_samples = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let p = r.sample((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    assert!((p.y - 1.0).abs() < 1e-5, "{p}");
                    assert!(p.x.abs() <= 0.8 + 1e-5 && p.z.abs() <= 0.4 + 1e-5, "{p}");
                    by_samples += f((p - o).as_dvec3().normalize());
                }
            }
            by_samples *= r.solid_angle() / (n * n) as f64;
            let by_area = over_area(o, 1000, f);
            assert!(
                (by_samples / by_area - 1.0).abs() < 1e-3,
                "{o}: {by_samples} against {by_area}"
            );
        }
    }

    #[test]
    fn a_tiny_or_edge_on_rectangle_is_left_to_area_sampling() {
        assert!(rect(Vec3::new(0.0, -2000.0, 0.0)).is_none());
        assert!(rect(Vec3::new(3.0, 1.0, 0.0)).is_none());
    }
}
