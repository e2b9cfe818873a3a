//! The direction a path scatters into: the phase function's, or, where the
//! radiance cache has learned, one drawn from the one-sample mixture of
//! the phase function and the product of the learned incident light with
//! the phase function (Herholz et al. 2019, section 4). The mixture's
//! density is exact, so next-event estimation and escaped light keep
//! their MIS weights.

use glam::Vec3;

use super::path::PathTracer;
use crate::guiding::BinDistribution;
use crate::medium::Media;
use crate::phase::Phase;
use crate::ray::Ray;
use crate::sampling::{Draw, SampleStream};

/// The share of guided directions drawn from the learned product; the
/// rest are the phase function's. The mixture is defensive: a direction's
/// weight `f / pdf` is at most `1 / (1 - GUIDED_FRACTION)`, and that
/// bound compounds over a path's vertices where the guide errs (hundreds
/// of vertices in a thick cloud). Measured on a thick cloud (BENCHMARKS.md,
/// "Guided path tracing"): 0.5 left fireflies carrying half the squared
/// error; 0.2 and 0.1 measured alike.
pub(super) const GUIDED_FRACTION: f32 = 0.2;

/// A scattered direction with what the path needs of it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Scattered {
    pub dir: Vec3,
    /// The density it was sampled with, for the MIS weights of the lights
    /// it may escape to.
    pub pdf: f32,
    /// The factor the path's throughput takes: the phase function over
    /// the density, 1 for phase sampling.
    pub weight: f32,
}

/// The density of a guided vertex's mixture at a direction where the
/// phase function is `f` (its own density) and the learned product's
/// density is `guide_pdf`.
#[inline]
pub(super) fn mixture_pdf(f: f32, guide_pdf: f32) -> f32 {
    (1.0 - GUIDED_FRACTION) * f + GUIDED_FRACTION * guide_pdf
}

/// A direction out of a vertex reached along `dir_in`: from `guide` if
/// `choice` falls below [`GUIDED_FRACTION`], else from the phase function,
/// `(u1, u2)` placing it either way; weighted by the mixture's density.
pub(super) fn sample_mixture(
    phase: &Phase,
    dir_in: Vec3,
    guide: &BinDistribution,
    choice: f32,
    (u1, u2): (f32, f32),
) -> Scattered {
    let dir = if choice < GUIDED_FRACTION {
        guide.sample(u1, u2).0
    } else {
        phase.sample(dir_in, u1, u2).0
    };
    let f = phase.eval(dir_in, dir);
    let pdf = mixture_pdf(f, guide.pdf(dir));
    Scattered {
        dir,
        pdf,
        weight: if pdf > 0.0 { f / pdf } else { 0.0 },
    }
}

impl<M: Media> PathTracer<'_, M> {
    /// Samples the direction out of a vertex reached along `ray_in`: the
    /// phase draw places it, the hashed stream picks the guided vertex's
    /// mixture component.
    pub(super) fn scatter(
        &self,
        ray_in: &Ray,
        phase: &Phase,
        guide: Option<&BinDistribution>,
        vertex: u32,
        draws: &mut SampleStream,
    ) -> Scattered {
        let u = draws.get_2d(Draw::Phase, vertex);
        match guide {
            None => {
                let (dir, pdf) = phase.sample(ray_in.dir, u.0, u.1);
                Scattered {
                    dir,
                    pdf,
                    weight: 1.0,
                }
            }
            Some(guide) => sample_mixture(phase, ray_in.dir, guide, draws.rng().uniform(), u),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::guiding::{IncidentLight, BINS};
    use crate::sampling::Rng;

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

    /// A guided direction's weight times an integrand estimates the
    /// integrand's phase-weighted integral, as phase sampling does; the
    /// same check with the guided density off by 10% (the weight of the
    /// directions drawn from the guide scaled by 1.1) fails it.
    #[test]
    fn the_mixture_estimates_the_phase_integral_and_a_broken_density_does_not() {
        let phase = Phase::hg(0.6);
        let dir_in = Vec3::new(0.3, 0.2, -0.93).normalize();
        // A learned light brighter over the upper hemisphere, as under a
        // sun, and its product with the phase function.
        let (mut sums, counts) = ([0.0f32; BINS], [8u32; BINS]);
        let centres = crate::guiding::bin_centres();
        for (b, s) in sums.iter_mut().enumerate() {
            *s = 8.0 * (0.2 + 3.0 * centres[b].z.max(0.0));
        }
        let light = IncidentLight::new(&sums, &counts).unwrap();
        let guide = light.product(|d| phase.eval(dir_in, d)).unwrap();
        // An integrand the guide only roughly follows.
        let f = |d: Vec3| f64::from((d.z + 0.3).max(0.0).powi(2) + 0.05 * (d.x + 1.0));
        let n = 400_000;
        let mut rng = Rng::new(3, 0, 0);
        let (reference, se_ref) = mean_se(n, || {
            f(phase.sample(dir_in, rng.uniform(), rng.uniform()).0)
        });
        let guided = |broken: bool| {
            let mut rng = Rng::new(4, 0, 0);
            mean_se(n, || {
                let choice = rng.uniform();
                let s = sample_mixture(
                    &phase,
                    dir_in,
                    &guide,
                    choice,
                    (rng.uniform(), rng.uniform()),
                );
                let w = if broken && choice < GUIDED_FRACTION {
                    1.1 * s.weight
                } else {
                    s.weight
                };
                f64::from(w) * f(s.dir)
            })
        };
        let z = |(m, se): (f64, f64)| (m - reference) / (se * se + se_ref * se_ref).sqrt();
        let (exact, broken) = (z(guided(false)), z(guided(true)));
        eprintln!("exact z {exact}, broken z {broken}");
        assert!(exact.abs() <= 4.0, "guided estimate off: z {exact}");
        assert!(
            broken.abs() > 10.0,
            "a 10% density error went unseen: z {broken}"
        );
    }
}
