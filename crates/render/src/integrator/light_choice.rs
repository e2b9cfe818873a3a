//! Which lights a vertex's next-event estimation samples.
//!
//! With `all`, every light gets one sample (and one shadow ray) at every
//! vertex. With `one`, a vertex picks one light at random and divides its
//! sample by the probability of the pick, as pbrt-v4's light samplers and
//! Cycles' light tree do: the shadow rays, the larger part of a path's
//! tracking in a cloud lit by a sun and a sky, are halved, at the price of
//! the noise of the pick. The pick follows each light's unoccluded
//! in-scattered radiance at the vertex, `E_sun f(w_in, w_sun)` against the
//! sky's mean radiance (the phase function integrates to 1 over the
//! sphere), so a forward-scattering vertex facing the sun takes the sun and
//! one facing away takes the sky; a probability is kept within
//! [`MIN_PROBABILITY`, 1 - `MIN_PROBABILITY`] so neither light's weight
//! exceeds `1 / MIN_PROBABILITY`.
//!
//! `auto` (the default) picks one light where that was measured to pay, a
//! sun beside a constant sky (1.25-1.35x the efficiency of `all` on the
//! corpus cloud, thin and thick: BENCHMARKS.md, "One light per vertex"),
//! and samples every light under an HDR map, whose hot texels divided by
//! a small pick probability make fireflies that were not measured away.
//!
//! A phase-sampled ray that escapes to a light is weighed against that
//! light's next-event samples by the power heuristic with the light's
//! density times its pick probability (Veach 1997, section 9.2.4, with the
//! selection folded into the light strategy's density), so the two
//! strategies' weights still sum to one.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::guiding::luminance;
use crate::light::Lights;
use crate::phase::Phase;

/// How many lights next-event estimation samples at each vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum LightSampling {
    /// `one` under a sun and a constant sky, `all` otherwise.
    #[default]
    Auto,
    /// Every light, one sample each.
    All,
    /// One light, picked in proportion to its unoccluded in-scattered
    /// radiance at the vertex.
    One,
}

impl LightSampling {
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::All => "all",
            Self::One => "one",
        }
    }

    /// What `self` comes to under `lights`: `All` or `One`.
    pub fn resolve(self, lights: &Lights) -> LightSampling {
        match self {
            Self::Auto if lights.environment.as_ref().is_some_and(|e| e.map.is_none()) => Self::One,
            Self::Auto => Self::All,
            other => other,
        }
    }
}

/// A pick probability is at least this.
pub const MIN_PROBABILITY: f32 = 0.05;

/// The probability that a vertex's next-event estimation samples each
/// light (1 for both under `all`: each light is sampled once).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LightChoice {
    pub sun: f32,
    pub sky: f32,
}

impl LightChoice {
    /// Every light sampled.
    pub const ALL: LightChoice = LightChoice { sun: 1.0, sky: 1.0 };

    /// The pick at a vertex reached along `dir_in` with phase function
    /// `phase`: [`Self::ALL`] unless `sampling` is `one` (resolved, see
    /// [`LightSampling::resolve`]) and both a sun and a sky light the scene.
    pub fn at(sampling: LightSampling, lights: &Lights, phase: &Phase, dir_in: Vec3) -> Self {
        match &lights.sun {
            Some(sun) => Self::facing_sun(sampling, lights, phase.eval(dir_in, -sun.direction())),
            None => Self::ALL,
        }
    }

    /// The pick at a vertex whose phase function toward the sun's centre
    /// is `f_sun`.
    pub fn facing_sun(sampling: LightSampling, lights: &Lights, f_sun: f32) -> Self {
        let (Some(sun), Some(env), LightSampling::One) =
            (&lights.sun, &lights.environment, sampling)
        else {
            return Self::ALL;
        };
        let sun_light = luminance(sun.irradiance()) * f_sun;
        let sky_light = luminance(env.mean_radiance());
        let p = sun_light / (sun_light + sky_light);
        let p = if p.is_finite() { p } else { 0.5 };
        let p = p.clamp(MIN_PROBABILITY, 1.0 - MIN_PROBABILITY);
        LightChoice {
            sun: p,
            sky: 1.0 - p,
        }
    }

    /// Whether this samples every light (no pick to draw).
    #[inline]
    pub fn is_all(self) -> bool {
        self == Self::ALL
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    use crate::env_map::EnvMap;
    use crate::light::{Environment, Sun};

    fn lights() -> Lights {
        Lights {
            sun: Some(Sun::new(Vec3::new(0.0, -1.0, 0.0), Vec3::splat(3.0), 0.0)),
            environment: Some(Environment::new(Vec3::splat(0.2))),
        }
    }

    #[test]
    fn the_pick_follows_the_phase_toward_the_sun_within_its_bounds() {
        let phase = Phase::hg(0.8);
        let l = lights();
        // The sun's unoccluded light, 3 f(w_in, up), against the sky's 0.2.
        let expected = |dir_in: Vec3| {
            let sun = 3.0 * phase.eval(dir_in, Vec3::Y);
            (sun / (sun + 0.2)).clamp(MIN_PROBABILITY, 1.0 - MIN_PROBABILITY)
        };
        for (dir_in, label) in [
            // Travelling down, as the sunlight does: the sun is behind.
            (Vec3::NEG_Y, "away"),
            // Travelling up, toward the sun: strongly forward.
            (Vec3::Y, "toward"),
            (Vec3::X, "side"),
            (Vec3::new(0.3, 0.5, -0.2).normalize(), "oblique"),
        ] {
            let c = LightChoice::at(LightSampling::One, &l, &phase, dir_in);
            assert!((c.sun - expected(dir_in)).abs() < 1e-6, "{label}: {c:?}");
            assert!((c.sun + c.sky - 1.0).abs() < 1e-6, "{label}: {c:?}");
        }
        let away = LightChoice::at(LightSampling::One, &l, &phase, Vec3::NEG_Y);
        let toward = LightChoice::at(LightSampling::One, &l, &phase, Vec3::Y);
        assert!(away.sun < 0.1, "{away:?}");
        assert_eq!(toward.sun, 1.0 - MIN_PROBABILITY);
    }

    #[test]
    fn all_or_a_single_light_samples_every_light() {
        let phase = Phase::hg(0.3);
        let l = lights();
        assert!(LightChoice::at(LightSampling::All, &l, &phase, Vec3::X).is_all());
        assert_eq!(LightSampling::Auto.resolve(&l), LightSampling::One);
        let map = Arc::new(EnvMap::new(2, 1, vec![Vec3::ONE, Vec3::splat(4.0)], 0.0));
        let mapped = Lights {
            environment: Some(Environment::from_map(map, Vec3::ONE)),
            ..l.clone()
        };
        assert_eq!(LightSampling::Auto.resolve(&mapped), LightSampling::All);
        assert_eq!(LightSampling::One.resolve(&mapped), LightSampling::One);
        let sun_only = Lights {
            environment: None,
            ..l.clone()
        };
        assert!(LightChoice::at(LightSampling::One, &sun_only, &phase, Vec3::X).is_all());
    }
}
