//! Next-event estimation for the path tracer: one sample of each light at
//! a scattering vertex, or of the lights picked by `light_choice.rs`, each
//! shadow ray's transmittance by the chosen estimator, weighted against
//! the scattered direction's density by the power heuristic (Veach 1997).

use glam::Vec3;

use super::light_choice::LightChoice;
use super::mis::Strategies;
use super::path::PathTracer;
use super::path_state::Vertex;
use super::LightParts;
use crate::counters::Counters;
use crate::light::{Light, LightSample};
use crate::medium::Media;
use crate::sampling::{Draw, SampleStream};
use crate::spectrum::Spectrum;
use crate::tracking::transmittance;

impl<M: Media> PathTracer<'_, M> {
    /// NEE at a vertex: one sample of every light, or of the lights
    /// `v.choice` picks (the pick drawn from the hashed stream, so the
    /// lights' Sobol dimensions stay where they are); the `k`-th sample
    /// the vertex takes draws [`Draw::LightDirection`]`(k)` and
    /// [`Draw::LightShadow`]`(k)`.
    pub(super) fn direct_light<S: Spectrum>(
        &self,
        v: &Vertex,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> LightParts {
        let mut l = LightParts::default();
        match &v.choice {
            LightChoice::All => {
                for (k, i) in (0..self.lights.len()).enumerate() {
                    let e = self.light_sample::<S>(v, i, 1.0, k as u32, draws, c);
                    l.add(self.lights.group(i), e);
                }
            }
            LightChoice::Weighed { at, total } => {
                let u = draws.rng().uniform();
                // None where the lights in the scene send nothing toward
                // the vertex (the lights at infinity were not picked).
                if let Some((i, p)) = self.sampler.pick_weighed(*at, *total, u) {
                    let e = self.light_sample::<S>(v, i, p, 0, draws, c);
                    l.add(self.lights.group(i), e);
                }
            }
            LightChoice::Pick(p) => {
                // Where the probabilities sum below one the vertex samples
                // no light with the rest; past one, sometimes two.
                let u = draws.rng().uniform();
                for (k, i) in LightChoice::picks(p, u).enumerate() {
                    let e = self.light_sample::<S>(v, i, p[i], k as u32, draws, c);
                    l.add(self.lights.group(i), e);
                }
            }
        }
        l
    }

    /// The `k`-th light sample at `v`: light `i`, which the vertex samples
    /// with probability `pick`, weighed against the other strategies that
    /// gather its light there: the equi-angular sample of the segment that
    /// reached the vertex (toward a point-like light, `path_equiangular.rs`)
    /// and sunward scattering at the previous vertex (toward the sunward
    /// light).
    fn light_sample<S: Spectrum>(
        &self,
        v: &Vertex,
        i: usize,
        pick: f32,
        k: u32,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> Vec3 {
        let light = self.lights.get(i);
        let weight = match light.point_centre() {
            Some(centre) => self.collision_weight(v, i, centre, pick),
            None if self.sunward_light == Some(i) => v.arrival.sun_weight(pick),
            None => 1.0,
        };
        weight * self.sample_light::<S>(v, light, pick, k, draws, c)
    }

    /// The `k`-th light sample at `v` of `light`, which the vertex samples
    /// with probability `pick`.
    pub(super) fn sample_light<S: Spectrum>(
        &self,
        v: &Vertex,
        light: &Light,
        pick: f32,
        k: u32,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> Vec3 {
        let (u1, u2) = draws.get_2d(Draw::LightDirection(k), v.index);
        let s = self.sample_toward(v, light, u1, u2);
        light.count_sample(c);
        // Outside a spot's cone, behind an area light, or a zero-density
        // direction (a map's pole): no light, no shadow ray.
        if s.radiance == Vec3::ZERO || s.pdf.is_some_and(|p| p <= 0.0) {
            return Vec3::ZERO;
        }
        light.count_shadow_ray(c);
        self.light_term::<S>(v, s, pick, Draw::LightShadow(k), draws, c)
    }

    /// A direction toward `light` at `v`: drawn from the light itself,
    /// except for a light the same from every direction (a constant sky)
    /// at a vertex without MIS (the last one a path may scatter at), where
    /// it is drawn from the phase function, the importance sampling of
    /// `f L` for any constant `L`. There nothing weighs the draw against
    /// another strategy, and a sky sampled uniformly against a narrow phase
    /// lobe (Mie scattering by cloud droplets) is a heavy-tailed estimate
    /// that a light pick's small probability then multiplies into
    /// fireflies.
    #[inline]
    fn sample_toward(&self, v: &Vertex, light: &Light, u1: f32, u2: f32) -> LightSample {
        match light.uniform_radiance() {
            Some(radiance) if !v.mis => {
                let (to_light, pdf) = v.phase.sample(v.ray_in.dir, u1, u2);
                LightSample {
                    to_light,
                    radiance,
                    pdf: Some(pdf),
                    distance: f32::INFINITY,
                }
            }
            _ => light.sample_toward(v.p, u1, u2),
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
                    Strategies::drawn_with(light_pdf).or(f).weight()
                } else {
                    1.0
                };
                f * w / light_pdf
            }
            Some(_) => return Vec3::ZERO,
        };
        let shadow = v.ray_in.spawn(v.p, s.to_light);
        let tr = draws.leading(shadow_draw, v.index, |rng| {
            transmittance::<S, M>(self.estimator, self.medium, &shadow, s.distance, rng, c)
        });
        s.radiance * (weight * tr.rgb())
    }
}
