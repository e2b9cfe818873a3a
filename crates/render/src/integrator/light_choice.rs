//! Which lights a vertex's next-event estimation samples.
//!
//! With `all`, every light gets one sample (and one shadow ray) at every
//! vertex. With `one`, a vertex picks one light at random and divides its
//! sample by the probability of the pick, as pbrt-v4's light samplers and
//! Cycles' light tree do: the shadow rays, the larger part of a path's
//! tracking in a cloud lit by a sun and a sky, are halved, at the price of
//! the noise of the pick. Without a shadow grid (below) the pick follows
//! each light's unoccluded in-scattered radiance at the vertex, `E_sun
//! f(w_in, w_sun)` against the sky's mean radiance (the phase function
//! integrates to 1 over the sphere), so a forward-scattering vertex facing
//! the sun takes the sun and one facing away takes the sky; a probability
//! is kept within [`MIN_PROBABILITY`, 1 - `MIN_PROBABILITY`] so neither
//! light's weight exceeds `1 / MIN_PROBABILITY`.
//!
//! Through the media: inside a thick cloud nine in ten shadow rays bring
//! nothing back (measured on the thick benchmark cloud: the sun's and the
//! sky's alike). So a render gives the pick a coarse grid of each light's
//! transmittance ([`LightGrid::for_light_choice`](super::light_grid::LightGrid::for_light_choice)): the lights are
//! weighed by their in-scattered radiance seen through the media, and a
//! vertex that expects less than [`TRACE_FRACTION`] of its unoccluded
//! light traces a shadow ray only with probability in proportion (at least
//! [`MIN_TRACE`]), the pick's probabilities then summing to less than one.
//! Any probabilities are exact so long as every weight uses them: the
//! grid only moves the noise, never the mean.
//!
//! `auto` (the default) picks one light where that was measured to pay, a
//! constant sky with or without a sun (1.25-1.35x the efficiency of `all`
//! on the corpus cloud under both, thin and thick, and the shadow grid
//! 1.14-1.8x more: BENCHMARKS.md, "One light per vertex"),
//! and samples every light under an HDR map, whose hot texels divided by
//! a small pick probability make fireflies that were not measured away.
//!
//! A phase-sampled ray that escapes to a light is weighed against that
//! light's next-event samples by the power heuristic with the light's
//! density times its pick probability (Veach 1997, section 9.2.4, with the
//! selection folded into the light strategy's density), so the two
//! strategies' weights still sum to one.

use glam::Vec3;

use super::light_grid::Seen;
use crate::light::Lights;
use crate::phase::Phase;
use crate::spectrum::luminance;

settings_enum! {
    /// How many lights next-event estimation samples at each vertex.
    pub enum LightSampling {
        /// `one` under a constant sky (with or without a sun), `all` otherwise.
        #[default]
        Auto = "auto",
        /// Every light, one sample each.
        All = "all",
        /// One light (or, deep in the media, most often none), picked in
        /// proportion to its in-scattered radiance at the vertex seen through
        /// the media.
        One = "one",
    }
}

impl LightSampling {
    /// Whether a vertex picks one light under `lights` (pruned of the dark
    /// ones): `one`, resolved, with a sun or a sky to pick.
    pub fn picks_one(self, lights: &Lights) -> bool {
        self.resolve(lights) == Self::One && (lights.sun.is_some() || lights.environment.is_some())
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

/// A vertex whose lights, seen through the media, bring at least this
/// fraction of their unoccluded in-scattered radiance always traces a
/// shadow ray; one that expects less traces in proportion. Measured at 64
/// spp (BENCHMARKS.md, "One light per vertex"): 0.1 and 0.3 alike, 1 lost
/// 1.5x on a thinner cloud (too many lit vertices left without light).
pub const TRACE_FRACTION: f32 = 0.3;

/// ... and every vertex traces with at least this probability, so that
/// where the coarse shadow grid is wrong a traced sample's weight stays
/// at most 20x.
pub const MIN_TRACE: f32 = 0.05;

/// The sun's pick probability is at least `DISC_MIS * sqrt(f * solid_angle)`
/// where the vertex's phase function toward it is `f`, for a sun with a
/// disc. A phase-sampled ray escaping into the disc carries the disc's
/// radiance `E / solid_angle` times its power-heuristic weight against
/// next-event estimation, `f^2 / (f^2 + (pick / solid_angle)^2)`, at most
/// `(f solid_angle / pick)^2`; with the floor, that is at most
/// `f E / DISC_MIS^2`, a quarter of the sun's unoccluded next-event value.
/// Without it, a vertex that the shadow grid takes for dark picks the sun
/// rarely, and the rare phase-sampled escape into a 0.5 degree disc (its
/// radiance the irradiance over 7e-5 sr), behind the narrow forward peak
/// of a Mie phase function, carried a back-lit cloud's light in single
/// samples of thousands. Under Henyey-Greenstein g 0.8 the floor is at
/// most 0.03 (a delta sun, which no ray can hit, has none), so a thick
/// cloud keeps most of its skipped shadow rays.
pub const DISC_MIS: f32 = 2.0;

/// [`DISC_MIS`]'s floor for a sun of `solid_angle` seen with phase `f`.
#[inline]
pub fn disc_floor(f: f32, solid_angle: f32) -> f32 {
    let floor = DISC_MIS * (f * solid_angle).sqrt();
    if floor.is_finite() {
        floor.min(1.0)
    } else {
        1.0
    }
}

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
        .with_disc_floor(lights, f_sun)
    }

    /// The pick at a vertex reached along `dir_in` with phase function
    /// `phase` (`one`: a sun, a sky or both), which sees the fractions
    /// `seen` of each light's in-scattered radiance through the media (a
    /// shadow grid's estimate); and no light at all, with the remaining
    /// probability, where it sees less than [`TRACE_FRACTION`] of the
    /// unoccluded light.
    pub fn shadowed(lights: &Lights, seen: Seen, phase: &Phase, dir_in: Vec3) -> Self {
        let f_sun = lights
            .sun
            .as_ref()
            .map_or(0.0, |sun| phase.eval(dir_in, -sun.direction()));
        let sun_open = lights
            .sun
            .as_ref()
            .map_or(0.0, |sun| luminance(sun.irradiance()) * f_sun);
        let sky_open = lights
            .environment
            .as_ref()
            .map_or(0.0, |env| luminance(env.mean_radiance()));
        let (sun_seen, sky_seen) = (sun_open * seen.sun, sky_open * seen.sky);
        let trace = (sun_seen + sky_seen) / (TRACE_FRACTION * (sun_open + sky_open));
        let trace = if trace.is_finite() {
            trace.clamp(MIN_TRACE, 1.0)
        } else {
            1.0
        };
        let p_sun = match (&lights.sun, &lights.environment) {
            (Some(_), Some(_)) => {
                let p_sun = if sun_seen + sky_seen > 0.0 {
                    sun_seen / (sun_seen + sky_seen)
                } else {
                    sun_open / (sun_open + sky_open)
                };
                let p_sun = if p_sun.is_finite() { p_sun } else { 0.5 };
                p_sun.clamp(MIN_PROBABILITY, 1.0 - MIN_PROBABILITY)
            }
            (Some(_), None) => 1.0,
            _ => 0.0,
        };
        LightChoice {
            sun: trace * p_sun,
            sky: trace * (1.0 - p_sun),
        }
        .with_disc_floor(lights, f_sun)
    }

    /// The pick with the sun's probability raised to
    /// [`disc_floor`] where its disc would otherwise be left to phase
    /// sampling (the sky's probability unchanged: where the two then sum
    /// past one, a vertex sometimes samples both).
    fn with_disc_floor(self, lights: &Lights, f_sun: f32) -> Self {
        let floor = lights
            .sun
            .as_ref()
            .map_or(0.0, |sun| disc_floor(f_sun, sun.solid_angle()));
        LightChoice {
            sun: self.sun.max(floor),
            ..self
        }
    }

    /// Which lights a vertex samples, from one uniform number `u`: the sun
    /// below `sun`, the sky over the next `sky` of the unit interval,
    /// wrapping around to its start where the two sum past one (so each
    /// is sampled with exactly its probability, and never both while they
    /// sum to one or less).
    #[inline]
    pub fn picks(self, u: f32) -> (bool, bool) {
        let sun = u < self.sun;
        let end = self.sun + self.sky;
        let sky = (u >= self.sun && u < end) || u < end - 1.0;
        (sun, sky)
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

    use super::super::light_grid::LightGrid;
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

    /// With the floor, a phase-sampled ray escaping into the sun's disc
    /// never carries more than `f E / DISC_MIS^2` (its radiance times its
    /// power-heuristic weight), at any phase value and disc size; a delta
    /// sun has no floor.
    #[test]
    fn an_escape_into_the_disc_carries_at_most_a_quarter_of_the_suns_value() {
        for degrees in [0.1f32, 0.53, 2.0, 10.0] {
            let sun = Sun::new(Vec3::NEG_Y, Vec3::ONE, degrees.to_radians());
            let omega = sun.solid_angle();
            for f in [0.01f32, 0.3, 3.6, 100.0, 2700.0, 1e6] {
                let pick = disc_floor(f, omega);
                assert!(pick > 0.0 && pick <= 1.0, "{degrees} deg, f {f}: {pick}");
                let w = crate::sampling::power_heuristic(f, pick / omega);
                let carried = w / omega;
                assert!(
                    carried <= f / (DISC_MIS * DISC_MIS) * 1.0001 || pick == 1.0,
                    "{degrees} deg, f {f}: pick {pick} carries {carried}"
                );
            }
        }
        let delta = Sun::new(Vec3::NEG_Y, Vec3::ONE, 0.0);
        assert_eq!(disc_floor(2700.0, delta.solid_angle()), 0.0);
    }

    /// One uniform number picks each light with exactly its probability,
    /// and both only where the probabilities sum past one.
    #[test]
    fn a_pick_samples_each_light_with_its_probability() {
        for (sun, sky) in [
            (0.3f32, 0.5f32),
            (0.05, 0.0025),
            (0.8, 0.6),
            (1.0, 0.2),
            (0.0, 0.7),
        ] {
            let choice = LightChoice { sun, sky };
            let n = 100_000;
            let (mut suns, mut skies, mut both) = (0, 0, 0);
            for i in 0..n {
                let (a, b) = choice.picks((i as f32 + 0.5) / n as f32);
                suns += u32::from(a);
                skies += u32::from(b);
                both += u32::from(a && b);
            }
            let frac = |k: u32| k as f32 / n as f32;
            assert!(
                (frac(suns) - sun).abs() < 1e-4,
                "{choice:?}: sun {}",
                frac(suns)
            );
            assert!(
                (frac(skies) - sky).abs() < 1e-4,
                "{choice:?}: sky {}",
                frac(skies)
            );
            let overlap = (sun + sky - 1.0).max(0.0);
            assert!(
                (frac(both) - overlap).abs() < 1e-4,
                "{choice:?}: both {}",
                frac(both)
            );
        }
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

    /// A cube of uniform density 4 over [0, 4]^3 (optical depth 16 across),
    /// its shadow grid under `lights`.
    fn cube_grid(lights: &Lights) -> LightGrid {
        use crate::medium::{GridField, Medium};
        let field = GridField::from_fn([32; 3], Vec3::splat(0.0625), 0.125, 4, |_, _, _| 1.0);
        let cube = crate::volumes::Volumes::from(Medium::new(field, 4.0, Vec3::splat(0.9), 0.5));
        LightGrid::for_light_choice(&cube, lights)
    }

    /// Deep in the cube a vertex traces a shadow ray with the least
    /// probability; just under the sunlit face, always, with the sun
    /// weighed by the light the grid sees there; and with one light, that
    /// light alone, as often as the grid says.
    #[test]
    fn the_shadowed_pick_traces_where_the_grid_sees_light() {
        let l = lights();
        let grid = cube_grid(&l);
        let phase = Phase::hg(0.5);
        let dir_in = Vec3::new(0.3, 0.5, -0.2).normalize();
        let deep = LightChoice::shadowed(
            &l,
            grid.seen(&phase, Vec3::splat(2.0), dir_in),
            &phase,
            dir_in,
        );
        assert!((deep.sun + deep.sky - MIN_TRACE).abs() < 1e-6, "{deep:?}");
        assert!(deep.sun >= MIN_PROBABILITY * MIN_TRACE && deep.sky >= MIN_PROBABILITY * MIN_TRACE);
        // The sun shines down (+y is toward it): 0.05 below the top face.
        let top = Vec3::new(2.0, 3.95, 2.0);
        let lit = LightChoice::shadowed(&l, grid.seen(&phase, top, dir_in), &phase, dir_in);
        assert!((lit.sun + lit.sky - 1.0).abs() < 1e-6, "{lit:?}");
        let seen = grid.in_scatter(&phase, &l, top, dir_in);
        let share = luminance(seen.sun) / (luminance(seen.sun) + luminance(seen.sky));
        let share = share.clamp(MIN_PROBABILITY, 1.0 - MIN_PROBABILITY);
        assert!((lit.sun - share).abs() < 1e-5, "{lit:?} against {share}");
        // The unoccluded pick does not see the cube, so it weighs the two
        // lights otherwise.
        let open = LightChoice::at(LightSampling::One, &l, &phase, dir_in);
        assert!(lit.sun != open.sun, "{lit:?} {open:?}");
        let sky_only = Lights {
            sun: None,
            ..l.clone()
        };
        let grid = cube_grid(&sky_only);
        let deep = LightChoice::shadowed(
            &sky_only,
            grid.seen(&phase, Vec3::splat(2.0), dir_in),
            &phase,
            dir_in,
        );
        assert_eq!(deep.sun, 0.0);
        assert!((deep.sky - MIN_TRACE).abs() < 1e-6, "{deep:?}");
        let edge = LightChoice::shadowed(&sky_only, grid.seen(&phase, top, dir_in), &phase, dir_in);
        assert_eq!(edge.sun, 0.0);
        assert!(edge.sky > 10.0 * MIN_TRACE && edge.sky <= 1.0, "{edge:?}");
    }
}
