//! Rayleigh scattering.

use super::draine::symmetric_cubic;
use super::Lobe;

/// Rayleigh scattering by particles much smaller than the wavelength
/// (unpolarised light): `p(mu) = 3 / (16 pi) (1 + mu^2)`, mean cosine 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rayleigh;

impl Lobe for Rayleigh {
    #[inline]
    fn eval_cos(&self, mu: f32) -> f32 {
        let mu = mu.clamp(-1.0, 1.0);
        3.0 / (16.0 * std::f32::consts::PI) * (1.0 + mu * mu)
    }

    /// Exact: the CDF `(mu^3 + 3 mu + 4) / 8` inverted in closed form,
    /// `mu = 2 sinh(asinh(4 u - 2) / 3)` (Cardano's formula for the cubic;
    /// it is Draine's `g = 0` case at `alpha = 1`, computed there).
    #[inline]
    fn sample_cos(&self, u: f32) -> f32 {
        (symmetric_cubic(1.0, f64::from(u)) as f32).clamp(-1.0, 1.0)
    }

    fn mean_cosine(&self) -> f32 {
        0.0
    }
}
