//! The Henyey-Greenstein lobe: the default phase function and a building
//! block of the two-lobe and approximate-Mie blends.

use std::f32::consts::PI;

use super::Lobe;

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

    /// Inverts the HG CDF in `mu` (e.g. pbrt-v4 `SampleHenyeyGreenstein`,
    /// written for this module's sign convention).
    #[inline]
    pub fn sample_cos(&self, u: f32) -> f32 {
        let g = self.g;
        if g == 0.0 {
            return 1.0 - 2.0 * u;
        }
        let s = (1.0 - g) * (1.0 + g) / (1.0 - g + 2.0 * g * u);
        ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
    }
}

impl Lobe for HenyeyGreenstein {
    #[inline]
    fn eval_cos(&self, mu: f32) -> f32 {
        HenyeyGreenstein::eval_cos(self, mu)
    }

    #[inline]
    fn sample_cos(&self, u: f32) -> f32 {
        HenyeyGreenstein::sample_cos(self, u)
    }

    fn mean_cosine(&self) -> f32 {
        self.g
    }
}
