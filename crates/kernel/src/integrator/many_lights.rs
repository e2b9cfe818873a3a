//! One light picked among any number, by what each sends toward the
//! vertex: the light choice of scenes with more lights than the per-vertex
//! pick of `light_choice.rs` keeps (a fog lit by a street of lamps).
//!
//! Each light is weighed by its unoccluded light at the vertex as an
//! isotropic phase function would scatter it (a distant light's irradiance
//! over `4 pi`, a dome's mean radiance, a sphere light's `I / (4 pi d^2)`
//! times its spot's falloff, an area light's `L A cos / (4 pi d^2)`), as pbrt-v4's `PowerLightSampler` does with
//! distance, or Cycles' light tree does per cluster; a light tree would
//! find the heavy lights in `log n`, this sum takes `n` multiply-adds per
//! vertex against a shadow ray's hundreds of lookups. Every light keeps a
//! defensive share `MIN_PROBABILITY / n` (the weights know no occlusion).
//! The pick is one light per vertex: its noise grows with how unevenly
//! the lights reach a vertex, not with their number.
//!
//! `uniform` weighs every light alike: the baseline the weighing is
//! measured against (BENCHMARKS.md, "Many lights").

use glam::Vec3;

use super::per_light::MIN_PROBABILITY;
use crate::light::{AreaLight, Light, Lights, SphereLight};
use crate::sampling::UNIFORM_SPHERE_PDF;
use crate::spectrum::luminance;

/// What a light's weight at a vertex depends on.
#[derive(Clone, Copy, Debug)]
enum Reach {
    /// The same everywhere (distant lights and domes).
    Everywhere(f32),
    /// Falling off from a sphere light, whose intensity's luminance is
    /// given.
    From(SphereLight, f32),
    /// Falling off from an area light, whose radiance's luminance is given.
    FromArea(AreaLight, f32),
}

/// The weighing of many lights.
#[derive(Clone, Debug)]
pub(crate) struct ManyLights {
    reach: Vec<Reach>,
    /// Weigh every light alike.
    uniform: bool,
}

impl ManyLights {
    pub fn new(lights: &Lights, uniform: bool) -> Self {
        let reach = lights
            .iter()
            .map(|light| match light {
                Light::Distant(sun) => {
                    Reach::Everywhere(luminance(sun.irradiance()) * UNIFORM_SPHERE_PDF)
                }
                Light::Dome(env) => Reach::Everywhere(luminance(env.mean_radiance())),
                Light::Sphere(s) => Reach::From(*s, luminance(s.intensity()) * UNIFORM_SPHERE_PDF),
                Light::Area(a) => Reach::FromArea(*a, luminance(a.radiance()) * UNIFORM_SPHERE_PDF),
            })
            .collect();
        Self { reach, uniform }
    }

    pub fn len(&self) -> usize {
        self.reach.len()
    }

    /// Light `i`'s weight at `at`.
    #[inline]
    fn weight(&self, i: usize, at: Vec3) -> f32 {
        if self.uniform {
            return 1.0;
        }
        match &self.reach[i] {
            Reach::Everywhere(w) => *w,
            Reach::From(s, l) => s.luminance_at(at, *l),
            Reach::FromArea(a, l) => a.luminance_at(at, *l),
        }
    }

    /// The sum of the weights at `at` (what [`Self::probability`] and
    /// [`Self::pick`] divide by), 0 where none is finite and positive.
    #[inline]
    pub fn total(&self, at: Vec3) -> f32 {
        let total: f32 = (0..self.len()).map(|i| self.weight(i, at)).sum();
        if total.is_finite() && total > 0.0 {
            total
        } else {
            0.0
        }
    }

    /// The probability that a vertex at `at` (with [`Self::total`]
    /// `total`) picks light `i`: its share of the weights, mixed with the
    /// defensive uniform share.
    #[inline]
    pub fn probability(&self, at: Vec3, total: f32, i: usize) -> f32 {
        let n = self.len() as f32;
        if total <= 0.0 {
            return 1.0 / n;
        }
        (1.0 - MIN_PROBABILITY) * self.weight(i, at) / total + MIN_PROBABILITY / n
    }

    /// The light `u` (uniform in [0, 1)) picks at `at`, with its
    /// probability: the probabilities laid end to end in list order.
    #[inline]
    pub fn pick(&self, at: Vec3, total: f32, u: f32) -> (usize, f32) {
        let mut end = 0.0;
        let mut last = (0, 0.0);
        for i in 0..self.len() {
            let p = self.probability(at, total, i);
            end += p;
            if p > 0.0 {
                last = (i, p);
                if u < end {
                    return last;
                }
            }
        }
        // Rounding left the sum a little below one.
        last
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::Sun;

    fn street() -> Lights {
        let lamps = (0..20).map(|k| {
            let at = Vec3::new(10.0 * k as f32, 5.0, 0.0);
            SphereLight::new(at, 0.1, Vec3::splat(100.0 + k as f32)).into()
        });
        let sun = Sun::new(Vec3::NEG_Y, Vec3::splat(0.5), 0.0).into();
        Lights::new(lamps.chain([sun]))
    }

    #[test]
    fn the_probabilities_sum_to_one_and_the_pick_follows_them() {
        let lights = street();
        for uniform in [false, true] {
            let many = ManyLights::new(&lights, uniform);
            let at = Vec3::new(42.0, 0.0, 1.0);
            let total = many.total(at);
            let p: Vec<f32> = (0..many.len())
                .map(|i| many.probability(at, total, i))
                .collect();
            let sum: f32 = p.iter().sum();
            assert!((sum - 1.0).abs() < 1e-5, "{sum}");
            assert!(p
                .iter()
                .all(|&x| x >= MIN_PROBABILITY / p.len() as f32 * 0.999));
            let n = 200_000;
            let mut counts = vec![0u32; p.len()];
            for k in 0..n {
                let (i, pi) = many.pick(at, total, (k as f32 + 0.5) / n as f32);
                assert_eq!(pi, p[i]);
                counts[i] += 1;
            }
            for (i, (&c, &pi)) in counts.iter().zip(&p).enumerate() {
                let f = c as f32 / n as f32;
                assert!(
                    (f - pi).abs() < 2.0 / n as f32 + 1e-5,
                    "light {i}: {f} vs {pi}"
                );
            }
            if !uniform {
                // The lamp above the vertex (x = 40) outweighs one 150 away
                // by far more than their intensities differ.
                assert!(p[4] > 50.0 * p[19], "{} vs {}", p[4], p[19]);
            }
        }
    }
}
