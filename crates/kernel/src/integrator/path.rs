//! Volumetric path tracing: the path loop (`path.rs`), the free flight
//! past sphere lights (`path_flight.rs`), equi-angular sampling toward
//! them (`path_equiangular.rs`), next-event estimation (`path_light.rs`)
//! and sunward scattering (`path_sunward.rs`).

use glam::Vec3;

use super::distance_sampling::DistanceSampling;
use super::light_choice::{LightChoice, LightSampler, PerLight};
use super::light_grid::LightGrid;
use super::light_sampling::LightSampling;
use super::path_equiangular::PointPick;
use super::path_state::{Arrival, At, Escape, Path, Vertex};
use super::sunward_mode::Sunward;
use super::{escaped_radiance, AovSample, CameraSampler, Sample};
use crate::counters::Counters;
use crate::light::GroupRadiance;
use crate::light::{Light, Lights, Sun};
use crate::medium::{Interaction, Media};
use crate::phase::Phase;
use crate::ray::Ray;
use crate::sampling::{Draw, Rng, SampleStream};
use crate::spectrum::luminance;
use crate::spectrum::Spectrum;
use crate::tracking::{FreeFlight, TransmittanceEstimator};

/// Russian roulette on path throughput starts after this many scattering
/// events...
pub const ROULETTE_MIN_DEPTH: u32 = 3;
/// ...and only once the largest throughput channel falls below this
/// (Hofmann et al. 2021's renderer uses 0.1). The path then survives with
/// probability equal to that channel and is divided by it.
pub const ROULETTE_THROUGHPUT: f32 = 0.1;

/// Unbiased volumetric path tracer.
///
/// - Free flights by delta tracking over the field's majorant segments.
/// - At a real collision the path always scatters and its throughput is
///   multiplied by the albedo (the expected-value form of absorption; no
///   absorption events). This is lower variance than stochastic absorption
///   and a coloured albedo comes for free; Russian roulette does the
///   terminating instead.
/// - Next-event estimation at every scattering event: one sample of each
///   light, or of one picked at random ([`LightSampling`]; weighed through
///   the media by a shadow grid where one is given, and then sometimes
///   none), each
///   shadow ray's transmittance estimated by the chosen estimator. Directions from a
///   light sampler and from phase sampling are combined with the power
///   heuristic (Veach 1997); a delta sun gets NEE only. At the last
///   allowed scattering event NEE takes weight 1 and the path stops, since
///   the phase-sampled continuation could only reach lights at infinity;
///   unless the media emit, when it goes on to collect emission only.
/// - `max_depth` counts scattering events: 0 shows only the environment
///   through the volume's transmittance, 1 is single scattering, `None`
///   is unlimited.
/// - Several media: albedo and phase function are those of the instance
///   chosen at the collision ([`Media::interaction`]).
/// - Alpha is the track-length estimate of `1 - T` along the camera ray:
///   1 if its first free flight collides, else 0 (for chromatic media,
///   else `1 - avg(beta)` with the escape weights, unbiased for the
///   channels' mean `1 - T`).
/// - Chromatic media (extinction per channel) are traced with `Vec3` as
///   the [`Spectrum`]: spectral tracking for free flights and per-channel
///   ratio tracking for shadow rays; their weights go into `beta`, and
///   the instance weight of [`Interaction`](crate::medium::Interaction)
///   corrects the mixture per channel. Grey media are traced with `f32`,
///   the scalar trackers.
/// - Numbers: each path vertex draws its free-flight distance, light
///   directions, shadow rays' first optical depths, phase direction and
///   roulette as the [`Draw`]s of [`crate::sampling`]'s allocation
///   (Sobol points for the first vertices); the rest from the hashed stream.
/// - Directions: the phase function's, sampled exactly (its density is
///   its value), so NEE's MIS weights and escaped light's take it.
/// - Sunward scattering ([`Sunward`], `path_sunward.rs`): at a vertex
///   with a forward-peaked phase function under a distant light (the
///   brightest, where there are several), a second direction drawn from
///   the phase lobe about that light gathers its light at its collision,
///   weighed by MIS against the light's next-event estimate at the path's
///   own next vertex (which takes the complementary weight).
/// - Emission: at every real collision, with the instance chosen with
///   probability `sigma_t,i / sigma_t` ([`Media::interaction`]), the
///   path adds `beta * (1 - albedo_i) * Le_i`. Delta tracking samples the
///   collision with density `sigma_t T`, so this estimates
///   `integral of T * sigma_a * Le` (the source term of the RTE), exactly
///   as the albedo weight estimates the scattering term. Added before the
///   depth test: emission is not a scattering event, so `max_depth` 0 shows
///   the emitted light seen through the volume.
pub struct PathTracer<'a, M> {
    pub(super) medium: &'a M,
    pub(super) lights: Lights,
    pub(super) estimator: TransmittanceEstimator,
    pub(super) max_depth: Option<u32>,
    chromatic: bool,
    /// The indices of the lights rays can meet, balls and area lights
    /// (`path_flight.rs`).
    pub(super) surfaces: Vec<usize>,
    /// The indices of the point-like lights (balls, points and spots),
    /// which equi-angular sampling aims at.
    pub(super) points: Vec<usize>,
    /// The pick of one of them for a segment's equi-angular sample.
    pub(super) point_pick: PointPick,
    /// Whether segments take an equi-angular sample toward them
    /// (`path_equiangular.rs`).
    pub(super) equiangular: bool,
    /// Tag contributions with their light groups (off: `Sample::groups`
    /// stays zero and costs nothing).
    pub(super) light_groups: bool,
    /// Which lights each vertex samples ([`LightSampling`]).
    pub(super) sampler: LightSampler,
    /// Where the next vertex's sunlight is gathered by sunward scattering
    /// as well ([`Sunward`]).
    pub(super) sunward: Sunward,
    /// The distant light sunward scattering draws toward: the brightest.
    pub(super) sunward_light: Option<usize>,
    /// Each light's transmittance through the media, which the light
    /// choice weighs lights by (`light_choice.rs`).
    pub(super) shadows: Option<&'a LightGrid>,
}

impl<'a, M: Media> PathTracer<'a, M> {
    pub fn new(
        medium: &'a M,
        lights: Lights,
        estimator: TransmittanceEstimator,
        max_depth: Option<u32>,
    ) -> Self {
        let lights = lights.pruned();
        let of = |keep: fn(&Light) -> bool| -> Vec<usize> {
            (0..lights.len()).filter(|&i| keep(lights.get(i))).collect()
        };
        let surfaces = of(Light::is_surface);
        let points = of(|l| l.point_centre().is_some());
        let point_pick = PointPick::new(&lights, &points, false);
        let equiangular =
            !points.is_empty() && DistanceSampling::default().samples_equiangular(medium);
        // The first of the brightest, where several are alike.
        let sunward_light = lights
            .distant()
            .map(|(i, sun)| (i, luminance(sun.irradiance())))
            .reduce(|best, next| if next.1 > best.1 { next } else { best })
            .map(|(i, _)| i);
        Self {
            medium,
            surfaces,
            points,
            point_pick,
            equiangular,
            sunward_light,
            sampler: LightSampler::new(&lights, LightSampling::default()),
            lights,
            estimator,
            max_depth,
            chromatic: medium.chromatic(),
            light_groups: false,
            sunward: Sunward::default(),
            shadows: None,
        }
    }

    /// Picks the light at each vertex with its transmittance from `grid`
    /// ([`LightGrid::for_light_choice`]) where one light is picked.
    pub fn with_shadows(self, grid: Option<&'a LightGrid>) -> Self {
        Self {
            shadows: grid,
            ..self
        }
    }

    /// How many lights each vertex samples, `auto` resolved for this
    /// tracer's lights.
    pub fn light_sampling(&self) -> LightSampling {
        self.sampler.sampling()
    }

    /// What the vertex at `p`, reached along `dir_in`, sees of each light
    /// through the media, where a shadow grid is given.
    #[inline]
    pub(super) fn seen(&self, phase: &Phase, p: Vec3, dir_in: Vec3) -> Option<PerLight> {
        self.shadows.map(|grid| grid.seen(phase, p, dir_in))
    }

    /// Which lights a vertex at `p` reached along `dir_in`, which sees
    /// `seen` ([`Self::seen`]), samples.
    #[inline]
    pub(super) fn light_choice(
        &self,
        phase: &Phase,
        p: Vec3,
        dir_in: Vec3,
        seen: Option<&PerLight>,
    ) -> LightChoice {
        match seen {
            Some(seen) if self.sampler.sampling() == LightSampling::One => {
                self.sampler.shadowed(seen, phase, p, dir_in)
            }
            _ => self.sampler.at(phase, p, dir_in),
        }
    }

    /// Splits each sample's radiance into light groups as well.
    pub fn with_light_groups(self, light_groups: bool) -> Self {
        Self {
            light_groups,
            ..self
        }
    }

    /// Samples every light at each vertex, or one ([`LightSampling`]).
    /// (`uniform` picks the equi-angular sample's light uniformly too.)
    pub fn with_light_sampling(self, light_sampling: LightSampling) -> Self {
        let uniform = light_sampling == LightSampling::Uniform;
        Self {
            sampler: LightSampler::new(&self.lights, light_sampling),
            point_pick: PointPick::new(&self.lights, &self.points, uniform),
            ..self
        }
    }

    /// Samples distances along segments as `sampling` says (equi-angular
    /// sampling only where there are sphere lights).
    pub fn with_distance_sampling(self, sampling: DistanceSampling) -> Self {
        Self {
            equiangular: !self.points.is_empty() && sampling.samples_equiangular(self.medium),
            ..self
        }
    }

    /// Gathers the next vertex's sunlight by sunward scattering as well
    /// where `sunward` says.
    pub fn with_sunward(self, sunward: Sunward) -> Self {
        Self { sunward, ..self }
    }

    /// The distant light sunward scattering draws toward, with its index.
    #[inline]
    pub(super) fn sunward_sun(&self) -> Option<(usize, &Sun)> {
        let i = self.sunward_light?;
        Some((i, self.lights.get(i).as_distant()?))
    }
}

impl<M: Media> CameraSampler for PathTracer<'_, M> {
    fn sample(&self, camera_ray: Ray, rng: &mut Rng, c: &mut Counters) -> Sample {
        let mut draws = SampleStream::random(rng.clone());
        let out = self.sample_stream(camera_ray, &mut draws, c);
        *rng = draws.into_rng();
        out
    }

    fn sample_stream(&self, camera_ray: Ray, draws: &mut SampleStream, c: &mut Counters) -> Sample {
        if self.chromatic {
            self.trace::<Vec3>(camera_ray, draws, c)
        } else {
            self.trace::<f32>(camera_ray, draws, c)
        }
    }
}

impl<M: Media> PathTracer<'_, M> {
    /// One camera path, tracked per channel of `S`, until it ends.
    fn trace<S: Spectrum>(
        &self,
        camera_ray: Ray,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> Sample {
        c.paths += 1;
        let mut path = Path {
            ray: camera_ray,
            beta: Vec3::ONE,
            depth: 0,
            escape: Escape::Full,
            emission_only: false,
            arrival: Arrival::default(),
            out: Sample {
                radiance: Vec3::ZERO,
                alpha: 0.0,
                aov: AovSample::default(),
                groups: GroupRadiance::default(),
            },
        };
        loop {
            // This free flight and the events at its collision are path
            // vertex `path.depth` of the draw allocation.
            let vertex = path.depth;
            if self.equiangular && self.equiangular_runs(&path) {
                self.equiangular::<S>(&mut path, draws, c);
            }
            let flight = self.fly::<S>(&mut path, vertex, draws, c);
            if path.depth == 0 {
                path.out.alpha = match flight {
                    FreeFlight::Escaped => S::escaped_alpha(path.beta),
                    _ => 1.0,
                };
            }
            let t = match flight {
                FreeFlight::Escaped => {
                    self.escape(&mut path, c);
                    break;
                }
                FreeFlight::Capped => break,
                FreeFlight::Collision { t } => t,
            };
            let Some(at) = self.collide::<S>(&mut path, t, vertex, draws, c) else {
                break;
            };
            if !self.scatter_from::<S>(&mut path, &at, draws, c) {
                break;
            }
        }
        path.out
    }

    /// The path left the media: the lights at infinity it reaches.
    fn escape(&self, path: &mut Path, c: &mut Counters) {
        // A camera ray ended by a depth holdout: what lies behind the
        // held-out geometry, the sky included, never shows.
        let pdf = match &path.escape {
            _ if path.emission_only || path.ray.t_max.is_finite() => return,
            Escape::Full => None,
            Escape::Mis(pdf, choice) => Some((*pdf, choice, &self.sampler)),
        };
        let parts = escaped_radiance(&self.lights, path.ray.dir, pdf, c);
        let e = path.beta * parts.total();
        path.add(e, &parts, self.light_groups);
        if path.depth == 1 {
            path.out.aov.direct += e;
        }
    }

    /// The events at a real collision at `t` up to scattering: the
    /// interaction, emission and the albedo. Returns the scattering vertex,
    /// or `None` when the path ends there.
    fn collide<'m, S: Spectrum>(
        &'m self,
        path: &mut Path,
        t: f32,
        vertex: u32,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> Option<At<'m>> {
        let p = path.ray.at(t);
        let it = self.medium.interaction(p, path.ray.time, draws.rng());
        if S::CHROMATIC {
            path.beta *= it.weight;
        }
        if path.depth == 0 {
            // A holdout volume seen first is a matte: no light, no alpha.
            if it.holdout {
                path.out.alpha = 0.0;
                return None;
            }
            let aov = &mut path.out.aov;
            aov.albedo = it.albedo;
            aov.depth = Some(t);
            aov.instance = Some(it.instance);
        }
        if self.medium.emits() {
            self.emit(path, p, &it, c);
        }
        if self.max_depth == Some(path.depth) {
            return None;
        }
        path.depth += 1;
        path.beta *= it.albedo;
        if path.beta.max_element() <= 0.0 {
            return None;
        }
        Some(At {
            p,
            phase: it.phase,
            vertex,
        })
    }

    /// The events at scattering vertex `at`: next-event estimation, the
    /// scattered direction and roulette. Returns false when the path ends
    /// there.
    fn scatter_from<S: Spectrum>(
        &self,
        path: &mut Path,
        at: &At,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> bool {
        let (p, vertex) = (at.p, at.vertex);
        let last = self.max_depth == Some(path.depth);
        let ray_in = path.ray;
        let seen = self.seen(at.phase, p, ray_in.dir);
        let v = Vertex {
            p,
            ray_in: &ray_in,
            phase: at.phase,
            mis: !last,
            index: vertex,
            choice: self.light_choice(at.phase, p, ray_in.dir, seen.as_ref()),
            arrival: path.arrival,
        };
        let parts = self.direct_light::<S>(&v, draws, c);
        let direct = path.beta * parts.total();
        path.add(direct, &parts, self.light_groups);
        if path.depth == 1 {
            path.out.aov.direct += direct;
        }
        if last {
            if !self.medium.emits() {
                return false;
            }
            path.emission_only = true;
        }
        // The sunward strategy gathers the next vertex's sunlight beside
        // the continuation (`path_sunward.rs`).
        let lobe = self.sunward_lobe(path, at, ray_in.dir, seen.as_ref());
        if let Some(lobe) = &lobe {
            let e = self.sunward::<S>(path, at, lobe, &ray_in, draws, c);
            path.add_to_group(e, self.lights.group(lobe.light), self.light_groups);
        }
        // The phase function is sampled exactly: the direction's weight
        // `f / pdf` is 1, and its density is `f`.
        let (u1, u2) = draws.get_2d(Draw::Phase, vertex);
        let (dir, pdf) = at.phase.sample(ray_in.dir, u1, u2);
        path.arrival = Arrival {
            scatter_pdf: pdf,
            sunward_pdf: lobe.map_or(0.0, |l| self.sunward_pdf(&l, dir, pdf)),
        };
        path.escape = Escape::Mis(pdf, v.choice);
        path.ray = ray_in.spawn(p, dir);
        self.roulette(path, vertex, draws)
    }

    /// `beta * (1 - albedo) * Le`: the emission term at a collision.
    fn emit(&self, path: &mut Path, p: Vec3, it: &Interaction, c: &mut Counters) {
        let le = self.medium.emission(p, path.ray.time, it.instance, c);
        let e = path.beta * (Vec3::ONE - it.albedo) * le;
        path.add_to_group(e, self.lights.emission_group(), self.light_groups);
        path.out.aov.emission += e;
    }

    /// Russian roulette on the throughput once it is small; false when the
    /// path ends.
    fn roulette(&self, path: &mut Path, vertex: u32, draws: &mut SampleStream) -> bool {
        if path.depth >= ROULETTE_MIN_DEPTH {
            let m = path.beta.max_element();
            if m < ROULETTE_THROUGHPUT {
                if draws.get_1d(Draw::Roulette, vertex) >= m {
                    return false;
                }
                path.beta /= m;
            }
        }
        true
    }
}
