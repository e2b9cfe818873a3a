//! Path guiding: a radiance cache learned from the render's own paths, and
//! the sampling decisions it guides.
//!
//! - `regions`: a binary tree over the media refined where samples fall,
//!   each leaf a [`Region`] holding the mean incident radiance per
//!   direction bin and its mean in-scattered radiance (Müller, Gross,
//!   Novák 2017's SD-tree, with a fixed equal-area directional grid,
//!   `sphere`, in place of their quadtrees: inside a cloud the light that
//!   is not the sun's own is smooth).
//! - `learn`: what a path teaches the cache ([`PathRecorder`]).
//! - `training`: the fixed schedule of training passes over the whole
//!   frame ([`train`]).
//!
//! A [`Guide`] is the cache frozen for a pass. The path tracer samples a
//! scattering direction in proportion to the product of the phase
//! function and the learned incident radiance, the zero-variance choice
//! of Herholz et al. 2019 ("Volume Path Guiding Based on Zero-Variance
//! Random Walk Theory", section 4), by resampled importance sampling
//! ([`resample`]): a mixture of the phase function and the learned light
//! alone compounds a weight of up to `1 / (1 - a)` per vertex where the
//! phase function is forward peaked (g 0.8) and paths scatter hundreds of
//! times, which measured worse than no guiding.

mod learn;
mod regions;
mod sphere;
mod training;

pub use learn::{luminance, Ignore, Learner, PathRecorder};
pub use regions::{Record, Region, Regions, MAX_REGIONS};
pub use sphere::{IncidentLight, BINS};
pub use training::{train, Frame, TrainingSchedule};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::medium::Bounds3;

/// Candidate directions drawn from the phase function for each guided
/// direction.
pub const CANDIDATES: usize = 8;

/// Whether the path tracer learns and follows a radiance cache.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum GuidingMode {
    /// Where it pays. Measured against unguided rendering at equal time
    /// (BENCHMARKS.md, "Guided path tracing"), the guide as it stands
    /// pays on no scene yet, thick bright clouds included, so `auto`
    /// renders unguided: the same image, bit for bit, as `off`.
    #[default]
    Auto,
    On,
    Off,
}

impl GuidingMode {
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::On => "on",
            Self::Off => "off",
        }
    }
}

/// The radiance cache, frozen: what a pass's paths are guided by.
#[derive(Clone, Debug)]
pub struct Guide {
    regions: Regions,
}

impl Guide {
    /// An empty cache over `bounds` (it guides nothing until it learns).
    pub fn new(bounds: Bounds3) -> Guide {
        Guide {
            regions: Regions::new(bounds),
        }
    }

    /// The region at `p`.
    #[inline]
    pub fn region_at(&self, p: Vec3) -> (u32, &Region) {
        let i = self.regions.index_of(p);
        (i, self.regions.region(i))
    }

    pub fn regions(&self) -> &Regions {
        &self.regions
    }
}

/// Resampled importance sampling (Talbot, Cline, Egbert 2005) of the
/// product `phase * L`, `L` the learned incident light: of [`CANDIDATES`]
/// directions drawn from the phase function, one is kept with probability
/// proportional to `L` there, `u` choosing it. Returns its index with the
/// factor its path's throughput takes, `mean(L_k) / L(kept)`: the phase
/// weight of a phase-sampled direction (1) times the RIS weight, so the
/// estimate stays unbiased for any learned `L` that is positive everywhere
/// (`IncidentLight` keeps a floor). The kept direction has no closed-form
/// density: a guided vertex takes its lights at infinity by next-event
/// estimation alone.
pub fn resample(light: &IncidentLight, dirs: &[Vec3; CANDIDATES], u: f32) -> (usize, f32) {
    let weights = dirs.map(|d| light.radiance(d));
    let sum: f32 = weights.iter().sum();
    let mut x = u * sum;
    let mut kept = CANDIDATES - 1;
    for (k, &w) in weights.iter().enumerate() {
        if x < w {
            kept = k;
            break;
        }
        x -= w;
    }
    (kept, (sum / CANDIDATES as f32) / weights[kept])
}

/// The learned-stats of a render that followed a guide.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct GuidingStats {
    /// "on", "off", or with `auto` the choice ("auto: on").
    pub mode: String,
    pub training_passes: u32,
    /// Samples per pixel spent on training (not in the image).
    pub training_spp: u32,
    pub training_seconds: f64,
    pub regions: usize,
    pub memory_bytes: usize,
    /// Records the cache learned from.
    pub records: u64,
}

#[cfg(test)]
mod tests {
    use super::sphere::tests_direction;
    use super::*;
    use crate::phase::Phase;
    use crate::sampling::Rng;

    /// A learned light brighter over the upper hemisphere, as under a sun.
    fn learned() -> IncidentLight {
        let (mut sums, counts) = ([0.0f32; BINS], [8u32; BINS]);
        for (b, s) in sums.iter_mut().enumerate() {
            let z = tests_direction(b).z;
            *s = 8.0 * (0.2 + 3.0 * z.max(0.0));
        }
        IncidentLight::new(&sums, &counts).unwrap()
    }

    /// Mean and standard error of `n` samples of `f`.
    fn mean_se(n: usize, mut f: impl FnMut() -> f64) -> (f64, f64) {
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let x = f();
            s += x;
            s2 += x * x;
        }
        let m = s / n as f64;
        (m, ((s2 / n as f64 - m * m) / (n as f64 - 1.0)).sqrt())
    }

    /// The resampled direction's weight times an integrand estimates the
    /// integrand's phase-weighted integral, as phase sampling does; the
    /// same check with the guided density off by 10% (the weight of the
    /// directions the guide favours scaled by 1.1) fails it.
    #[test]
    fn resampling_estimates_the_phase_integral_and_a_broken_density_does_not() {
        let phase = Phase::hg(0.6);
        let light = learned();
        let dir_in = Vec3::new(0.3, 0.2, -0.93).normalize();
        // An integrand the guide only roughly follows.
        let f = |d: Vec3| f64::from((d.z + 0.3).max(0.0).powi(2) + 0.05 * (d.x + 1.0));
        let n = 200_000;
        let mut rng = Rng::new(3, 0, 0);
        let (reference, se_ref) = mean_se(n, || {
            f(phase.sample(dir_in, rng.uniform(), rng.uniform()).0)
        });
        let guided = |broken: bool| {
            let mut rng = Rng::new(4, 0, 0);
            mean_se(n, || {
                let dirs: [Vec3; CANDIDATES] =
                    std::array::from_fn(|_| phase.sample(dir_in, rng.uniform(), rng.uniform()).0);
                let (k, mut w) = resample(&light, &dirs, rng.uniform());
                if broken && dirs[k].z > 0.0 {
                    w *= 1.1;
                }
                f64::from(w) * f(dirs[k])
            })
        };
        let z = |(m, se): (f64, f64)| (m - reference) / (se * se + se_ref * se_ref).sqrt();
        let (exact, broken) = (z(guided(false)), z(guided(true)));
        assert!(exact.abs() <= 4.0, "resampled estimate off: z {exact}");
        assert!(
            broken.abs() > 10.0,
            "a 10% density error went unseen: z {broken}"
        );
    }
}
