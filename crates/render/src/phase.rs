//! The Henyey-Greenstein phase function.
//!
//! Convention: both directions are *propagation* directions along the path
//! from the camera, so `mu = dot(dir_in, dir_out)` is the cosine of the
//! scattering angle and `g > 0` scatters forward (`dir_out` near `dir_in`).
//! For next-event estimation `dir_out` is the direction toward the light,
//! which by reciprocity gives the same `mu` as the light's own path.

use std::f32::consts::PI;

use glam::Vec3;

use crate::sampling::from_local;

/// Below this |g| the function is taken as isotropic: the inversion formula
/// divides by g and cancels badly (pbrt-v4 uses the same cut-off). `new`
/// snaps such g to 0 so that `eval` and `sample` stay consistent.
const ISOTROPIC_G: f32 = 1e-3;

/// |g| is clamped to this: at |g| = 1 the function is a delta and its
/// density is unbounded; 0.9999 keeps the peak finite in f32.
pub const MAX_ABS_G: f32 = 0.9999;

/// Henyey and Greenstein (1941): `p(mu) = (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^(3/2))`,
/// normalised over the sphere, mean cosine `g`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HenyeyGreenstein {
    g: f32,
}

impl HenyeyGreenstein {
    /// `g` is clamped to `[-MAX_ABS_G, MAX_ABS_G]`; |g| below 1e-3 and NaN
    /// become 0.
    pub fn new(g: f32) -> Self {
        let g = if g.is_nan() || g.abs() < ISOTROPIC_G {
            0.0
        } else {
            g.clamp(-MAX_ABS_G, MAX_ABS_G)
        };
        Self { g }
    }

    pub fn g(&self) -> f32 {
        self.g
    }

    /// Density per steradian for scattering-angle cosine `mu`.
    #[inline]
    pub fn eval_cos(&self, mu: f32) -> f32 {
        let g = self.g;
        let mu = mu.clamp(-1.0, 1.0);
        // 1 + g^2 - 2 g mu as a sum of two non-negative terms, so there is no
        // cancellation at the peak when |g| -> 1: (1 - g)^2 + 2 g (1 - mu)
        // for g >= 0, (1 + g)^2 - 2 g (1 + mu) for g < 0.
        let denom = if g >= 0.0 {
            (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - mu)
        } else {
            (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + mu)
        };
        (1.0 - g) * (1.0 + g) / (4.0 * PI * denom * denom.sqrt())
    }

    /// Density of scattering from propagation direction `dir_in` into
    /// `dir_out` (both unit vectors).
    #[inline]
    pub fn eval(&self, dir_in: Vec3, dir_out: Vec3) -> f32 {
        self.eval_cos(dir_in.dot(dir_out))
    }

    /// Inverts the HG CDF in `mu` (e.g. pbrt-v4 `SampleHenyeyGreenstein`,
    /// written for this file's sign convention).
    #[inline]
    pub fn sample_cos(&self, u: f32) -> f32 {
        let g = self.g;
        if g == 0.0 {
            return 1.0 - 2.0 * u;
        }
        let s = (1.0 - g) * (1.0 + g) / (1.0 - g + 2.0 * g * u);
        ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
    }

    /// Samples an outgoing propagation direction; returns it and its pdf,
    /// which equals the phase value (sampling is exact, so the path weight
    /// `p / pdf` is 1).
    #[inline]
    pub fn sample(&self, dir_in: Vec3, u1: f32, u2: f32) -> (Vec3, f32) {
        let mu = self.sample_cos(u1);
        let sin = (1.0 - mu * mu).max(0.0).sqrt();
        let phi = 2.0 * PI * u2;
        let dir = from_local(dir_in, sin * phi.cos(), sin * phi.sin(), mu);
        (dir, self.eval_cos(mu))
    }
}
