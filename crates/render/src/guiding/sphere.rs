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

    /// The learned radiance arriving from `dir` (positive).
    #[inline]
    pub fn radiance(&self, dir: Vec3) -> f32 {
        self.radiance[bin_of(dir)]
    }
}

/// A direction at the centre of bin `bin` (for tests).
#[cfg(test)]
pub(crate) fn tests_direction(bin: usize) -> Vec3 {
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
        let dir = tests_direction;
        assert_eq!(light.radiance(dir(5)), 10.0);
        assert_eq!(light.radiance(dir(6)), FLOOR * mean);
        // Too few samples: the mean stands in.
        assert_eq!(light.radiance(dir(7)), mean);
        assert_eq!(light.radiance(dir(100)), mean);
        assert!(IncidentLight::new(&[0.0; BINS], &counts).is_none());
    }
}
