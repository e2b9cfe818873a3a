//! The sphere of directions cut into equal-area bins, and what a region
//! learns of the light arriving through each ([`IncidentLight`]).
//!
//! Layout: Lambert's cylindrical equal-area map, `z = cos(theta)` in
//! `[-1, 1]` against `phi` in `[0, 2 pi)`, cut into `Z_BINS x PHI_BINS`
//! rectangles; each covers the same solid angle, `4 pi / BINS`, because
//! the map preserves area. A direction's bin is two multiplications and a
//! floor; a point uniform in a bin's rectangle is uniform in its solid
//! angle, so a bin's density is its probability over that solid angle.
//! The incident light inside a cloud is smooth (multiply scattered), so a
//! fixed 8 x 16 grid (each bin about 0.1 sr) resolves it; the sun's own,
//! sharp direction is next-event estimation's, never the guide's.

use std::f32::consts::PI;

use glam::Vec3;

use crate::phase::Phase;

/// Bins along `z = cos(theta)`.
pub const Z_BINS: usize = 8;
/// Bins along the azimuth.
pub const PHI_BINS: usize = 16;
pub const BINS: usize = Z_BINS * PHI_BINS;

/// The bin of a unit direction.
#[inline]
pub fn bin_of(dir: Vec3) -> usize {
    let z = ((dir.z + 1.0) * 0.5 * Z_BINS as f32) as usize;
    let phi = dir.y.atan2(dir.x);
    let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
    let p = (phi * (PHI_BINS as f32 / (2.0 * PI))) as usize;
    z.min(Z_BINS - 1) * PHI_BINS + p.min(PHI_BINS - 1)
}

/// What a region learned of the light arriving from each bin: the mean
/// incident radiance (luminance) of the samples that left through it.
/// Where few or none did, the region's mean over all directions stands
/// in, and no bin is darker than a share of it, so every direction keeps
/// a chance to be sampled (the resampling that uses it needs that).
#[derive(Clone, Debug, PartialEq)]
pub struct IncidentLight {
    radiance: [f32; BINS],
}

/// A density over directions, constant within each bin: a bin is drawn in
/// proportion to its weight, then a point uniform in its solid angle.
#[derive(Clone, Debug, PartialEq)]
pub struct BinDistribution {
    weights: [f32; BINS],
    /// Running sums of `weights` (the last is the total), searched by
    /// bisection.
    cdf: [f32; BINS],
}

/// A bin's own mean counts once it has this many samples.
const MIN_BIN_SAMPLES: u32 = 4;
/// No bin is taken as darker than this share of the mean.
const FLOOR: f32 = 0.05;

impl IncidentLight {
    /// From each bin's sum of incident radiance and sample count; `None`
    /// where nothing arrived at all.
    pub fn new(sums: &[f32; BINS], counts: &[u32; BINS]) -> Option<IncidentLight> {
        let total: f64 = sums.iter().map(|&s| f64::from(s)).sum();
        let n: u64 = counts.iter().map(|&c| u64::from(c)).sum();
        let mean = (total / n.max(1) as f64) as f32;
        if !(mean > 0.0 && mean.is_finite()) {
            return None;
        }
        let mut radiance = [mean; BINS];
        for ((r, &s), &c) in radiance.iter_mut().zip(sums).zip(counts) {
            if c >= MIN_BIN_SAMPLES {
                *r = (s / c as f32).max(FLOOR * mean);
            }
        }
        Some(IncidentLight { radiance })
    }

    /// The learned light times `f` (the phase function toward each bin's
    /// centre), as a density to sample: the product of Herholz et al.
    /// 2019, section 4, constant over each bin. `None` if the product
    /// vanishes.
    pub fn product(&self, f: impl Fn(Vec3) -> f32) -> Option<BinDistribution> {
        let centres = bin_centres();
        BinDistribution::new(std::array::from_fn(|b| self.radiance[b] * f(centres[b])))
    }

    /// The learned radiance of each bin.
    #[inline]
    pub fn bins(&self) -> &[f32; BINS] {
        &self.radiance
    }

    /// The learned radiance arriving from `dir` (positive).
    #[inline]
    pub fn radiance(&self, dir: Vec3) -> f32 {
        self.radiance[bin_of(dir)]
    }

    /// The learned light scattered once by `phase` toward each bin's
    /// centre: entry `o` is the mean of the bins' radiance weighted by
    /// `phase.eval(c_o, c_b)`, the in-scattered radiance a path arriving
    /// along bin `o`'s centre finds (normalised by the weights' sum, so
    /// uniform light scatters to itself whatever the bins resolve of the
    /// phase function's peak).
    pub fn scattered(&self, phase: &Phase) -> [f32; BINS] {
        let centres = bin_centres();
        std::array::from_fn(|o| {
            let (mut sum, mut weights) = (0.0f32, 0.0f32);
            for (c, &l) in centres.iter().zip(&self.radiance) {
                let f = phase.eval(centres[o], *c);
                sum += f * l;
                weights += f;
            }
            if weights > 0.0 {
                sum / weights
            } else {
                0.0
            }
        })
    }

    /// The learned light alone as a density to sample.
    pub fn distribution(&self) -> BinDistribution {
        BinDistribution::new(self.radiance).expect("learned light is positive")
    }
}

impl BinDistribution {
    /// From each bin's weight (finite, non-negative); `None` if all vanish.
    pub fn new(weights: [f32; BINS]) -> Option<BinDistribution> {
        let mut cdf = weights;
        for b in 1..BINS {
            cdf[b] += cdf[b - 1];
        }
        let total = cdf[BINS - 1];
        (total > 0.0 && total.is_finite()).then_some(BinDistribution { weights, cdf })
    }

    /// The density (per steradian) of [`BinDistribution::sample`] at
    /// `dir`: its bin's share of the weight over the bin's solid angle.
    #[inline]
    pub fn pdf(&self, dir: Vec3) -> f32 {
        self.weights[bin_of(dir)] / self.cdf[BINS - 1] * (BINS as f32 / (4.0 * PI))
    }

    /// A direction drawn from the density: a bin by its share (`u1`,
    /// reused within the bin for the azimuth), then a point uniform in the
    /// bin's solid angle (`u2` for `z`). Returns it with its density.
    pub fn sample(&self, u1: f32, u2: f32) -> (Vec3, f32) {
        let total = self.cdf[BINS - 1];
        let x = u1 * total;
        let bin = self.cdf.partition_point(|&c| c <= x).min(BINS - 1);
        // Skip empty bins the search may land on at their edge.
        let bin = (bin..BINS).find(|&b| self.weights[b] > 0.0).unwrap_or(bin);
        let below = if bin == 0 { 0.0 } else { self.cdf[bin - 1] };
        // Where `x` fell inside the bin's interval, reused for the azimuth.
        let v = ((x - below) / self.weights[bin]).clamp(0.0, 1.0 - f32::EPSILON);
        let (iz, ip) = (bin / PHI_BINS, bin % PHI_BINS);
        let z = -1.0 + 2.0 * (iz as f32 + u2) / Z_BINS as f32;
        let phi = 2.0 * PI * (ip as f32 + v) / PHI_BINS as f32;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let dir = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        (dir, self.weights[bin] / total * (BINS as f32 / (4.0 * PI)))
    }
}

/// The direction at the centre of each bin.
pub fn bin_centres() -> &'static [Vec3; BINS] {
    static CENTRES: std::sync::OnceLock<[Vec3; BINS]> = std::sync::OnceLock::new();
    CENTRES.get_or_init(|| std::array::from_fn(bin_centre))
}

/// The direction at the centre of bin `bin`.
pub(crate) fn bin_centre(bin: usize) -> Vec3 {
    let (iz, ip) = (bin / PHI_BINS, bin % PHI_BINS);
    let z = -1.0 + 2.0 * (iz as f32 + 0.5) / Z_BINS as f32;
    let phi = 2.0 * PI * (ip as f32 + 0.5) / PHI_BINS as f32;
    let r = (1.0 - z * z).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{uniform_sphere, Rng};

    #[test]
    fn bins_cover_the_sphere_with_equal_areas() {
        // Uniform directions fall into every bin about equally often.
        let mut rng = Rng::new(1, 0, 0);
        let mut counts = [0u32; BINS];
        let n = 256_000;
        for _ in 0..n {
            counts[bin_of(uniform_sphere(rng.uniform(), rng.uniform()))] += 1;
        }
        let expected = n as f64 / BINS as f64;
        for (b, &c) in counts.iter().enumerate() {
            // 2000 per bin: 5 standard deviations is 224.
            assert!(
                (f64::from(c) - expected).abs() < 5.0 * expected.sqrt(),
                "bin {b}: {c}"
            );
        }
    }

    #[test]
    fn learned_light_falls_back_to_the_mean_and_keeps_a_floor() {
        let (mut sums, mut counts) = ([0.0f32; BINS], [0u32; BINS]);
        sums[5] = 80.0;
        counts[5] = 8;
        sums[6] = 0.0;
        counts[6] = 10;
        counts[7] = 2;
        sums[7] = 100.0;
        let light = IncidentLight::new(&sums, &counts).unwrap();
        let mean = 180.0 / 20.0;
        let dir = bin_centre;
        assert_eq!(light.radiance(dir(5)), 10.0);
        assert_eq!(light.radiance(dir(6)), FLOOR * mean);
        // Too few samples: the mean stands in.
        assert_eq!(light.radiance(dir(7)), mean);
        assert_eq!(light.radiance(dir(100)), mean);
        assert!(IncidentLight::new(&[0.0; BINS], &counts).is_none());
    }

    /// Sampled directions fall in each bin in proportion to its radiance,
    /// land in the bin they were drawn from, carry the density `pdf`
    /// gives, and that density integrates to 1 over the sphere.
    #[test]
    fn learned_light_samples_its_own_density() {
        let (mut sums, counts) = ([0.0f32; BINS], [4u32; BINS]);
        for (b, s) in sums.iter_mut().enumerate() {
            *s = 4.0 * (1.0 + (b % 7) as f32 + 10.0 * f32::from(b == 40));
        }
        let learned = IncidentLight::new(&sums, &counts).unwrap();
        let total: f32 = (0..BINS).map(|b| learned.radiance(bin_centre(b))).sum();
        let light = learned.distribution();
        let mut rng = Rng::new(2, 0, 0);
        let n = 200_000;
        let mut hits = [0u32; BINS];
        for _ in 0..n {
            let (d, pdf) = light.sample(rng.uniform(), rng.uniform());
            assert!((d.length() - 1.0).abs() < 1e-4);
            assert!(
                (pdf - light.pdf(d)).abs() <= 1e-4 * pdf,
                "{pdf} against {}",
                light.pdf(d)
            );
            hits[bin_of(d)] += 1;
        }
        for (b, &hit) in hits.iter().enumerate() {
            let expected = f64::from(n) * f64::from(learned.radiance(bin_centre(b)) / total);
            let c = f64::from(hit);
            assert!(
                (c - expected).abs() < 5.0 * expected.sqrt() + 1.0,
                "bin {b}: {c} against {expected}"
            );
        }
        // Monte Carlo integral of the density over uniform directions.
        let integral: f64 = (0..n)
            .map(|_| f64::from(light.pdf(uniform_sphere(rng.uniform(), rng.uniform()))))
            .sum::<f64>()
            * 4.0
            * std::f64::consts::PI
            / f64::from(n);
        assert!((integral - 1.0).abs() < 0.01, "{integral}");
    }
}
