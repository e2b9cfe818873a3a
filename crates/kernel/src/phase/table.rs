//! A phase function given as a table of `(cos(theta), value)` points.

use std::f64::consts::PI;

use super::Lobe;
use crate::error::Error;

/// The most rows a table may have (checked before anything is allocated
/// for it): 1e6 rows resolve the forward peak of any droplet size to well
/// under 1e-5 in `mu`.
pub const MAX_TABLE_ROWS: usize = 1_000_000;

/// How far the first and last `cos(theta)` may lie from -1 and 1 (printed
/// tables round); they are then moved to -1 and 1 exactly.
const END_TOLERANCE: f32 = 1e-4;

/// A piecewise-linear function of `mu` through the table's points,
/// normalised on construction so that it integrates to 1 over the sphere.
///
/// Sampling inverts the piecewise-quadratic CDF exactly: a binary search
/// for the segment, then the root of that segment's quadratic. The sample
/// density is the function itself (`pdf == eval`).
#[derive(Debug, PartialEq)]
pub struct TabulatedPhase {
    /// Strictly increasing, from -1 to 1.
    mu: Box<[f32]>,
    /// Density per steradian at each `mu`.
    value: Box<[f32]>,
    /// `P(M <= mu[i])`, 0 to 1, accumulated from `value` in f64.
    cdf: Box<[f64]>,
    /// Density of `mu` in the cdf's units per unit `value`: `2 pi / sum`,
    /// `sum` (1 up to rounding) being the integral before `cdf` was scaled.
    mu_density: f64,
    mean_cosine: f32,
}

/// A rejected table: the offending row (0-based, in the order given) if
/// there is one, and what is wrong.
pub(super) struct TableError {
    pub row: Option<usize>,
    pub message: String,
}

impl TabulatedPhase {
    /// The table of `values` at `cos_values`.
    ///
    /// - `cos_values` strictly increasing or strictly decreasing (a table
    ///   by increasing angle is decreasing in cosine), from -1 to 1 (each
    ///   end within 1e-4, then snapped);
    /// - values finite and `>= 0`, not all 0; any positive scale (they are
    ///   normalised);
    /// - 2 to [`MAX_TABLE_ROWS`] rows, as many values as cosines.
    pub fn new(cos_values: &[f32], values: &[f32]) -> crate::error::Result<Self> {
        Self::build(cos_values, values).map_err(|e| {
            Error::invalid(match e.row {
                Some(row) => format!("phase table row {row}: {}", e.message),
                None => format!("phase table: {}", e.message),
            })
        })
    }

    fn build(cos_values: &[f32], values: &[f32]) -> Result<Self, TableError> {
        validate(cos_values, values)?;
        let (mut mu, mut value) = (cos_values.to_vec(), values.to_vec());
        if mu[0] > mu[mu.len() - 1] {
            mu.reverse();
            value.reverse();
        }
        let last = mu.len() - 1;
        mu[0] = -1.0;
        mu[last] = 1.0;

        // Trapezoids are exact for a piecewise-linear function; the sphere
        // contributes 2 pi per unit of mu.
        let segment = |value: &[f32], i: usize| {
            let h = f64::from(mu[i + 1]) - f64::from(mu[i]);
            PI * h * (f64::from(value[i]) + f64::from(value[i + 1]))
        };
        let total: f64 = (0..last).map(|i| segment(&value, i)).sum();
        if !(total > 0.0 && total.is_finite()) {
            return Err(TableError {
                row: None,
                message: format!("the values must have a positive, finite integral (got {total})"),
            });
        }
        for v in &mut value {
            *v = (f64::from(*v) / total) as f32;
        }
        // Accumulate from the stored (rounded) values, so sampling follows
        // exactly the function that `eval_cos` interpolates.
        let mut cdf = vec![0.0f64; mu.len()];
        for i in 0..last {
            cdf[i + 1] = cdf[i] + segment(&value, i);
        }
        let sum = cdf[last];
        cdf.iter_mut().for_each(|c| *c /= sum);
        cdf[last] = 1.0;
        // Integral of mu v(mu) over a segment, exact for linear v (Simpson).
        let first_moment: f64 = (0..last)
            .map(|i| {
                let (m0, m1) = (f64::from(mu[i]), f64::from(mu[i + 1]));
                let (v0, v1) = (f64::from(value[i]), f64::from(value[i + 1]));
                (m1 - m0) / 6.0 * (v0 * (2.0 * m0 + m1) + v1 * (m0 + 2.0 * m1))
            })
            .sum();
        Ok(Self {
            mu: mu.into(),
            value: value.into(),
            cdf: cdf.into(),
            mu_density: 2.0 * PI / sum,
            mean_cosine: (2.0 * PI * first_moment / sum) as f32,
        })
    }

    /// The table as it is evaluated and sampled: the cosines (increasing,
    /// from -1 to 1), the normalised values at them, the sampling CDF at
    /// them and the density's scale over cosines (`2 pi / total`), for a
    /// device that mirrors `eval_cos` and `sample_cos` (crates/gpu).
    pub fn rows(&self) -> (&[f32], &[f32], &[f64], f64) {
        (&self.mu, &self.value, &self.cdf, self.mu_density)
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.mu.len()
    }

    pub fn is_empty(&self) -> bool {
        self.mu.is_empty()
    }

    /// The segment `[mu[i], mu[i + 1]]` holding `mu` (clamped to [-1, 1]).
    #[inline]
    fn segment_of(&self, mu: f32) -> usize {
        self.mu
            .partition_point(|&m| m <= mu)
            .saturating_sub(1)
            .min(self.mu.len() - 2)
    }
}

/// The checks on a table, with the row they fail at.
pub(super) fn validate(cos_values: &[f32], values: &[f32]) -> Result<(), TableError> {
    let whole = |message: String| TableError { row: None, message };
    let at = |row: usize, message: String| TableError {
        row: Some(row),
        message,
    };
    let n = cos_values.len();
    if values.len() != n {
        return Err(whole(format!("{n} cosines but {} values", values.len())));
    }
    if !(2..=MAX_TABLE_ROWS).contains(&n) {
        return Err(whole(format!("needs 2 to {MAX_TABLE_ROWS} rows, got {n}")));
    }
    for (i, (&c, &v)) in cos_values.iter().zip(values).enumerate() {
        if c.is_nan() || c.abs() > 1.0 + END_TOLERANCE {
            return Err(at(i, format!("cos(theta) must be in [-1, 1], got {c}")));
        }
        if !(v.is_finite() && v >= 0.0) {
            return Err(at(i, format!("value must be finite and >= 0, got {v}")));
        }
    }
    let increasing = cos_values[1] > cos_values[0];
    for i in 1..n {
        let (a, b) = (cos_values[i - 1], cos_values[i]);
        if (increasing && b <= a) || (!increasing && b >= a) {
            let order = if increasing {
                "increasing"
            } else {
                "decreasing"
            };
            return Err(at(
                i,
                format!("cos(theta) {b} after {a}: must be strictly {order}"),
            ));
        }
    }
    let (lo, hi) = if increasing {
        (cos_values[0], cos_values[n - 1])
    } else {
        (cos_values[n - 1], cos_values[0])
    };
    if (lo + 1.0).abs() > END_TOLERANCE || (hi - 1.0).abs() > END_TOLERANCE {
        return Err(whole(format!(
            "cos(theta) must run from -1 to 1 (the whole sphere), got {lo} to {hi}"
        )));
    }
    Ok(())
}

impl Lobe for TabulatedPhase {
    #[inline]
    fn eval_cos(&self, mu: f32) -> f32 {
        let mu = mu.clamp(-1.0, 1.0);
        let i = self.segment_of(mu);
        let (m0, m1) = (self.mu[i], self.mu[i + 1]);
        let t = ((mu - m0) / (m1 - m0)).clamp(0.0, 1.0);
        self.value[i] + t * (self.value[i + 1] - self.value[i])
    }

    /// In segment `i` the density of `mu` is linear, `q0 + (q1 - q0) x / h`
    /// at `x = mu - mu[i]` (`q = 2 pi value`), so the mass `r` still to go
    /// is reached where `(q1 - q0) x^2 / (2 h) + q0 x = r`; the root is
    /// taken as `2 r / (q0 + sqrt(q0^2 + 2 (q1 - q0) r / h))`, which has no
    /// cancellation and no division by a vanishing slope. The square root's
    /// argument is at least `q1^2` for `r` up to the segment's mass.
    fn sample_cos(&self, u: f32) -> f32 {
        let target = f64::from(u);
        // The last row whose cdf is <= target: a zero-mass segment (cdf
        // equal at both ends) is never chosen.
        let i = self
            .cdf
            .partition_point(|&c| c <= target)
            .saturating_sub(1)
            .min(self.cdf.len() - 2);
        let (m0, m1) = (f64::from(self.mu[i]), f64::from(self.mu[i + 1]));
        let h = m1 - m0;
        let q0 = self.mu_density * f64::from(self.value[i]);
        let q1 = self.mu_density * f64::from(self.value[i + 1]);
        let r = (target - self.cdf[i]).max(0.0);
        let denom = q0 + (q0 * q0 + 2.0 * (q1 - q0) * r / h).max(0.0).sqrt();
        let x = if denom > 0.0 { 2.0 * r / denom } else { 0.0 };
        ((m0 + x).clamp(m0, m1)) as f32
    }

    fn mean_cosine(&self) -> f32 {
        self.mean_cosine
    }
}
