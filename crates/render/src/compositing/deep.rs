//! Deep samples from the path tracer's own estimates.
//!
//! Depth is planar (along the view axis, as camera-space Z in Nuke and as
//! `--holdout-depth` reads it), not distance along the ray.
//!
//! Each camera sample of a pixel either collides first at a depth `t` (it
//! is opaque there: the track-length estimate of alpha is 1) or escapes
//! (alpha 0), and carries its whole path's radiance `L`. The pixel keeps
//! bins of first-collision depth: each bin its depth range, its count `c`
//! and its radiance sum `S`; escapes go to a background bin.
//!
//! Which alpha and colour make OpenEXR's front-to-back "over" of the bins
//! give back the flat pixel? Out of `n` samples, let `R_k = n - sum of
//! c_j over the bins j in front of k` (the samples still travelling when
//! bin k begins). Choose
//!
//! ```text
//! a_k = c_k / R_k          C_k = S_k / R_k   (premultiplied)
//! ```
//!
//! "Over" leaves transmittance `T_k = prod_{j<k} (1 - a_j)` in front of
//! bin k, and `1 - a_j = R_{j+1} / R_j` telescopes to `T_k = R_k / n`.
//! So the composite alpha is `1 - R_K / n = hits / n`, the flat alpha,
//! and the composite colour is `sum_k T_k C_k = sum_k S_k / n`, the flat
//! mean: exact, whatever the bins. In words, a bin's alpha is the fraction
//! of the samples reaching it that stop in it, and its colour is divided
//! by the transmittance in front, which "over" multiplies back.
//!
//! Merging two adjacent bins keeps this exact: their counts and sums add,
//! and `1 - a` of the merged bin is `(1 - a_k)(1 - a_{k+1})`, so optical
//! depths `-ln(1 - a)` add. The film keeps at most [`RAW_BINS`] bins per
//! pixel while sampling (merging the adjacent pair holding fewest
//! samples); the resolve then merges the adjacent pair of least summed
//! optical depth until at most the asked-for number remain, so thin stretches
//! merge first and the depth resolution goes where the opacity changes.
//! Bins are in the order samples arrive, per pixel, so deep images are
//! the same on any thread count and in crops.

use glam::Vec3;

/// Depth of a pixel no camera sample collided in (Blender's convention
/// for the background of its Z pass), in the film's depth pass and the
/// deep image's background sample alike.
pub const NO_DEPTH: f32 = 1e10;

/// Bins a pixel keeps while sampling.
pub const RAW_BINS: usize = 64;

/// One deep sample: depth range, premultiplied colour and alpha.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeepSample {
    pub z: f32,
    pub z_back: f32,
    pub rgb: [f32; 3],
    pub alpha: f32,
}

#[derive(Clone, Copy, Debug)]
struct Bin {
    t0: f32,
    t1: f32,
    count: u32,
    sum: Vec3,
}

/// One pixel's bins of first-collision depth.
#[derive(Clone, Debug, Default)]
pub(crate) struct DeepPixel {
    bins: Vec<Bin>,
    /// Radiance of the samples that collided nowhere visible.
    background: Vec3,
}

impl DeepPixel {
    /// Adds a sample of radiance `l` whose camera ray first collided at
    /// `depth` (`None`: it escaped, or met a holdout).
    pub fn add(&mut self, depth: Option<f32>, l: Vec3) {
        let Some(t) = depth.filter(|t| t.is_finite()) else {
            self.background += l;
            return;
        };
        let at = self.bins.partition_point(|b| b.t1 < t);
        match self.bins.get_mut(at) {
            Some(b) if b.t0 <= t => {
                b.count += 1;
                b.sum += l;
            }
            _ => self.bins.insert(
                at,
                Bin {
                    t0: t,
                    t1: t,
                    count: 1,
                    sum: l,
                },
            ),
        }
        if self.bins.len() > RAW_BINS {
            let k = (0..self.bins.len() - 1)
                .min_by_key(|&k| self.bins[k].count + self.bins[k + 1].count)
                .unwrap_or(0);
            merge(&mut self.bins, k);
        }
    }

    /// The deep samples of a pixel of `n` samples, at most `max` bins
    /// (plus the background, when it has light); see the module doc.
    pub fn resolve(&self, n: u32, max: usize) -> Vec<DeepSample> {
        let mut bins = self.bins.clone();
        let n = n.max(1) as f64;
        while bins.len() > max.max(1) {
            let depths = optical_depths(&bins, n);
            let k = (0..bins.len() - 1)
                .min_by(|&i, &j| {
                    (depths[i] + depths[i + 1]).total_cmp(&(depths[j] + depths[j + 1]))
                })
                .unwrap_or(0);
            merge(&mut bins, k);
        }
        let mut out = Vec::with_capacity(bins.len() + 1);
        let mut remaining = n;
        for b in &bins {
            let r = remaining.max(1.0);
            out.push(DeepSample {
                z: b.t0,
                z_back: b.t1,
                rgb: (b.sum.as_dvec3() / r).as_vec3().to_array(),
                alpha: (f64::from(b.count) / r) as f32,
            });
            remaining -= f64::from(b.count);
        }
        if self.background.max_element() > 0.0 && remaining > 0.0 {
            out.push(DeepSample {
                z: NO_DEPTH,
                z_back: NO_DEPTH,
                rgb: (self.background.as_dvec3() / remaining)
                    .as_vec3()
                    .to_array(),
                alpha: 0.0,
            });
        }
        out
    }
}

/// Each bin's optical depth `-ln(1 - a)` for a pixel of `n` samples.
fn optical_depths(bins: &[Bin], n: f64) -> Vec<f64> {
    let mut remaining = n;
    bins.iter()
        .map(|b| {
            let after = remaining - f64::from(b.count);
            let tau = (remaining / after.max(0.0)).ln();
            remaining = after;
            tau
        })
        .collect()
}

/// Merges bins `k` and `k + 1`.
fn merge(bins: &mut Vec<Bin>, k: usize) {
    let next = bins.remove(k + 1);
    let b = &mut bins[k];
    b.t1 = next.t1;
    b.count += next.count;
    b.sum += next.sum;
}

/// Front-to-back "over" of deep samples (OpenEXR's flattening of
/// non-overlapping samples), for tests and tools: premultiplied RGB and
/// alpha.
pub fn flatten(samples: &[DeepSample]) -> [f32; 4] {
    let mut out = [0.0f64; 4];
    let mut t = 1.0f64;
    for s in samples {
        for (o, c) in out.iter_mut().zip(s.rgb) {
            *o += t * f64::from(c);
        }
        out[3] += t * f64::from(s.alpha);
        t *= 1.0 - f64::from(s.alpha);
    }
    out.map(|v| v as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bins merged to any count flatten to the samples' mean colour and
    /// their fraction of collisions, to float rounding.
    #[test]
    fn merged_bins_flatten_to_the_mean() {
        let mut px = DeepPixel::default();
        let mut sum = Vec3::ZERO;
        let mut hits = 0;
        let n = 500u32;
        for i in 0..n {
            let x = ((i * 7919) % 1000) as f32 / 1000.0;
            let l = Vec3::new(x, 0.5 * x, 1.0 - x);
            sum += l;
            let depth = (i % 5 != 0).then_some(3.0 + 40.0 * x);
            hits += u32::from(depth.is_some());
            px.add(depth, l);
        }
        assert!(px.bins.len() <= RAW_BINS);
        for max in [1, 3, 16, 64] {
            let deep = px.resolve(n, max);
            assert!(deep.len() <= max + 1, "{}", deep.len());
            let flat = flatten(&deep);
            let mean = sum / n as f32;
            for c in 0..3 {
                assert!(
                    (flat[c] - mean[c]).abs() < 1e-5 * mean[c].max(1.0),
                    "{flat:?} {mean}"
                );
            }
            assert!((flat[3] - hits as f32 / n as f32).abs() < 1e-6, "{flat:?}");
            assert!(deep.windows(2).all(|w| w[0].z_back <= w[1].z), "sorted");
        }
    }
}
