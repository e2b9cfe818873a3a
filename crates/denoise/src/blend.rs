//! A blend of the noisy image and its denoised self that is never much worse
//! than either: per pixel, each estimate is weighted by its error, and the
//! denoiser's error is measured on data it did not see.
//!
//! A denoiser's output `D = f(N)` of the noisy image `N` (mean of `n`
//! samples, variance `v` per pixel, known from the samples) has an error
//! of its own: a bias `b` (detail blurred away, tone shifted where the
//! network guesses) and residual noise. At low sample counts the noise
//! removed dwarfs the bias; at high ones the bias is all that is left and
//! `D` is worse than `N`. Both errors are estimated per region from the two
//! independent halves `A`, `B` of the samples (even and odd; dual-buffer
//! estimation as in Rousselle, Knaus and Zwicker 2012, "Adaptive rendering
//! with non-local means filtering"), with `D_A = f(A)`, `D_B = f(B)`:
//!
//! - residual noise of a denoised half: `R_h = E[(D_A - D_B)^2] / 2`
//!   (the halves' biases are alike and cancel, their noises are
//!   independent);
//! - its covariance with the input noise:
//!   `C_h = E[(A - B)(D_A - D_B)] / 2`;
//! - its whole error, by cross-validation against the other half, whose
//!   variance `v_B` is known and whose noise is independent of `D_A`:
//!   `MSE(D_A) = E[(D_A - B)^2] - v_B`, hence the squared bias
//!   `b^2 = MSE(D_A) - R_h`.
//!
//! For the full image, with twice the samples of a half, the noise terms
//! halve (a denoiser acts locally like a linear filter `F` of its input:
//! `Var(F e) = sum_j F_ij^2 v_j`, `Cov(e, F e) = F_ii v`). The bias
//! shrinks too, since with less noise a denoiser blurs less; a smoother
//! whose bandwidth is tuned to the noise in two dimensions has
//! `b^2 ~ n^(-2/3)` (bandwidth `h ~ n^(-1/6)`, `b^2 ~ h^4`), so the full
//! image's is taken as `BIAS_SCALE = 2^(-2/3)` times the half's:
//! `MSE(D) = BIAS_SCALE b^2 + R_h / 2`, `C = C_h / 2`. The blend
//! `w N + (1 - w) D` has the error
//! `w^2 v + (1 - w)^2 MSE(D) + 2 w (1 - w) C`, least at
//! `w = (MSE(D) - C) / (v + MSE(D) - 2 C)`, clamped to `[0, 1]`. The
//! squared bias is counted only beyond [`BIAS_EVIDENCE`] standard errors
//! of its cross-validated estimate: clamped at 0, a noisy estimate is
//! biased upward and would move weight to the noisy image where the
//! denoised one is better.
//!
//! Each term is summed over a square window around the pixel and over the
//! three channels before the weight is formed: one pixel's terms are too
//! noisy alone, and one weight for all channels keeps colour unshifted.

/// One RGB image, row-major.
pub type Rgb = [[f32; 3]];

/// What the weights are estimated from, all of `width x height` pixels.
#[derive(Clone, Copy, Debug)]
pub struct BlendInputs<'a> {
    pub width: usize,
    pub height: usize,
    /// Per-sample variance of each pixel's samples (the unbiased sample
    /// variance; the variance of the pixel's mean is this over the count).
    pub variance: &'a Rgb,
    /// Samples of each pixel in each half: `[even, odd]`.
    pub half_samples: &'a [[u32; 2]],
    /// The halves' means, `A` and `B`.
    pub halves: [&'a Rgb; 2],
    /// The denoiser's output of each half, `D_A` and `D_B`.
    pub denoised_halves: [&'a Rgb; 2],
}

/// Half-width of the window the error terms are summed over: 17 x 17
/// pixels, so a weight rests on ~870 terms (the relative noise of a sum of
/// squares of that many is about 5%) while a region still follows the
/// image's structure at the scale a denoiser blurs.
pub const DEFAULT_RADIUS: usize = 8;

/// The full image's squared bias over a half's: the rate `n^(-2/3)` of a
/// noise-tuned smoother in two dimensions, at twice the samples. Measured
/// on three scenes at four sample counts (BENCHMARKS.md), 1 (the half's
/// own bias, an upper bound) left the blend up to 7% above the plain
/// denoised image at low sample counts on the thick and default clouds
/// (better only on a 64x64 image at 512-2048 spp); 1/2 was within 2% of
/// this at every point.
pub const BIAS_SCALE: f64 = 0.629_960_524_947_436_6;

/// Standard errors of the cross-validated bias estimate (the halves' noise
/// in it) discounted from it. A trade measured on the sweeps of
/// BENCHMARKS.md (thick, default and sky-lit clouds at 128x128, 16-2048
/// spp; the default cloud at 64x64): 0 left the blend 1-2% above the plain
/// denoised image at 16-256 spp on the thick cloud; 2 brought that to
/// 0.97-0.99 but left the blend 11-30% above the noisy image at 512-2048
/// spp on the 64x64 cloud, where the denoiser's bias sits in few pixels of
/// a window; 1/2 gave 0.99-1.00 and 0.97-1.11 there.
pub const BIAS_EVIDENCE: f64 = 0.5;

/// The error terms of one pixel, summed over its channels.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Terms {
    /// Variance of the full image's mean.
    noisy: f64,
    /// Residual noise of a denoised half (`R_h`).
    residual: f64,
    /// Its covariance with the half's own noise (`C_h`).
    covariance: f64,
    /// A denoised half's whole error (`MSE(D_A)`), cross-validated.
    denoised: f64,
    /// The variance the halves' noise gives `denoised` (summed over a
    /// window: the squared standard error of the window's estimate).
    denoised_noise: f64,
    /// 1 where the pixel's samples allow the terms (both halves hold
    /// samples), else 0 and the other terms 0.
    valid: f64,
}

impl Terms {
    const COUNT: usize = 6;

    fn of_pixel(inp: &BlendInputs, i: usize) -> Self {
        let [na, nb] = inp.half_samples[i];
        if na == 0 || nb == 0 {
            return Self::default();
        }
        let (na, nb) = (f64::from(na), f64::from(nb));
        let n = na + nb;
        let [a, b] = inp.halves.map(|h| h[i]);
        let [da, db] = inp.denoised_halves.map(|h| h[i]);
        let mut t = Self {
            valid: 1.0,
            ..Self::default()
        };
        for c in 0..3 {
            let s2 = f64::from(inp.variance[i][c]);
            let (a, b, da, db) = (a[c] as f64, b[c] as f64, da[c] as f64, db[c] as f64);
            t.noisy += s2 / n;
            t.residual += 0.5 * (da - db).powi(2);
            t.covariance += 0.5 * (a - b) * (da - db);
            let (va, vb) = (s2 / na, s2 / nb);
            let (ta, tb) = ((da - b).powi(2) - vb, (db - a).powi(2) - va);
            t.denoised += 0.5 * (ta + tb);
            // (d - e)^2 - v for a denoised error d and a half's noise e of
            // variance v varies by 2 v^2 + 4 v d^2 (e taken as normal); d^2
            // is estimated by the term itself, clamped at 0.
            let noise = |v: f64, d2: f64| 2.0 * v * v + 4.0 * v * d2.max(0.0);
            t.denoised_noise += 0.25 * (noise(vb, ta) + noise(va, tb));
        }
        t
    }

    fn to_array(self) -> [f64; Self::COUNT] {
        [
            self.noisy,
            self.residual,
            self.covariance,
            self.denoised,
            self.denoised_noise,
            self.valid,
        ]
    }

    fn from_array(a: [f64; Self::COUNT]) -> Self {
        let [noisy, residual, covariance, denoised, denoised_noise, valid] = a;
        Self {
            noisy,
            residual,
            covariance,
            denoised,
            denoised_noise,
            valid,
        }
    }

    /// The weight of the noisy image for terms summed over a window (see
    /// the module's derivation); 0 (the denoised image, as a plain
    /// denoiser gives) where no pixel of the window allowed an estimate.
    fn noisy_weight(self) -> f32 {
        if self.valid == 0.0 {
            return 0.0;
        }
        // The cross-validated error's standard error over the window from
        // the halves' noise alone (the pixels taken as independent; not
        // the terms' spread, which counts the bias's own variation across
        // the window as uncertainty): only the bias the data shows beyond
        // BIAS_EVIDENCE of it is counted, so where the estimate is noisy
        // (few samples, heavy tails) the denoised image keeps its weight.
        let standard_error = self.denoised_noise.max(0.0).sqrt();
        let evidence = self.denoised - self.residual - BIAS_EVIDENCE * standard_error;
        let bias2 = BIAS_SCALE * evidence.max(0.0);
        let mse_denoised = bias2 + 0.5 * self.residual.max(0.0);
        let covariance = 0.5 * self.covariance;
        let v = self.noisy.max(0.0);
        let denom = v + mse_denoised - 2.0 * covariance;
        // `denom` is E[(N - D)^2] over the window; where it vanishes the
        // two images agree and the weight does not matter.
        if denom <= 1e-12 * (v + mse_denoised) || denom <= 0.0 {
            return 0.5;
        }
        ((mse_denoised - covariance) / denom).clamp(0.0, 1.0) as f32
    }
}

/// Per pixel, the weight `w` of the noisy image in `w N + (1 - w) D`,
/// from the error terms summed over the `(2 radius + 1)^2` window around
/// it (clipped at the image's edges).
pub fn noisy_weights(inp: &BlendInputs, radius: usize) -> Vec<f32> {
    let (w, h) = (inp.width, inp.height);
    let n = w * h;
    assert!(
        inp.variance.len() == n
            && inp.half_samples.len() == n
            && inp
                .halves
                .iter()
                .chain(&inp.denoised_halves)
                .all(|x| x.len() == n),
        "blend inputs must all hold {w} x {h} pixels"
    );
    // Summed-area table of the terms, one row and column of zeros in front.
    let stride = w + 1;
    let mut table = vec![[0.0f64; Terms::COUNT]; stride * (h + 1)];
    for y in 0..h {
        let mut row = [0.0f64; Terms::COUNT];
        for x in 0..w {
            let t = Terms::of_pixel(inp, y * w + x).to_array();
            for k in 0..Terms::COUNT {
                row[k] += t[k];
                table[(y + 1) * stride + x + 1][k] = table[y * stride + x + 1][k] + row[k];
            }
        }
    }
    let mut out = vec![0.0; n];
    for y in 0..h {
        let (y0, y1) = (y.saturating_sub(radius), (y + radius + 1).min(h));
        for x in 0..w {
            let (x0, x1) = (x.saturating_sub(radius), (x + radius + 1).min(w));
            let mut sum = [0.0f64; Terms::COUNT];
            for (k, s) in sum.iter_mut().enumerate() {
                *s = table[y1 * stride + x1][k]
                    - table[y0 * stride + x1][k]
                    - table[y1 * stride + x0][k]
                    + table[y0 * stride + x0][k];
            }
            out[y * w + x] = Terms::from_array(sum).noisy_weight();
        }
    }
    out
}

/// `w N + (1 - w) D` per pixel.
pub fn blend(noisy: &Rgb, denoised: &Rgb, noisy_weight: &[f32]) -> Vec<[f32; 3]> {
    noisy
        .iter()
        .zip(denoised)
        .zip(noisy_weight)
        .map(|((n, d), &w)| std::array::from_fn(|c| w * n[c] + (1.0 - w) * d[c]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator of standard normal numbers.
    struct Normal(u64);
    impl Normal {
        fn uniform(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }
        fn next(&mut self) -> f32 {
            let (u, v) = (self.uniform(), self.uniform());
            ((-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()) as f32
        }
    }

    const W: usize = 48;
    const H: usize = 40;

    type Image = Vec<[f32; 3]>;

    /// Two halves of `n / 2` samples each of a flat image of value 1 with
    /// per-sample standard deviation `sigma`: (A, B, per-sample variance).
    fn halves(n: u32, sigma: f32, seed: u64) -> (Image, Image, Image) {
        let mut g = Normal(seed);
        let sd = sigma / ((n / 2) as f32).sqrt();
        let mut img = || -> Vec<[f32; 3]> {
            (0..W * H)
                .map(|_| std::array::from_fn(|_| 1.0 + sd * g.next()))
                .collect()
        };
        let (a, b) = (img(), img());
        (a, b, vec![[sigma * sigma; 3]; W * H])
    }

    fn weights(
        a: &Rgb,
        b: &Rgb,
        var: &Rgb,
        n: u32,
        denoise: impl Fn(&Rgb) -> Vec<[f32; 3]>,
    ) -> Vec<f32> {
        let (da, db) = (denoise(a), denoise(b));
        let samples = vec![[n / 2; 2]; W * H];
        noisy_weights(
            &BlendInputs {
                width: W,
                height: H,
                variance: var,
                half_samples: &samples,
                halves: [a, b],
                denoised_halves: [&da, &db],
            },
            DEFAULT_RADIUS,
        )
    }

    fn mean(x: &[f32]) -> f64 {
        x.iter().map(|&v| f64::from(v)).sum::<f64>() / x.len() as f64
    }

    #[test]
    fn the_bias_scale_is_two_to_the_minus_two_thirds() {
        assert!((BIAS_SCALE - 2f64.powf(-2.0 / 3.0)).abs() < 1e-15);
    }

    #[test]
    fn a_perfect_denoiser_takes_all_the_weight() {
        let (a, b, var) = halves(64, 0.5, 1);
        let w = weights(&a, &b, &var, 64, |x| vec![[1.0; 3]; x.len()]);
        // Its error is 0 and the cross-validation's estimate of it is
        // noise around 0 clamped at 0, so the weights are 0 or near it.
        assert!(mean(&w) < 0.06, "mean weight {}", mean(&w));
    }

    #[test]
    fn an_unbiased_smoothing_denoiser_keeps_its_weight_through_the_covariance() {
        // D_i = (N_i + N_(i+1)) / 2 on a flat image: error v / 2, of which
        // v / 2 is shared with N_i, so no blend beats D (w = 0). Without
        // the covariance term the weight would be 1/3.
        let (a, b, var) = halves(64, 0.5, 2);
        let pair = |x: &Rgb| -> Vec<[f32; 3]> {
            (0..x.len())
                .map(|i| {
                    let j = if i + 1 < x.len() { i + 1 } else { i - 1 };
                    std::array::from_fn(|c| 0.5 * (x[i][c] + x[j][c]))
                })
                .collect()
        };
        let w = weights(&a, &b, &var, 64, pair);
        assert!(mean(&w) < 0.08, "mean weight {}", mean(&w));
    }

    #[test]
    fn a_biased_denoiser_is_weighted_by_its_bias_against_the_noise() {
        // A denoiser that returns the truth shifted by `bias` has error
        // bias^2 per channel and no covariance with the noise: the best
        // weight of the noisy image is bias^2 / (v + bias^2), and the
        // estimate takes BIAS_SCALE of the bias a half shows.
        let (n, sigma, bias) = (64u32, 0.4f32, 0.05f32);
        let (a, b, var) = halves(n, sigma, 3);
        let w = weights(&a, &b, &var, n, |x| vec![[1.0 + bias; 3]; x.len()]);
        let v = f64::from(sigma * sigma) / f64::from(n);
        let b2 = BIAS_SCALE * f64::from(bias * bias);
        let best = b2 / (v + b2);
        let m = mean(&w);
        assert!(
            (m - best).abs() < 0.05,
            "mean weight {m:.3}, best {best:.3}"
        );
    }

    #[test]
    fn the_blend_is_never_much_worse_than_the_better_image() {
        // A box-filter "denoiser" over a ramp: it blurs the ramp's slope
        // away at the edges (bias) and averages noise (residual noise
        // correlated with its input). At low sample counts it should win,
        // at high ones the noisy image; the blend must follow the better.
        let truth: Vec<[f32; 3]> = (0..W * H)
            .map(|i| {
                let x = (i % W) as f32 / W as f32;
                [0.5 + 2.0 * x * x; 3]
            })
            .collect();
        let blur = |img: &Rgb| -> Vec<[f32; 3]> {
            (0..W * H)
                .map(|i| {
                    let (x, y) = (i % W, i / W);
                    let mut s = [0.0f32; 3];
                    let mut k = 0.0;
                    for yy in y.saturating_sub(2)..(y + 3).min(H) {
                        for xx in x.saturating_sub(2)..(x + 3).min(W) {
                            let p = img[yy * W + xx];
                            for c in 0..3 {
                                s[c] += p[c];
                            }
                            k += 1.0;
                        }
                    }
                    s.map(|v| v / k)
                })
                .collect()
        };
        let mse = |img: &Rgb| -> f64 {
            img.iter()
                .zip(&truth)
                .flat_map(|(p, t)| (0..3).map(move |c| f64::from(p[c] - t[c]).powi(2)))
                .sum::<f64>()
                / (3 * W * H) as f64
        };
        for (n, seed) in [(2u32, 11u64), (16, 12), (256, 13), (65536, 14)] {
            let sigma = 0.5f32;
            let (na, nb, var) = halves(n, sigma, seed);
            // The halves around the truth instead of around 1.
            let shift = |h: Vec<[f32; 3]>| -> Vec<[f32; 3]> {
                h.iter()
                    .zip(&truth)
                    .map(|(p, t)| std::array::from_fn(|c| p[c] - 1.0 + t[c]))
                    .collect()
            };
            let (a, b) = (shift(na), shift(nb));
            let noisy: Vec<[f32; 3]> = a
                .iter()
                .zip(&b)
                .map(|(a, b)| std::array::from_fn(|c| 0.5 * (a[c] + b[c])))
                .collect();
            let d = blur(&noisy);
            let w = weights(&a, &b, &var, n, blur);
            let out = blend(&noisy, &d, &w);
            let (e_n, e_d, e_b) = (mse(&noisy), mse(&d), mse(&out));
            let best = e_n.min(e_d);
            assert!(
                e_b <= 1.1 * best,
                "{n} spp: blend {e_b:.3e}, noisy {e_n:.3e}, denoised {e_d:.3e}"
            );
        }
    }
}
