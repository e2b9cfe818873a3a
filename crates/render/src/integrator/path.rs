//! Volumetric path tracing.

use glam::Vec3;

use super::{escaped_radiance, CameraSampler, Sample};
use crate::light::{LightSample, Lights};
use crate::medium::{DensityField, Medium};
use crate::ray::Ray;
use crate::sampling::{power_heuristic, Rng};
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
///   light sampler and from HG sampling are combined with the power
///   heuristic (Veach 1997); a delta sun gets NEE only. At the last
///   allowed scattering event NEE takes weight 1 and the path stops, since
///   the phase-sampled continuation could only reach lights at infinity.
/// - `max_depth` counts scattering events: 0 shows only the environment
///   through the volume's transmittance, 1 is single scattering, `None`
///   is unlimited.
/// - Alpha is the track-length estimate of `1 - T` along the camera ray:
///   1 if its first free flight collides, else 0.
pub struct PathTracer<'a, F> {
    medium: &'a Medium<F>,
    lights: Lights,
    estimator: TransmittanceEstimator,
    max_depth: Option<u32>,
}

impl<'a, F: DensityField> PathTracer<'a, F> {
    pub fn new(
        medium: &'a Medium<F>,
        lights: Lights,
        estimator: TransmittanceEstimator,
        max_depth: Option<u32>,
    ) -> Self {
        Self {
            medium,
            lights: lights.pruned(),
            estimator,
            max_depth,
        }
    }

    /// NEE at `p` for a path arriving along `dir_in`.
    fn direct_light(
        &self,
        p: Vec3,
        dir_in: Vec3,
        mis: bool,
        rng: &mut Rng,
        c: &mut Counters,
    ) -> Vec3 {
        let mut l = Vec3::ZERO;
        if let Some(sun) = &self.lights.sun {
            let s = sun.sample(rng.uniform(), rng.uniform());
            l += self.light_term(p, dir_in, s, mis, rng, c);
        }
        if let Some(env) = &self.lights.environment {
            let s = env.sample(rng.uniform(), rng.uniform());
            l += self.light_term(p, dir_in, s, mis, rng, c);
        }
        l
    }

    /// `f * Li * T * w / p_light` for one light sample; for a delta light
    /// `radiance` is the irradiance and the pdf is a delta, so `f * E * T`.
    fn light_term(
        &self,
        p: Vec3,
        dir_in: Vec3,
        s: LightSample,
        mis: bool,
        rng: &mut Rng,
        c: &mut Counters,
    ) -> Vec3 {
        let f = self.medium.phase.eval(dir_in, s.to_light);
        let weight = match s.pdf {
            None => f,
            Some(light_pdf) if light_pdf > 0.0 => {
                // The phase function is sampled exactly: its pdf is f.
                let w = if mis {
                    power_heuristic(light_pdf, f)
                } else {
                    1.0
                };
                f * w / light_pdf
            }
            Some(_) => return Vec3::ZERO,
        };
        let shadow = Ray::new(p, s.to_light);
        let tr = transmittance(self.estimator, self.medium, &shadow, f32::INFINITY, rng, c);
        s.radiance * (weight * tr)
    }
}

impl<F: DensityField> CameraSampler for PathTracer<'_, F> {
    fn sample(&self, camera_ray: Ray, rng: &mut Rng, c: &mut Counters) -> Sample {
        c.paths += 1;
        let mut ray = camera_ray;
        let mut beta = Vec3::ONE;
        let mut l = Vec3::ZERO;
        let mut alpha = 0.0;
        let mut depth = 0u32;
        let mut phase_pdf = None;
        loop {
            let flight = sample_free_flight(self.medium, &ray, f32::INFINITY, rng, c);
            if depth == 0 && flight != FreeFlight::Escaped {
                alpha = 1.0;
            }
            let t = match flight {
                FreeFlight::Escaped => {
                    l += beta * escaped_radiance(&self.lights, ray.dir, phase_pdf);
                    break;
                }
                FreeFlight::Capped => break,
                FreeFlight::Collision { t } => t,
            };
            if self.max_depth == Some(depth) {
                break;
            }
            depth += 1;
            beta *= self.medium.albedo;
            if beta.max_element() <= 0.0 {
                break;
            }
            let p = ray.at(t);
            let last = self.max_depth == Some(depth);
            l += beta * self.direct_light(p, ray.dir, !last, rng, c);
            if last {
                break;
            }
            let (dir, pdf) = self
                .medium
                .phase
                .sample(ray.dir, rng.uniform(), rng.uniform());
            phase_pdf = Some(pdf);
            ray = Ray::new(p, dir);
            if depth >= ROULETTE_MIN_DEPTH {
                let m = beta.max_element();
                if m < ROULETTE_THROUGHPUT {
                    if rng.uniform() >= m {
                        break;
                    }
                    beta /= m;
                }
            }
        }
        Sample { radiance: l, alpha }
    }
}
