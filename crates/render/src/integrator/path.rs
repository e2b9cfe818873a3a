//! Volumetric path tracing.

use glam::Vec3;

use super::{escaped_radiance, AovSample, CameraSampler, LightParts, Sample};
use crate::compositing::{tag, GroupRadiance, LightGroup};
use crate::light::{LightSample, Lights};
use crate::medium::Media;
use crate::phase::Phase;
use crate::ray::Ray;
use crate::sampling::{power_heuristic, Draw, Rng, SampleStream};
use crate::spectrum::Spectrum;
use crate::stats::Counters;
use crate::tracking::{sample_free_flight, transmittance, FreeFlight, TransmittanceEstimator};

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
/// - Next-event estimation at every scattering event: one sample of the
///   sun (if any) and one of the environment (if any), each shadow ray's
///   transmittance estimated by the chosen estimator. Directions from a
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
/// - Emission: at every real collision, with the instance chosen with
///   probability `sigma_t,i / sigma_t` ([`Media::interaction`]), the
///   path adds `beta * (1 - albedo_i) * Le_i`. Delta tracking samples the
///   collision with density `sigma_t T`, so this estimates
///   `integral of T * sigma_a * Le` (the source term of the RTE), exactly
///   as the albedo weight estimates the scattering term. Added before the
///   depth test: emission is not a scattering event, so `max_depth` 0 shows
///   the emitted light seen through the volume.
pub struct PathTracer<'a, M> {
    medium: &'a M,
    lights: Lights,
    estimator: TransmittanceEstimator,
    max_depth: Option<u32>,
    chromatic: bool,
    /// Tag contributions with their light groups (off: `Sample::groups`
    /// stays zero and costs nothing).
    light_groups: bool,
}

impl<'a, M: Media> PathTracer<'a, M> {
    pub fn new(
        medium: &'a M,
        lights: Lights,
        estimator: TransmittanceEstimator,
        max_depth: Option<u32>,
    ) -> Self {
        Self {
            medium,
            lights: lights.pruned(),
            estimator,
            max_depth,
            chromatic: medium.chromatic(),
            light_groups: false,
        }
    }

    /// Splits each sample's radiance into light groups as well.
    pub fn with_light_groups(self, light_groups: bool) -> Self {
        Self {
            light_groups,
            ..self
        }
    }

    /// NEE at `p`, path vertex `vertex`, for a path arriving along `ray_in`
    /// (whose time the shadow rays keep).
    #[allow(clippy::too_many_arguments)]
    fn direct_light<S: Spectrum>(
        &self,
        p: Vec3,
        ray_in: &Ray,
        phase: &Phase,
        mis: bool,
        vertex: u32,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> LightParts {
        let mut l = LightParts::default();
        if let Some(sun) = &self.lights.sun {
            let (u1, u2) = draws.get_2d(Draw::SunDirection, vertex);
            let s = sun.sample(u1, u2);
            c.nee_rays_sun += 1;
            let shadow = (Draw::SunShadow, vertex);
            l.sun = self.light_term::<S>(p, ray_in, phase, s, mis, shadow, draws, c);
        }
        if let Some(env) = &self.lights.environment {
            let (u1, u2) = draws.get_2d(Draw::SkyDirection, vertex);
            let s = env.sample(u1, u2);
            c.env_samples += 1;
            // A zero-density sample (a pole) is dropped without a shadow ray.
            c.nee_rays_env += u64::from(s.pdf.is_some_and(|p| p > 0.0));
            let shadow = (Draw::SkyShadow, vertex);
            l.sky = self.light_term::<S>(p, ray_in, phase, s, mis, shadow, draws, c);
        }
        l
    }

    /// `f * Li * T * w / p_light` for one light sample; for a delta light
    /// `radiance` is the irradiance and the pdf is a delta, so `f * E * T`.
    #[allow(clippy::too_many_arguments)]
    fn light_term<S: Spectrum>(
        &self,
        p: Vec3,
        ray_in: &Ray,
        phase: &Phase,
        s: LightSample,
        mis: bool,
        (draw, vertex): (Draw, u32),
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> Vec3 {
        let f = phase.eval(ray_in.dir, s.to_light);
        let weight = match s.pdf {
            None => f,
            Some(light_pdf) if light_pdf > 0.0 => {
                // Every phase function is sampled exactly: its pdf is f.
                let w = if mis {
                    power_heuristic(light_pdf, f)
                } else {
                    1.0
                };
                f * w / light_pdf
            }
            Some(_) => return Vec3::ZERO,
        };
        let shadow = ray_in.spawn(p, s.to_light);
        let tr = draws.leading(draw, vertex, |rng| {
            transmittance::<S, M>(self.estimator, self.medium, &shadow, f32::INFINITY, rng, c)
        });
        s.radiance * (weight * tr.rgb())
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
    /// One camera path, tracked per channel of `S`.
    fn trace<S: Spectrum>(
        &self,
        camera_ray: Ray,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> Sample {
        c.paths += 1;
        let emits = self.medium.emits();
        let mut ray = camera_ray;
        let mut beta = Vec3::ONE;
        let mut l = Vec3::ZERO;
        let mut alpha = 0.0;
        let mut aov = AovSample::default();
        let mut groups = GroupRadiance::default();
        let mut depth = 0u32;
        let mut phase_pdf = None;
        // Set after the last allowed scattering event when the media emit:
        // the path goes on only to find emitted light, lights at infinity
        // having had their full weight from next-event estimation.
        let mut emission_only = false;
        loop {
            // This free flight and the events at its collision are path
            // vertex `vertex` of the draw allocation.
            let vertex = depth;
            let flight = draws.leading(Draw::FreeFlight, vertex, |rng| {
                sample_free_flight::<S, M>(self.medium, &ray, ray.t_max, &mut beta, rng, c)
            });
            if depth == 0 {
                alpha = match flight {
                    FreeFlight::Escaped => S::escaped_alpha(beta),
                    _ => 1.0,
                };
            }
            let t = match flight {
                FreeFlight::Escaped if emission_only => break,
                // A camera ray ended by a depth holdout: what lies behind
                // the held-out geometry, the sky included, never shows.
                FreeFlight::Escaped if ray.t_max.is_finite() => break,
                FreeFlight::Escaped => {
                    let parts = escaped_radiance(&self.lights, ray.dir, phase_pdf, c);
                    let e = beta * parts.total();
                    if self.light_groups {
                        parts.scaled(beta).tag(&mut groups);
                    }
                    l += e;
                    if depth == 1 {
                        aov.direct += e;
                    }
                    break;
                }
                FreeFlight::Capped => break,
                FreeFlight::Collision { t } => t,
            };
            let p = ray.at(t);
            let it = self.medium.interaction(p, ray.time, draws.rng());
            if S::CHROMATIC {
                beta *= it.weight;
            }
            if depth == 0 {
                // A holdout volume seen first is a matte: no light, no alpha.
                if it.holdout {
                    alpha = 0.0;
                    break;
                }
                aov.albedo = it.albedo;
                aov.depth = Some(t);
                aov.instance = Some(it.instance);
            }
            if emits {
                let e = beta
                    * (Vec3::ONE - it.albedo)
                    * self.medium.emission(p, ray.time, it.instance, c);
                l += e;
                aov.emission += e;
                if self.light_groups {
                    tag(&mut groups, LightGroup::Emission, e);
                }
            }
            if self.max_depth == Some(depth) {
                break;
            }
            depth += 1;
            beta *= it.albedo;
            if beta.max_element() <= 0.0 {
                break;
            }
            let last = self.max_depth == Some(depth);
            let parts = self.direct_light::<S>(p, &ray, it.phase, !last, vertex, draws, c);
            let direct = beta * parts.total();
            if self.light_groups {
                parts.scaled(beta).tag(&mut groups);
            }
            l += direct;
            if depth == 1 {
                aov.direct += direct;
            }
            if last {
                if !emits {
                    break;
                }
                emission_only = true;
            }
            let (u1, u2) = draws.get_2d(Draw::Phase, vertex);
            let (dir, pdf) = it.phase.sample(ray.dir, u1, u2);
            phase_pdf = Some(pdf);
            ray = ray.spawn(p, dir);
            if depth >= ROULETTE_MIN_DEPTH {
                let m = beta.max_element();
                if m < ROULETTE_THROUGHPUT {
                    if draws.get_1d(Draw::Roulette, vertex) >= m {
                        break;
                    }
                    beta /= m;
                }
            }
        }
        Sample {
            radiance: l,
            alpha,
            aov,
            groups,
        }
    }
}
