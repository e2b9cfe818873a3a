//! Next-event estimation for the path tracer: one sample of each light at
//! a scattering vertex, or of one light picked by `light_choice.rs`, its
//! shadow ray's transmittance by the chosen estimator, weighted against the scattered direction's density by the
//! power heuristic (Veach 1997).

use glam::Vec3;

use super::path::PathTracer;
use super::path_state::Vertex;
use super::LightParts;
use crate::light::{Environment, LightSample};
use crate::medium::Media;
use crate::sampling::{power_heuristic, Draw, SampleStream};
use crate::spectrum::Spectrum;
use crate::stats::Counters;
use crate::tracking::transmittance;

impl<M: Media> PathTracer<'_, M> {
    /// NEE at a vertex: one sample of the sun and one of the sky, or of
    /// one of them picked by `v.choice` (the pick drawn from the hashed
    /// stream, so the lights' Sobol dimensions stay where they are).
    pub(super) fn direct_light<S: Spectrum>(
        &self,
        v: &Vertex,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> LightParts {
        let (sun_picked, sky_picked) = if v.choice.is_all() {
            (true, true)
        } else {
            // Sun, sky, or (where the choice traces no shadow ray with the
            // remaining probability) neither; both where they sum past one.
            v.choice.picks(draws.rng().uniform())
        };
        let mut l = LightParts::default();
        if let Some(sun) = self.lights.sun.as_ref().filter(|_| sun_picked) {
            let (u1, u2) = draws.get_2d(Draw::SunDirection, v.index);
            let s = sun.sample(u1, u2);
            c.nee_rays_sun += 1;
            let weight = v.arrival.sun_weight(v.choice.sun);
            l.sun = weight * self.light_term::<S>(v, s, v.choice.sun, Draw::SunShadow, draws, c);
        }
        if let Some(env) = self.lights.environment.as_ref().filter(|_| sky_picked) {
            let (u1, u2) = draws.get_2d(Draw::SkyDirection, v.index);
            let s = self.sky_sample(v, env, u1, u2);
            c.env_samples += 1;
            // A zero-density sample (a pole) is dropped without a shadow ray.
            c.nee_rays_env += u64::from(s.pdf.is_some_and(|p| p > 0.0));
            l.sky = self.light_term::<S>(v, s, v.choice.sky, Draw::SkyShadow, draws, c);
        }
        l
    }

    /// The sky's direction at `v`: drawn from the sky itself, except for a
    /// constant sky at a vertex without MIS (the last one a path may
    /// scatter at), where it is drawn from the phase function, the
    /// importance sampling of `f * L` for any constant `L`. There nothing
    /// weighs the draw against another strategy, and a sky sampled
    /// uniformly against a narrow phase lobe (Mie scattering by cloud
    /// droplets) is a heavy-tailed estimate that a light pick's small
    /// probability then multiplies into fireflies.
    fn sky_sample(&self, v: &Vertex, env: &Environment, u1: f32, u2: f32) -> LightSample {
        if v.mis || env.map.is_some() {
            return env.sample(u1, u2);
        }
        let (to_light, pdf) = v.phase.sample(v.ray_in.dir, u1, u2);
        LightSample {
            to_light,
            radiance: env.radiance,
            pdf: Some(pdf),
        }
    }

    /// `f * Li * T * w / (pick p_light)` for one light sample, `pick` the
    /// probability that the vertex sampled this light; for a delta light
    /// `radiance` is the irradiance and the pdf is a delta, so
    /// `f * E * T / pick`.
    fn light_term<S: Spectrum>(
        &self,
        v: &Vertex,
        s: LightSample,
        pick: f32,
        shadow_draw: Draw,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> Vec3 {
        let f = v.phase.eval(v.ray_in.dir, s.to_light);
        let weight = match s.pdf {
            None => f / pick,
            Some(light_pdf) if light_pdf > 0.0 => {
                let light_pdf = pick * light_pdf;
                // Every phase function is sampled exactly: its pdf is f.
                let w = if v.mis {
                    power_heuristic(light_pdf, f)
                } else {
                    1.0
                };
                f * w / light_pdf
            }
            Some(_) => return Vec3::ZERO,
        };
        let shadow = v.ray_in.spawn(v.p, s.to_light);
        let tr = draws.leading(shadow_draw, v.index, |rng| {
            transmittance::<S, M>(self.estimator, self.medium, &shadow, f32::INFINITY, rng, c)
        });
        s.radiance * (weight * tr.rgb())
    }
}
