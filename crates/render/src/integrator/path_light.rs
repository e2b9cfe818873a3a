//! Next-event estimation for the path tracer: one sample of each light at
//! a scattering vertex, its shadow ray's transmittance by the chosen
//! estimator, weighted against the scattered direction's density by the
//! power heuristic (Veach 1997).

use glam::Vec3;

use super::path::PathTracer;
use super::LightParts;
use crate::light::LightSample;
use crate::medium::Media;
use crate::phase::Phase;
use crate::ray::Ray;
use crate::sampling::{power_heuristic, Draw, SampleStream};
use crate::spectrum::Spectrum;
use crate::stats::Counters;
use crate::tracking::transmittance;

/// Where and how the light is gathered at a vertex.
pub(super) struct Vertex<'a> {
    pub p: Vec3,
    /// The ray that arrived (its direction and time).
    pub ray_in: &'a Ray,
    pub phase: &'a Phase,
    /// Weight against the scattered direction (false at the last allowed
    /// vertex, whose continuation cannot reach a light, and at a guided
    /// one, whose resampled direction has no density to weigh by: its
    /// escapes take no light at infinity).
    pub mis: bool,
    /// The vertex's index in the draw allocation.
    pub index: u32,
}

impl<M: Media> PathTracer<'_, M> {
    /// NEE at a vertex: the sun and the sky, each one sample.
    pub(super) fn direct_light<S: Spectrum>(
        &self,
        v: &Vertex,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> LightParts {
        let mut l = LightParts::default();
        if let Some(sun) = &self.lights.sun {
            let (u1, u2) = draws.get_2d(Draw::SunDirection, v.index);
            let s = sun.sample(u1, u2);
            c.nee_rays_sun += 1;
            l.sun = self.light_term::<S>(v, s, Draw::SunShadow, draws, c);
        }
        if let Some(env) = &self.lights.environment {
            let (u1, u2) = draws.get_2d(Draw::SkyDirection, v.index);
            let s = env.sample(u1, u2);
            c.env_samples += 1;
            // A zero-density sample (a pole) is dropped without a shadow ray.
            c.nee_rays_env += u64::from(s.pdf.is_some_and(|p| p > 0.0));
            l.sky = self.light_term::<S>(v, s, Draw::SkyShadow, draws, c);
        }
        l
    }

    /// `f * Li * T * w / p_light` for one light sample; for a delta light
    /// `radiance` is the irradiance and the pdf is a delta, so `f * E * T`.
    fn light_term<S: Spectrum>(
        &self,
        v: &Vertex,
        s: LightSample,
        shadow_draw: Draw,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> Vec3 {
        let f = v.phase.eval(v.ray_in.dir, s.to_light);
        let weight = match s.pdf {
            None => f,
            Some(light_pdf) if light_pdf > 0.0 => {
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
