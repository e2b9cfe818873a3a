//! A convex combination of two lobes.

use super::Lobe;
use crate::error::{Error, Result};

/// Largest f32 below 1: a rescaled uniform number stays in `[0, 1)`.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// `w a(mu) + (1 - w) b(mu)`, normalised since both lobes are.
///
/// Sampling picks lobe `a` when `u < w` and reuses `u`, rescaled to
/// `[0, 1)` within the chosen interval, to invert that lobe's CDF, so a
/// sample still takes one number for `mu` (and `Phase::sample` two in
/// all). The sample's density is the mixture's, `w p_a + (1 - w) p_b`,
/// which is the function itself: sampling is exact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend<A, B> {
    a: A,
    b: B,
    w: f32,
}

impl<A: Lobe, B: Lobe> Blend<A, B> {
    /// Errors unless `w`, the weight of `a`, is in `[0, 1]` (NaN included).
    pub fn new(a: A, b: B, w: f32) -> Result<Self> {
        if !(0.0..=1.0).contains(&w) {
            return Err(Error::invalid(format!(
                "lobe weight must be in [0, 1], got {w}"
            )));
        }
        Ok(Self { a, b, w })
    }

    pub fn lobes(&self) -> (&A, &B) {
        (&self.a, &self.b)
    }

    /// The weight of the first lobe.
    pub fn weight(&self) -> f32 {
        self.w
    }
}

impl<A: Lobe, B: Lobe> Lobe for Blend<A, B> {
    #[inline]
    fn eval_cos(&self, mu: f32) -> f32 {
        self.w * self.a.eval_cos(mu) + (1.0 - self.w) * self.b.eval_cos(mu)
    }

    #[inline]
    fn sample_cos(&self, u: f32) -> f32 {
        // With w = 0 the first branch is never taken, with w = 1 always
        // (u < 1), so neither division is by zero.
        if u < self.w {
            self.a.sample_cos((u / self.w).min(ONE_MINUS_EPSILON))
        } else {
            let v = (u - self.w) / (1.0 - self.w);
            self.b.sample_cos(v.min(ONE_MINUS_EPSILON))
        }
    }

    fn mean_cosine(&self) -> f32 {
        self.w * self.a.mean_cosine() + (1.0 - self.w) * self.b.mean_cosine()
    }
}
