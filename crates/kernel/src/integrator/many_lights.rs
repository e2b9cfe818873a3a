//! One light picked among any number, by what each sends toward the
//! vertex: the light choice of scenes with more lights than the per-vertex
//! pick of `light_choice.rs` keeps (a fog lit by a street of lamps, embers
//! in smoke).
//!
//! The lights at infinity (distant lights and domes) are weighed one by
//! one as an isotropic phase function would scatter their light (a
//! distant light's irradiance over `4 pi`, a dome's mean radiance); the
//! lights in the scene are held by a light tree (`light_tree.rs`), which
//! weighs as one its root's importance over `4 pi` (a bound on what they
//! all send toward the vertex, `I / (4 pi d^2)` for a lone point light) and,
//! once chosen, picks one of them in `log n`. Each of these top-level
//! choices keeps a defensive share `MIN_PROBABILITY / m` of the `m` (the
//! weights know no occlusion); inside the tree a light that sends nothing
//! toward the vertex (behind an area light) is never picked.
//!
//! `uniform` weighs every light alike: the baseline the weighing is
//! measured against (BENCHMARKS.md, "Many lights").

use glam::Vec3;

use super::light_tree::LightTree;
use super::per_light::MIN_PROBABILITY;
use crate::light::{LightBounds, Lights, Whence};
use crate::sampling::UNIFORM_SPHERE_PDF;

/// The weighing of many lights.
#[derive(Clone, Debug)]
pub(crate) struct ManyLights {
    /// How many lights.
    n: usize,
    /// Weigh every light alike.
    uniform: bool,
    /// The lights at infinity with their weights, the same everywhere.
    infinite: Vec<(usize, f32)>,
    /// The lights in the scene.
    tree: Option<LightTree>,
}

impl ManyLights {
    pub fn new(lights: &Lights, uniform: bool) -> Self {
        let infinite = lights
            .at_infinity()
            .iter()
            .map(|&i| {
                let light = lights.get(i as usize);
                let w = match light.whence(Vec3::ZERO) {
                    Whence::Everywhere => light.luminance(),
                    Whence::Toward { .. } => light.luminance() * UNIFORM_SPHERE_PDF,
                };
                (i as usize, w)
            })
            .collect();
        let members: Vec<usize> = (0..lights.len()).collect();
        let tree = if uniform {
            None
        } else {
            LightTree::new(lights, &members)
        };
        Self {
            n: lights.len(),
            uniform,
            infinite,
            tree,
        }
    }

    pub fn len(&self) -> usize {
        self.n
    }

    /// How many top-level choices: the lights at infinity and the tree.
    #[inline]
    fn choices(&self) -> usize {
        self.infinite.len() + usize::from(self.tree.is_some())
    }

    /// The tree's weight at `at`.
    #[inline]
    fn tree_weight(&self, at: Vec3) -> f32 {
        self.tree
            .as_ref()
            .map_or(0.0, |t| t.root().importance(at) * UNIFORM_SPHERE_PDF)
    }

    /// The sum of the top-level weights at `at` (what [`Self::probability`]
    /// and [`Self::pick`] divide by), 0 where it is not finite and positive.
    #[inline]
    pub fn total(&self, at: Vec3) -> f32 {
        if self.uniform {
            return 0.0;
        }
        let total = self.infinite.iter().map(|l| l.1).sum::<f32>() + self.tree_weight(at);
        if total.is_finite() && total > 0.0 {
            total
        } else {
            0.0
        }
    }

    /// The probability of a top-level choice of weight `w`.
    #[inline]
    fn share(&self, w: f32, total: f32) -> f32 {
        let m = self.choices() as f32;
        if total <= 0.0 {
            return 1.0 / m;
        }
        (1.0 - MIN_PROBABILITY) * w / total + MIN_PROBABILITY / m
    }

    /// The probability that a vertex at `at` (with [`Self::total`]
    /// `total`) picks light `i`.
    #[inline]
    pub fn probability(&self, at: Vec3, total: f32, i: usize) -> f32 {
        if self.uniform {
            return 1.0 / self.n as f32;
        }
        if let Some(&(_, w)) = self.infinite.iter().find(|l| l.0 == i) {
            return self.share(w, total);
        }
        match &self.tree {
            Some(tree) if tree.holds(i) => {
                let own = |b: &LightBounds| b.importance_range(at);
                self.share(self.tree_weight(at), total) * tree.probability(own, i)
            }
            _ => 0.0,
        }
    }

    /// The light `u` (uniform in [0, 1)) picks at `at`, with its
    /// probability; `None` where the tree's lights send nothing there.
    #[inline]
    pub fn pick(&self, at: Vec3, total: f32, u: f32) -> Option<(usize, f32)> {
        if self.uniform {
            let i = ((u * self.n as f32) as usize).min(self.n - 1);
            return Some((i, 1.0 / self.n as f32));
        }
        let mut end = 0.0;
        for &(i, w) in &self.infinite {
            let p = self.share(w, total);
            end += p;
            if u < end {
                return Some((i, p));
            }
        }
        let Some(tree) = &self.tree else {
            // Rounding left the sum a little below one.
            return self
                .infinite
                .last()
                .map(|&(i, w)| (i, self.share(w, total)));
        };
        let p = self.share(self.tree_weight(at), total);
        // The rest of the interval, rescaled to [0, 1) for the tree.
        let start = end;
        let u = ((u - start) / p).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let own = |b: &LightBounds| b.importance_range(at);
        tree.pick(own, u).map(|(i, q)| (i, p * q))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{SphereLight, Sun};

    fn street() -> Lights {
        let lamps = (0..20).map(|k| {
            let at = Vec3::new(10.0 * k as f32, 5.0, 0.0);
            SphereLight::new(at, 0.1, Vec3::splat(100.0 + k as f32)).into()
        });
        let sun = Sun::new(Vec3::NEG_Y, Vec3::splat(0.5), 0.0).into();
        Lights::new(lamps.chain([sun]))
    }

    /// The probabilities sum to one, the pick takes each light as often as
    /// its probability says and reports that probability, the sun keeps
    /// its defensive share, and the lamp above the vertex outweighs a far
    /// one by far more than their intensities differ.
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
            assert!(p[20] >= MIN_PROBABILITY / 2.0 * 0.999, "{}", p[20]);
            let n = 200_000;
            let mut counts = vec![0u32; p.len()];
            for k in 0..n {
                let (i, pi) = many.pick(at, total, (k as f32 + 0.5) / n as f32).unwrap();
                assert!((pi - p[i]).abs() <= 1e-6 * p[i], "{pi} vs {}", p[i]);
                counts[i] += 1;
            }
            for (i, (&c, &pi)) in counts.iter().zip(&p).enumerate() {
                let f = c as f32 / n as f32;
                assert!(
                    (f - pi).abs() < 3.0 / n as f32 + 1e-5,
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
