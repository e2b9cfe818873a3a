//! Which lights a vertex's next-event estimation samples.
//!
//! With `all`, every light gets one sample (and one shadow ray) at every
//! vertex. With `one`, a vertex picks one light at random and divides its
//! sample by the probability of the pick, as pbrt-v4's light samplers and
//! Cycles' light tree do: the shadow rays, the larger part of a path's
//! tracking in a cloud lit by a sun and a sky, are halved, at the price of
//! the noise of the pick. Without a shadow grid (below) the pick follows
//! each light's unoccluded in-scattered radiance at the vertex, `E
//! f(w_in, w_light)` for a distant light against a dome's mean radiance
//! (the phase function integrates to 1 over the sphere), so a
//! forward-scattering vertex facing the sun takes the sun and one facing
//! away takes the sky; every light keeps a defensive share of at least
//! `min(MIN_PROBABILITY, 1 / 2n)` of the `n` lights (with two, a
//! probability within [0.05, 0.95]: [`MIN_PROBABILITY`]), so no
//! light is starved where the weights are wrong.
//!
//! [`MIN_PROBABILITY`]: super::per_light::MIN_PROBABILITY
//!
//! The probabilities are laid end to end around the unit interval and one
//! number picks ([`LightChoice::picks`]): each light is sampled with its
//! probability, none where they sum below one, two where a disc's floor
//! (below) lifts them past one.
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

use super::light_sampling::LightSampling;
use super::many_lights::ManyLights;
use super::per_light::{
    into_shares, lane_shares, lanes_of, raise_to_floors, share_of_two, Lanes, Shares,
    MIN_PROBABILITY,
};
pub(crate) use super::per_light::{PerLight, MAX_PICKED_LIGHTS};
use crate::light::{Light, Lights, Whence};
use crate::phase::Phase;
use crate::sampling::UNIFORM_SPHERE_PDF;

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
/// light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum LightChoice {
    /// Every light, once (probability 1 each; no number drawn).
    All,
    /// One light among many, weighed at `at` ([`ManyLights`]), whose
    /// weights sum to `total` there.
    Weighed { at: Vec3, total: f32 },
    /// Each light with its probability. They may sum to less than one
    /// (the vertex then samples no light with the rest) or, where a disc's
    /// floor raised one, to more (it then sometimes samples two).
    Pick(PerLight),
}

/// The light choice of a render: what it weighs each light by, kept flat
/// and built once from the lights (as pbrt-v4's light samplers keep
/// theirs), and the pick at a vertex from it.
#[derive(Clone, Debug)]
pub(crate) struct LightSampler {
    /// `All` or `One`, resolved for the lights.
    sampling: LightSampling,
    /// The lights, up to [`MAX_PICKED_LIGHTS`] (past them the weighing is
    /// `many`'s).
    lights: Vec<Light>,
    /// Per light, the luminance of its strength ([`Light::luminance`]).
    luminance: Vec<f32>,
    /// Per light, a distant light's disc's solid angle (0 for a delta
    /// light or a dome: no floor).
    disc: Vec<f32>,
    /// 1 in the lanes of the lights, 0 past them ([`lane_shares`]).
    lanes: Lanes,
    /// The weighing of lights past [`MAX_PICKED_LIGHTS`], or of any number
    /// picked uniformly.
    many: Option<ManyLights>,
    /// Per light, its weight seen from an isotropic vertex (luminance over
    /// `4 pi` for a distant light), which [`Self::facing`] gives every
    /// light but the one it asks about; empty past [`MAX_PICKED_LIGHTS`].
    isotropic: PerLight,
}

impl LightSampler {
    /// The choice `sampling` (resolved here) makes among `lights`.
    pub fn new(lights: &Lights, sampling: LightSampling) -> Self {
        let disc = lights.iter().map(Light::disc_solid_angle).collect();
        let luminance: Vec<f32> = lights.iter().map(Light::luminance).collect();
        let mut isotropic = PerLight::zeros(lights.len().min(MAX_PICKED_LIGHTS));
        for ((w, l), light) in isotropic.iter_mut().zip(&luminance).zip(lights.iter()) {
            // A light in the scene weighs by where the vertex is, which
            // the estimate does not know.
            *w = match light.whence(Vec3::ZERO) {
                _ if !light.is_at_infinity() => 0.0,
                Whence::Everywhere => *l,
                Whence::Toward { .. } => l * UNIFORM_SPHERE_PDF,
            };
        }
        let sampling = sampling.resolve(lights);
        let many = match sampling {
            LightSampling::Uniform => Some(ManyLights::new(lights, true)),
            LightSampling::One if lights.len() > MAX_PICKED_LIGHTS => {
                Some(ManyLights::new(lights, false))
            }
            _ => None,
        };
        Self {
            sampling,
            many,
            lights: lights.iter().take(MAX_PICKED_LIGHTS).cloned().collect(),
            luminance,
            disc,
            isotropic,
            lanes: lanes_of(lights.len()),
        }
    }

    /// `All` or `One`.
    #[inline]
    pub fn sampling(&self) -> LightSampling {
        self.sampling
    }

    /// Whether vertices pick among a few lights (`one`, and two to
    /// [`MAX_PICKED_LIGHTS`]).
    #[inline]
    fn picks(&self) -> bool {
        self.sampling == LightSampling::One && self.luminance.len() >= 2 && self.many.is_none()
    }

    /// The probability that `choice` samples light `i`.
    #[inline]
    pub fn probability(&self, choice: &LightChoice, i: usize) -> f32 {
        match (choice, &self.many) {
            (LightChoice::All, _) => 1.0,
            (LightChoice::Pick(p), _) => p[i],
            (LightChoice::Weighed { at, total }, Some(many)) => many.probability(*at, *total, i),
            (LightChoice::Weighed { .. }, None) => {
                unreachable!("a weighed pick without its weights")
            }
        }
    }

    /// The probability that a vertex at `at` whose choice is weighed
    /// ([`LightChoice::Weighed`]) samples light `i`; `None` where vertices
    /// do not weigh many lights.
    #[inline]
    pub fn weighed_probability(&self, at: Vec3, i: usize) -> Option<f32> {
        let many = self.many.as_ref()?;
        Some(many.probability(at, many.total(at), i))
    }

    /// The light a weighed pick at `at` samples with `u`, and its
    /// probability.
    #[inline]
    pub fn pick_weighed(&self, at: Vec3, total: f32, u: f32) -> Option<(usize, f32)> {
        self.many
            .as_ref()
            .expect("a weighed pick has its weights")
            .pick(at, total, u)
    }

    /// Light `i`'s unoccluded in-scattered luminance at a vertex at `p`
    /// reached along `dir_in` (`f E` toward a distant light's centre, a
    /// dome's mean radiance: the phase function integrates to 1 over the
    /// sphere; `f I / d^2` toward a sphere light), and the least
    /// probability its disc needs ([`disc_floor`]; 0 for other lights).
    #[inline(always)]
    fn weigh(&self, i: usize, phase: &Phase, p: Vec3, dir_in: Vec3) -> (f32, f32) {
        let light = &self.lights[i];
        let open = light.luminance_at(p, self.luminance[i]);
        match light.whence(p) {
            Whence::Everywhere => (open, 0.0),
            Whence::Toward { dir, .. } => {
                let f = phase.eval(dir_in, dir);
                let disc = self.disc[i];
                let floor = if disc > 0.0 { disc_floor(f, disc) } else { 0.0 };
                (open * f, floor)
            }
        }
    }

    /// [`Self::weigh`] of every light, the weights and the floors apart.
    #[inline(always)]
    fn weigh_all(&self, phase: &Phase, p: Vec3, dir_in: Vec3) -> (PerLight, PerLight) {
        let n = self.luminance.len();
        let (mut open, mut floors) = (PerLight::zeros(n), PerLight::zeros(n));
        for (i, (open, floor)) in open.iter_mut().zip(floors.iter_mut()).enumerate() {
            (*open, *floor) = self.weigh(i, phase, p, dir_in);
        }
        (open, floors)
    }

    /// The pick at a vertex at `at` reached along `dir_in` with phase
    /// function `phase`, each light weighed by its unoccluded in-scattered
    /// light: [`LightChoice::All`] unless the sampling is `one` and there
    /// are lights to choose among.
    #[inline]
    pub fn at(&self, phase: &Phase, at: Vec3, dir_in: Vec3) -> LightChoice {
        if let Some(many) = &self.many {
            return LightChoice::Weighed {
                at,
                total: many.total(at),
            };
        }
        if !self.picks() {
            return LightChoice::All;
        }
        let (mut p, floors) = self.weigh_all(phase, at, dir_in);
        into_shares(&mut p);
        raise_to_floors(&mut p, &floors);
        LightChoice::Pick(p)
    }

    /// The probability that a vertex whose phase function toward distant
    /// light `light`'s centre is `f` samples that light, unoccluded, the
    /// others weighed as from an isotropic vertex (an estimate, for
    /// sunward scattering's keep probability, which only needs to be the
    /// same for both of its strategies).
    #[inline]
    pub fn facing(&self, light: usize, f: f32) -> f32 {
        if let Some(many) = &self.many {
            // Its defensive share: the weights need a position.
            return MIN_PROBABILITY / many.len() as f32;
        }
        if !self.picks() {
            return 1.0;
        }
        let own = self.luminance[light] * f;
        let share = if let [a, b] = *self.isotropic {
            share_of_two(own, if light == 0 { b } else { a })
        } else {
            let mut w = self.isotropic;
            w[light] = own;
            Shares::of(w.iter().copied()).share(own)
        };
        let disc = self.disc[light];
        if disc > 0.0 {
            share.max(disc_floor(f, disc))
        } else {
            share
        }
    }

    /// The pick at a vertex at `at` reached along `dir_in` with phase
    /// function `phase` (`one`), which sees the fractions `seen` of each light's
    /// in-scattered light through the media (a shadow grid's estimate):
    /// the lights weighed by what they bring through the media, and no
    /// light at all, with the remaining probability, where the vertex sees
    /// less than [`TRACE_FRACTION`] of its unoccluded light.
    #[inline]
    pub fn shadowed(&self, seen: &PerLight, phase: &Phase, at: Vec3, dir_in: Vec3) -> LightChoice {
        // Each light's unoccluded light and its disc's floor, then, over
        // the lanes (this runs at every vertex), what each brings through
        // the media and its share.
        let n = self.luminance.len();
        let (open, floors) = self.weigh_all(phase, at, dir_in);
        let (open, seen) = (open.lanes(), seen.lanes());
        let through = [open[0] * seen[0], open[1] * seen[1]];
        let open_total = open[0].element_sum() + open[1].element_sum();
        let seen_total = through[0].element_sum() + through[1].element_sum();
        let trace = seen_total / (TRACE_FRACTION * open_total);
        let trace = if trace.is_finite() {
            trace.clamp(MIN_TRACE, 1.0)
        } else {
            1.0
        };
        // Where the grid sees no light at all, the unoccluded weights.
        let (w, total) = if seen_total > 0.0 {
            (through, seen_total)
        } else {
            (open, open_total)
        };
        let p = lane_shares(w, total, n, self.lanes);
        let floors = floors.lanes();
        let p = [0, 1].map(|k| (p[k] * trace).max(floors[k]));
        LightChoice::Pick(PerLight::from_lanes(p, n))
    }
}

impl LightChoice {
    /// Whether `u` (uniform in [0, 1)) samples light `i`: the lights'
    /// probabilities laid end to end around the unit interval, in list
    /// order, wrapping to its start past one. Each light is sampled with
    /// exactly its probability, and two only where the probabilities sum
    /// past one.
    #[inline]
    pub fn picks(p: &[f32], u: f32) -> impl Iterator<Item = usize> + '_ {
        let mut start = 0.0f32;
        p.iter().enumerate().filter_map(move |(i, &pi)| {
            let (s, e) = (start, start + pi);
            start = if e >= 1.0 { e - 1.0 } else { e };
            ((u >= s && u < e) || u < e - 1.0).then_some(i)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    use super::super::light_grid::LightGrid;
    use crate::env_map::EnvMap;
    use crate::light::{Environment, Sun};
    use crate::spectrum::luminance;

    fn lights() -> Lights {
        Lights::sun_and_sky(
            Some(Sun::new(Vec3::new(0.0, -1.0, 0.0), Vec3::splat(3.0), 0.0)),
            Some(Environment::new(Vec3::splat(0.2))),
        )
    }

    /// The probabilities of a pick (panics for `All`).
    fn probabilities(c: &LightChoice) -> &[f32] {
        match c {
            LightChoice::Pick(p) => p,
            other => panic!("not a pick among a few: {other:?}"),
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
            let c = LightSampler::new(&l, LightSampling::One).at(&phase, Vec3::ZERO, dir_in);
            let p = probabilities(&c);
            assert!((p[0] - expected(dir_in)).abs() < 1e-6, "{label}: {c:?}");
            assert!((p[0] + p[1] - 1.0).abs() < 1e-6, "{label}: {c:?}");
            let facing =
                LightSampler::new(&l, LightSampling::One).facing(0, phase.eval(dir_in, Vec3::Y));
            assert!(
                (facing - p[0]).abs() < 1e-6,
                "{label}: {facing} against {c:?}"
            );
        }
        let away = LightSampler::new(&l, LightSampling::One).at(&phase, Vec3::ZERO, Vec3::NEG_Y);
        let toward = LightSampler::new(&l, LightSampling::One).at(&phase, Vec3::ZERO, Vec3::Y);
        assert!(probabilities(&away)[0] < 0.1, "{away:?}");
        assert!((probabilities(&toward)[0] - (1.0 - MIN_PROBABILITY)).abs() < 1e-6);
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
    /// and two only as often as the probabilities sum past one.
    #[test]
    fn a_pick_samples_each_light_with_its_probability() {
        let cases: [&[f32]; 7] = [
            &[0.3, 0.5],
            &[0.05, 0.0025],
            &[0.8, 0.6],
            &[1.0, 0.2],
            &[0.0, 0.7],
            &[0.2, 0.3, 0.4],
            &[0.9, 0.5, 0.7],
        ];
        for p in cases {
            let n = 100_000;
            let mut counts = vec![0u32; p.len()];
            let mut samples = 0u32;
            for i in 0..n {
                for light in LightChoice::picks(p, (i as f32 + 0.5) / n as f32) {
                    counts[light] += 1;
                    samples += 1;
                }
            }
            for (light, &k) in counts.iter().enumerate() {
                let frac = k as f32 / n as f32;
                assert!(
                    (frac - p[light]).abs() < 1e-4,
                    "{p:?}: light {light} {frac}"
                );
            }
            // A pick never samples one light twice, so the samples per
            // vertex average the probabilities' sum.
            let total: f32 = p.iter().sum();
            assert!((samples as f32 / n as f32 - total).abs() < 1e-4, "{p:?}");
        }
    }

    #[test]
    fn all_or_a_single_light_samples_every_light() {
        let phase = Phase::hg(0.3);
        let l = lights();
        assert_eq!(
            LightSampler::new(&l, LightSampling::All).at(&phase, Vec3::ZERO, Vec3::X),
            LightChoice::All
        );
        assert_eq!(LightSampling::Auto.resolve(&l), LightSampling::One);
        let map = Arc::new(EnvMap::new(2, 1, vec![Vec3::ONE, Vec3::splat(4.0)], 0.0));
        let sun = Sun::new(Vec3::new(0.0, -1.0, 0.0), Vec3::splat(3.0), 0.0);
        let mapped = Lights::sun_and_sky(Some(sun), Some(Environment::from_map(map, Vec3::ONE)));
        assert_eq!(LightSampling::Auto.resolve(&mapped), LightSampling::All);
        assert_eq!(LightSampling::One.resolve(&mapped), LightSampling::One);
        let sun_only = Lights::sun_and_sky(Some(sun), None);
        assert_eq!(LightSampling::Auto.resolve(&sun_only), LightSampling::All);
        assert_eq!(
            LightSampler::new(&sun_only, LightSampling::One).at(&phase, Vec3::ZERO, Vec3::X),
            LightChoice::All
        );
    }

    /// Up to [`MAX_PICKED_LIGHTS`] lights a vertex picks among them, every
    /// one with at least its defensive share; past that it samples every
    /// light.
    #[test]
    fn a_pick_covers_up_to_its_most_lights_and_then_weighs_many() {
        let phase = Phase::hg(0.6);
        let sun = |i: usize| {
            let a = i as f32;
            Light::from(Sun::new(
                Vec3::new(a.cos(), -1.0, a.sin()),
                Vec3::splat(1.0 + a),
                0.0,
            ))
        };
        let sky = || Light::from(Environment::new(Vec3::splat(0.2)));
        let most = Lights::new((0..MAX_PICKED_LIGHTS - 1).map(sun).chain([sky()]));
        assert_eq!(LightSampling::Auto.resolve(&most), LightSampling::One);
        let c = LightSampler::new(&most, LightSampling::Auto).at(&phase, Vec3::ZERO, Vec3::X);
        let p = probabilities(&c);
        assert_eq!(p.len(), MAX_PICKED_LIGHTS);
        let floor = MIN_PROBABILITY.min(0.5 / MAX_PICKED_LIGHTS as f32);
        assert!((p.iter().sum::<f32>() - 1.0).abs() < 1e-5, "{p:?}");
        assert!(p.iter().all(|&p| p >= floor * 0.9999), "{p:?}");
        let too_many = Lights::new((0..MAX_PICKED_LIGHTS).map(sun).chain([sky()]));
        assert_eq!(LightSampling::Auto.resolve(&too_many), LightSampling::One);
        assert!(
            !LightSampling::One.picks_one(&too_many),
            "no shadow grid past the most"
        );
        let sampler = LightSampler::new(&too_many, LightSampling::One);
        let c = sampler.at(&phase, Vec3::ZERO, Vec3::X);
        assert!(matches!(c, LightChoice::Weighed { .. }), "{c:?}");
        let sum: f32 = (0..too_many.len())
            .map(|i| sampler.probability(&c, i))
            .sum();
        assert!((sum - 1.0).abs() < 1e-5, "{sum}");
        let all = LightSampler::new(&too_many, LightSampling::All);
        assert_eq!(all.at(&phase, Vec3::ZERO, Vec3::X), LightChoice::All);
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
        let shadowed = |l: &Lights, grid: &LightGrid, p: Vec3| {
            let sampler = LightSampler::new(l, LightSampling::One);
            let c = sampler.shadowed(&grid.seen(&phase, p, dir_in), &phase, p, dir_in);
            probabilities(&c).to_vec()
        };
        let deep = shadowed(&l, &grid, Vec3::splat(2.0));
        assert!((deep[0] + deep[1] - MIN_TRACE).abs() < 1e-6, "{deep:?}");
        assert!(deep
            .iter()
            .all(|&p| p >= MIN_PROBABILITY * MIN_TRACE * 0.999));
        // The sun shines down (+y is toward it): 0.05 below the top face.
        let top = Vec3::new(2.0, 3.95, 2.0);
        let lit = shadowed(&l, &grid, top);
        assert!((lit[0] + lit[1] - 1.0).abs() < 1e-6, "{lit:?}");
        let seen = grid.in_scatter(&phase, &l, top, dir_in);
        let (sun, sky) = (luminance(seen.group(0)), luminance(seen.group(1)));
        let share = (sun / (sun + sky)).clamp(MIN_PROBABILITY, 1.0 - MIN_PROBABILITY);
        assert!((lit[0] - share).abs() < 1e-5, "{lit:?} against {share}");
        // The unoccluded pick does not see the cube, so it weighs the two
        // lights otherwise.
        let open = LightSampler::new(&l, LightSampling::One).at(&phase, Vec3::ZERO, dir_in);
        assert!(lit[0] != probabilities(&open)[0], "{lit:?} {open:?}");
        let sky_only = Lights::sun_and_sky(None, Some(Environment::new(Vec3::splat(0.2))));
        let grid = cube_grid(&sky_only);
        let deep = shadowed(&sky_only, &grid, Vec3::splat(2.0));
        assert_eq!(deep.len(), 1);
        assert!((deep[0] - MIN_TRACE).abs() < 1e-6, "{deep:?}");
        let edge = shadowed(&sky_only, &grid, top);
        assert!(edge[0] > 10.0 * MIN_TRACE && edge[0] <= 1.0, "{edge:?}");
    }
}
