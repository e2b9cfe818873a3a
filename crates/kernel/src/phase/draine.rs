//! The Draine phase function and its exact inverse CDF.

use super::hg::HenyeyGreenstein;
use super::Lobe;
use crate::error::{Error, Result};

/// An `alpha` below this is taken as 0 (pure HG), in `eval` and `sample`
/// alike: it changes the function by less than 1e-6 relative, and the
/// quartic below loses digits as `alpha -> 0` (its `1 / alpha` terms grow).
const MIN_ALPHA: f32 = 1e-6;

/// Draine (2003, "Scattering by interstellar dust grains. I. Optical and
/// ultraviolet", ApJ 598, 1017):
/// `p(mu) = HG_g(mu) (1 + alpha mu^2) / (1 + alpha (1 + 2 g^2) / 3)`.
/// The denominator is `E_HG[1 + alpha mu^2]` (the HG second moment is
/// `(1 + 2 g^2) / 3`), so `p` is normalised. `alpha = 0` is HG,
/// `g = 0, alpha = 1` Rayleigh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Draine {
    /// HG with the same `g` (clamped and snapped to 0 as HG's is).
    hg: HenyeyGreenstein,
    alpha: f32,
    /// `1 / (1 + alpha (1 + 2 g^2) / 3)`.
    norm: f32,
}

impl Draine {
    /// `g` is clamped like [`HenyeyGreenstein::new`]'s. Errors: a
    /// non-finite `g`, a negative or non-finite `alpha`.
    pub fn new(g: f32, alpha: f32) -> Result<Self> {
        if !g.is_finite() {
            return Err(Error::invalid(format!("Draine g must be finite, got {g}")));
        }
        if !(alpha.is_finite() && alpha >= 0.0) {
            return Err(Error::invalid(format!(
                "Draine alpha must be finite and >= 0, got {alpha}"
            )));
        }
        let hg = HenyeyGreenstein::new(g);
        let alpha = if alpha < MIN_ALPHA { 0.0 } else { alpha };
        let g = f64::from(hg.g());
        let norm = (1.0 / (1.0 + f64::from(alpha) * (1.0 + 2.0 * g * g) / 3.0)) as f32;
        Ok(Self { hg, alpha, norm })
    }

    pub fn g(&self) -> f32 {
        self.hg.g()
    }

    pub fn alpha(&self) -> f32 {
        self.alpha
    }
}

impl Lobe for Draine {
    #[inline]
    fn eval_cos(&self, mu: f32) -> f32 {
        let mu = mu.clamp(-1.0, 1.0);
        self.hg.eval_cos(mu) * (1.0 + self.alpha * mu * mu) * self.norm
    }

    /// Exact inversion of the CDF (the function's own density, no
    /// weights), in f64: for `g != 0` the unique positive root of a
    /// quartic (`quartic_root`), for `g = 0` a cubic (`symmetric_cubic`).
    /// Jendersie and d'Eon (2023, supplemental) publish a closed form of
    /// their own (Blender Cycles' `phase_draine_sample_cos` adapts it, in
    /// f32); this one is derived below, in an arrangement without
    /// cancellation, and tested against the CDF at extreme parameters.
    fn sample_cos(&self, u: f32) -> f32 {
        let g = self.hg.g();
        if self.alpha == 0.0 {
            return self.hg.sample_cos(u);
        }
        let alpha = f64::from(self.alpha);
        let u = f64::from(u);
        let mu = if g == 0.0 {
            symmetric_cubic(alpha, u)
        } else if g > 0.0 {
            // mu decreases as s grows: P(S <= s) = P(M >= mu) = 1 - u.
            quartic_root(f64::from(g), alpha, 1.0 - u)
        } else {
            // p_{-g}(mu) = p_g(-mu): the mirror image, with P(M <= mu) =
            // P(M' >= -mu) = u for M' drawn with |g|.
            -quartic_root(-f64::from(g), alpha, u)
        };
        (mu as f32).clamp(-1.0, 1.0)
    }

    /// `<mu> = (E[mu] + alpha E[mu^3]) / (1 + alpha E[mu^2])` under HG,
    /// whose Legendre moments are `g^l`, so `E[mu^2] = (1 + 2 g^2) / 3` and
    /// `E[mu^3] = g (3 + 2 g^2) / 5` (`mu^3 = (2 P_3 + 3 P_1) / 5`).
    fn mean_cosine(&self) -> f32 {
        let g = self.hg.g();
        g * (1.0 + self.alpha * (3.0 + 2.0 * g * g) / 5.0) * self.norm
    }
}

/// The `mu` with `P(M >= mu) = v` for Draine with `g > 0`, `alpha > 0`.
///
/// Substituting `s = sqrt(1 + g^2 - 2 g mu)` (from `1 - g` at `mu = 1` to
/// `1 + g` at `mu = -1`; HG is uniform in `1 / s`), `mu = (a - s^2) / (2 g)`
/// with `a = 1 + g^2`, and the density of `s` is
/// `p_S(s) = K ((1 + b a^2) / s^2 - 2 a b + b s^2)` with
/// `K = (1 - g^2) / (2 g N)`, `b = alpha / (4 g^2)`, `N` the Draine
/// normaliser. Its antiderivative is
/// `H(s) = K (-(1 + b a^2) / s - 2 a b s + b s^3 / 3)`, and
/// `P(S <= s) = P(M >= mu) = H(s) - H(1 - g)`. Setting that to `v` and
/// multiplying by `3 s / (K b)` gives the depressed quartic
/// `s^4 + P s^2 + Q s + R = 0`, `P = -6 a`,
/// `Q = -3 (H(1 - g) + v) / (K b)`, `R = -3 (1 / b + a^2)`.
/// `p_S > 0` for every `s > 0`, so `H` increases there, and `H < 0` on
/// `(0, 2]`, so `Q > 0`: the quartic has one positive root (the one
/// wanted), one negative, and a complex pair (Descartes' rule of signs).
///
/// Ferrari: for a root `m > 0` of the resolvent cubic
/// `m^3 + P m^2 + (P^2 / 4 - R) m - Q^2 / 8 = 0` the quartic is
/// `(s^2 + P/2 + m)^2 - 2 m (s - Q / (4 m))^2`, the product of
/// `s^2 - r s + P/2 + m + Q / (2 r)` and `s^2 + r s + P/2 + m - Q / (2 r)`
/// with `r = sqrt(2 m)`. With two real roots the quartic's discriminant is
/// negative, so the resolvent has one real root (Cardano), and it is
/// positive since the cubic is `-Q^2 / 8 < 0` at 0. The real pair is the
/// second factor's (its constant term is negative: one root of each
/// sign), whose positive root is taken in the cancellation-free form
/// `-2 c / (r + sqrt(r^2 - 4 c))`. Worst CDF error over `g` in
/// `[1e-3, 0.9999]`, `alpha` in `[1e-6, 1e8]`: about 4e-7 (at `g = 1e-3`),
/// 1e-12 for typical parameters.
fn quartic_root(g: f64, alpha: f64, v: f64) -> f64 {
    let a = 1.0 + g * g;
    let n = 1.0 + alpha * (1.0 + 2.0 * g * g) / 3.0;
    let inv_b = 4.0 * g * g / alpha;
    let lo = 1.0 - g;
    // H(1 - g) / (K b) and 1 / (K b).
    let h_lo = -(inv_b + a * a) / lo - 2.0 * a * lo + lo * lo * lo / 3.0;
    let inv_kb = 8.0 * g * g * g * n / ((1.0 - g * g) * alpha);
    let p4 = -6.0 * a;
    let q4 = -3.0 * (h_lo + v * inv_kb);
    let r4 = -3.0 * (inv_b + a * a);
    // Resolvent cubic, depressed by m = y - P/3: y^3 + p y + q = 0.
    let p = -p4 * p4 / 12.0 - r4;
    let q = -p4 * p4 * p4 / 108.0 + p4 * r4 / 3.0 - q4 * q4 / 8.0;
    let disc = (0.25 * q * q + p * p * p / 27.0).max(0.0);
    // Cardano with the larger-magnitude cube root first (no cancellation).
    let big = (-0.5 * q - disc.sqrt().copysign(q)).cbrt();
    let y = if big == 0.0 {
        0.0
    } else {
        big - p / (3.0 * big)
    };
    let m = (y - p4 / 3.0).max(f64::MIN_POSITIVE);
    let r = (2.0 * m).sqrt();
    let c = 0.5 * p4 + m - q4 / (2.0 * r);
    let s = -2.0 * c / (r + (r * r - 4.0 * c).max(0.0).sqrt());
    let s = s.clamp(lo, 1.0 + g);
    (a - s * s) / (2.0 * g)
}

/// The `mu` with `P(M <= mu) = u` for `p(mu) ~ 1 + alpha mu^2` (Draine
/// with `g = 0`; Rayleigh at `alpha = 1`). The CDF is
/// `(mu + alpha mu^3 / 3 + 1 + alpha / 3) / (2 (1 + alpha / 3))`, so `mu`
/// solves `mu^3 + (3 / alpha) mu = 3 c / alpha`, `c = (2 u - 1)(1 + alpha / 3)`:
/// a depressed cubic with positive linear coefficient, so one real root,
/// which Cardano's formula gives as
/// `(2 / sqrt(alpha)) sinh(asinh(w) / 3)`, `w = 1.5 c sqrt(alpha)`. With
/// `A = cbrt(|w| + sqrt(w^2 + 1)) = exp(asinh(|w|) / 3)` that is
/// `sign(w) (A - 1 / A) / sqrt(alpha)`: a cube root instead of two
/// transcendental calls, and no cancellation in `A` (the odd symmetry
/// handles `w < 0`). It tends to `mu = c` as `alpha -> 0`.
pub(super) fn symmetric_cubic(alpha: f64, u: f64) -> f64 {
    let c = (2.0 * u - 1.0) * (1.0 + alpha / 3.0);
    let sa = alpha.sqrt();
    let w = 1.5 * c * sa;
    let a = (w.abs() + (w * w + 1.0).sqrt()).cbrt();
    ((a - 1.0 / a) / sa).copysign(w)
}
