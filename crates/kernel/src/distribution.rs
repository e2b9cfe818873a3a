//! Piecewise-constant distributions in one and two dimensions, sampled by
//! inverting their CDFs (pbrt-v4's `PiecewiseConstant1D` / `2D`, Pharr,
//! Jakob, Humphreys, "Physically Based Rendering", 4th ed., section A.4.2
//! and A.5): what the environment map is importance-sampled with.

/// A density on `[0, 1)` constant on `n` equal cells, proportional to the
/// given non-negative weights.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f32>,
    /// `n + 1` entries from 0 to 1.
    cdf: Vec<f64>,
    /// Mean of `func` (its integral over `[0, 1)`).
    integral: f64,
}

impl Distribution1D {
    /// Weights must be finite; negative ones are taken as 0. All zero gives
    /// the uniform distribution (so sampling stays defined) but
    /// [`integral`](Self::integral) reports 0.
    pub fn new(weights: &[f32]) -> Self {
        let n = weights.len().max(1);
        let func: Vec<f32> = weights
            .iter()
            .map(|&w| if w.is_finite() { w.max(0.0) } else { 0.0 })
            .collect();
        let mut cdf = Vec::with_capacity(n + 1);
        cdf.push(0.0);
        let mut sum = 0f64;
        for &f in &func {
            sum += f as f64;
            cdf.push(sum);
        }
        let integral = sum / n as f64;
        if sum > 0.0 {
            cdf.iter_mut().for_each(|c| *c /= sum);
        } else {
            cdf = (0..=n).map(|i| i as f64 / n as f64).collect();
        }
        *cdf.last_mut().expect("n + 1 >= 1 entries") = 1.0;
        Self {
            func,
            cdf,
            integral,
        }
    }

    /// Mean of the weights.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// Samples `x` in `[0, 1)` for `u` in `[0, 1)`: returns `x`, its density
    /// and its cell. A cell of weight 0 is never returned while others
    /// have weight.
    #[inline]
    pub fn sample(&self, u: f32) -> (f32, f32, usize) {
        let u = u as f64;
        let n = self.func.len();
        // Last cell whose CDF start is <= u (zero-width cells are skipped).
        let i = (self.cdf.partition_point(|&c| c <= u) - 1).min(n - 1);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 {
            ((u - self.cdf[i]) / width).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let x = ((i as f64 + du) / n as f64).min(1.0 - f64::EPSILON) as f32;
        (x, self.pdf(i), i)
    }

    /// Density of cell `i` (with respect to `x` on `[0, 1)`).
    #[inline]
    pub fn pdf(&self, i: usize) -> f32 {
        if self.integral > 0.0 {
            (self.func[i] as f64 / self.integral) as f32
        } else {
            1.0
        }
    }
}

/// A density on `[0, 1)^2` constant on a `width x height` grid of cells:
/// a marginal over rows and a conditional per row.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `weights` is row-major, `width` per row.
    pub fn new(weights: &[f32], width: usize) -> Self {
        assert!(
            width > 0 && weights.len().is_multiple_of(width),
            "weights per row"
        );
        let rows: Vec<Distribution1D> = weights.chunks(width).map(Distribution1D::new).collect();
        let marginal =
            Distribution1D::new(&rows.iter().map(|r| r.integral() as f32).collect::<Vec<_>>());
        Self { rows, marginal }
    }

    /// Mean weight over the grid.
    pub fn integral(&self) -> f64 {
        self.marginal.integral()
    }

    /// Samples `(x, y)`: returns them, their joint density and the cell
    /// `(column, row)`.
    #[inline]
    pub fn sample(&self, u1: f32, u2: f32) -> ((f32, f32), f32, (usize, usize)) {
        let (y, pdf_y, row) = self.marginal.sample(u2);
        let (x, pdf_x, col) = self.rows[row].sample(u1);
        ((x, y), pdf_x * pdf_y, (col, row))
    }

    /// Joint density of cell `(column, row)`.
    #[inline]
    pub fn pdf(&self, col: usize, row: usize) -> f32 {
        let integral = self.marginal.integral();
        if integral > 0.0 {
            (self.rows[row].func[col] as f64 / integral) as f32
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_dimensional_sampling_follows_the_weights() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0, 0.0]);
        assert_eq!(d.integral(), 1.0);
        // u below 1/4 lands in cell 0, above in cell 2; never in the zero cells.
        let (x, pdf, i) = d.sample(0.1);
        assert_eq!(i, 0);
        assert!((x - 0.1).abs() < 1e-6 && (pdf - 1.0).abs() < 1e-6);
        let (x, pdf, i) = d.sample(0.625);
        assert_eq!(i, 2);
        assert!((x - 0.625).abs() < 1e-6 && (pdf - 3.0).abs() < 1e-6);
        let (_, _, i) = d.sample(0.25);
        assert_eq!(i, 2, "u on a zero-width cell goes to the next with weight");
    }

    #[test]
    fn two_dimensional_pdf_integrates_to_one() {
        let w: Vec<f32> = (0..12).map(|i| (i % 5) as f32).collect();
        let d = Distribution2D::new(&w, 4);
        let sum: f32 = (0..3)
            .flat_map(|r| (0..4).map(move |c| (c, r)))
            .map(|(c, r)| d.pdf(c, r) / 12.0)
            .sum();
        assert!((sum - 1.0).abs() < 1e-5, "{sum}");
        let ((x, y), pdf, (c, r)) = d.sample(0.3, 0.7);
        assert!((pdf - d.pdf(c, r)).abs() <= 1e-6 * pdf, "{pdf}");
        assert_eq!(((x * 4.0) as usize, (y * 3.0) as usize), (c, r));
    }
}
