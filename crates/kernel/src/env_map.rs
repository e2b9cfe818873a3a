//! A latitude-longitude HDR environment map, importance-sampled.
//!
//! Mapping (Mitsuba 3's `envmap`, so maps lit there look the same here):
//! for a unit direction `d` toward the sky (the direction an escaping ray
//! travels), after undoing the map's rotation about +Y,
//! `u = atan2(d.x, -d.z) / 2 pi` (wrapped to `[0, 1)`) and
//! `v = acos(d.y) / pi`: row 0 is straight up (+Y), the middle row is the
//! horizon, column 0 looks along -Z and u grows toward +X.
//!
//! Radiance is the texel's, constant over it (no filtering), so the map
//! is exactly the piecewise-constant function its sampling distribution
//! follows. Sampling (pbrt-v4 `ImageInfiniteLight`, Pharr et al. 4th ed.
//! section 12.5.2): a [`Distribution2D`] over `(u, v)` with weights
//! `max(r, g, b) * sin(theta)` at each row's centre (the `sin` makes the
//! density per steradian follow the radiance), and the solid-angle density
//! `p(w) = p(u, v) / (2 pi^2 sin(theta))`.

use std::f32::consts::PI;

use glam::Vec3;

use crate::distribution::Distribution2D;

/// An equirectangular environment map with its sampling distribution.
#[derive(Clone, Debug)]
pub struct EnvMap {
    width: usize,
    height: usize,
    /// Row-major, row 0 at the top (+Y).
    texels: Vec<Vec3>,
    distribution: Distribution2D,
    /// Rotation about +Y in radians, as (cos, sin).
    rotation: (f32, f32),
    /// Radiance averaged over the sphere (by solid angle).
    mean: Vec3,
}

impl EnvMap {
    /// A map from row-major texels (row 0 = up), rotated by
    /// `rotation_degrees` about +Y (positive turns the sky counter-clockwise
    /// seen from above). Negative and non-finite radiance become 0.
    pub fn new(width: usize, height: usize, texels: Vec<Vec3>, rotation_degrees: f32) -> Self {
        assert!(width > 0 && height > 0 && texels.len() == width * height);
        let texels: Vec<Vec3> = texels
            .into_iter()
            .map(|t| {
                let t = if t.is_finite() { t } else { Vec3::ZERO };
                t.max(Vec3::ZERO)
            })
            .collect();
        let mut weights = Vec::with_capacity(texels.len());
        let mut mean = Vec3::ZERO;
        let mut total = 0.0;
        for row in 0..height {
            let theta0 = PI * row as f32 / height as f32;
            let theta1 = PI * (row + 1) as f32 / height as f32;
            let sin_c = (PI * (row as f32 + 0.5) / height as f32).sin();
            // Exact solid angle of a texel in this row.
            let omega = 2.0 * PI / width as f32 * (theta0.cos() - theta1.cos());
            for t in &texels[row * width..(row + 1) * width] {
                weights.push(t.max_element() * sin_c);
                mean += *t * omega;
                total += omega;
            }
        }
        let r = rotation_degrees.to_radians();
        Self {
            width,
            height,
            distribution: Distribution2D::new(&weights, width),
            texels,
            rotation: (r.cos(), r.sin()),
            mean: mean / total,
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// Radiance averaged over the sphere.
    pub fn mean(&self) -> Vec3 {
        self.mean
    }

    /// Whether the map delivers any light.
    pub fn is_black(&self) -> bool {
        self.distribution.integral() <= 0.0
    }

    /// World direction to map direction: undo the rotation about +Y.
    #[inline]
    fn to_map(&self, d: Vec3) -> Vec3 {
        let (c, s) = self.rotation;
        Vec3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z)
    }

    #[inline]
    fn to_world(&self, d: Vec3) -> Vec3 {
        let (c, s) = self.rotation;
        Vec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z)
    }

    /// `(u, v)` in `[0, 1)^2` and `sin(theta)` of a unit world direction.
    #[inline]
    fn uv(&self, dir: Vec3) -> (f32, f32, f32) {
        let d = self.to_map(dir);
        let mut u = d.x.atan2(-d.z) * (0.5 / PI);
        if u < 0.0 {
            u += 1.0;
        }
        let cos_theta = d.y.clamp(-1.0, 1.0);
        let v = cos_theta.acos() / PI;
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        (u, v, sin_theta)
    }

    #[inline]
    fn texel_of(&self, u: f32, v: f32) -> (usize, usize) {
        let col = ((u * self.width as f32) as usize).min(self.width - 1);
        let row = ((v * self.height as f32) as usize).min(self.height - 1);
        (col, row)
    }

    /// Radiance along a world direction and the solid-angle density with
    /// which [`sample`](Self::sample) picks it.
    #[inline]
    pub fn eval(&self, dir: Vec3) -> (Vec3, f32) {
        let (u, v, sin_theta) = self.uv(dir);
        let (col, row) = self.texel_of(u, v);
        let radiance = self.texels[row * self.width + col];
        let pdf = if sin_theta > 0.0 {
            self.distribution.pdf(col, row) / (2.0 * PI * PI * sin_theta)
        } else {
            0.0
        };
        (radiance, pdf)
    }

    /// Samples a world direction toward the sky: direction, its radiance
    /// and its solid-angle density (0 at the poles, where the sample is
    /// then worthless and the caller drops it).
    #[inline]
    pub fn sample(&self, u1: f32, u2: f32) -> (Vec3, Vec3, f32) {
        let ((u, v), pdf_uv, (col, row)) = self.distribution.sample(u1, u2);
        let (phi, theta) = (2.0 * PI * u, PI * v);
        let (sin_t, cos_t) = theta.sin_cos();
        let (sin_p, cos_p) = phi.sin_cos();
        let d = Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p);
        let pdf = if sin_t > 0.0 {
            pdf_uv / (2.0 * PI * PI * sin_t)
        } else {
            0.0
        };
        (
            self.to_world(d).normalize(),
            self.texels[row * self.width + col],
            pdf,
        )
    }

    /// Centre direction and solid angle of texel `(col, row)` (tests and
    /// tools: a one-texel map is a sun of irradiance `L * solid angle`).
    pub fn texel_direction(&self, col: usize, row: usize) -> (Vec3, f32) {
        let u = (col as f32 + 0.5) / self.width as f32;
        let v = (row as f32 + 0.5) / self.height as f32;
        let (phi, theta) = (2.0 * PI * u, PI * v);
        let d = Vec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        );
        let theta0 = PI * row as f32 / self.height as f32;
        let theta1 = PI * (row + 1) as f32 / self.height as f32;
        let omega = 2.0 * PI / self.width as f32 * (theta0.cos() - theta1.cos());
        (self.to_world(d), omega)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_round_trip_through_the_mapping() {
        let map = EnvMap::new(8, 4, vec![Vec3::ONE; 32], 30.0);
        for (col, row) in [(0, 0), (3, 1), (7, 3), (5, 2)] {
            let (d, _) = map.texel_direction(col, row);
            let (u, v, _) = map.uv(d);
            assert_eq!(map.texel_of(u, v), (col, row));
        }
        // Row 0 is up; column 0 looks along -Z (unrotated).
        let plain = EnvMap::new(8, 4, vec![Vec3::ONE; 32], 0.0);
        let (d, _) = plain.texel_direction(0, 1);
        assert!(d.y > 0.0 && d.z < 0.0, "{d}");
    }

    #[test]
    fn sampled_pdf_matches_eval() {
        let texels: Vec<Vec3> = (0..32).map(|i| Vec3::splat((i % 7) as f32)).collect();
        let map = EnvMap::new(8, 4, texels, 45.0);
        for k in 0..50 {
            let (u1, u2) = ((k as f32 * 0.137) % 1.0, (k as f32 * 0.291 + 0.05) % 1.0);
            let (d, l, pdf) = map.sample(u1, u2);
            let (l2, pdf2) = map.eval(d);
            assert!(l.max_element() > 0.0, "never samples a black texel");
            assert_eq!(l, l2);
            assert!((pdf - pdf2).abs() <= 1e-3 * pdf, "{pdf} vs {pdf2}");
        }
    }
}
