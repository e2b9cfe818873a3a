//! The path's free flight past the light surfaces it meets: balls of
//! sphere lights and area lights.
//!
//! Lights do not block rays (as in Cycles, pbrt-v4's area lights without
//! geometry, and UsdLux's lights, which are not geometry): a ray that
//! reaches a light surface before its next real collision gathers its
//! radiance there and flies on. The flight is split at each surface it
//! meets in turn; delta tracking is memoryless, so a flight restarted
//! at the surface samples the same collision density, and the surface is
//! reached with probability (or, for chromatic media, spectral tracking's
//! weight) the transmittance to it, which makes the gathered light the
//! track-length estimate of `T L`. A surface seen from a scattering vertex
//! is weighed against that vertex's next-event samples of it by the power
//! heuristic with its sampling density (a ball's cone, an area light's
//! shape) times its pick probability;
//! a camera ray sees it whole, where the light is seen by the camera at
//! all (off by default: the light shows in what it lights).

use glam::Vec3;

use super::mis::Strategies;
use super::path::PathTracer;
use super::path_state::{Escape, Path};
use crate::counters::Counters;
use crate::light::LightHit;
use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::{Draw, SampleStream};
use crate::spectrum::Spectrum;
use crate::tracking::{sample_free_flight, FreeFlight};

/// A light surface (a ball or an area light) a ray meets: its light's
/// index, where and what it sees.
#[derive(Clone, Copy, Debug)]
struct SurfaceHit {
    light: usize,
    t: f32,
    radiance: Vec3,
    pdf: f32,
}

impl<M: Media> PathTracer<'_, M> {
    /// The free flight of path vertex `vertex` along `path.ray`, gathering
    /// the light of the light surfaces it passes.
    #[inline]
    pub(super) fn fly<S: Spectrum>(
        &self,
        path: &mut Path,
        vertex: u32,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) -> FreeFlight {
        let ray = path.ray;
        if self.surfaces.is_empty() {
            return draws.leading(Draw::FreeFlight, vertex, |rng| {
                sample_free_flight::<S, M>(self.medium, &ray, ray.t_max, &mut path.beta, rng, c)
            });
        }
        let mut t0 = 0.0;
        let mut last = None;
        let camera = matches!(path.escape, Escape::Full);
        loop {
            let hit = self.next_surface(&ray, camera, last);
            let t_end = hit.map_or(ray.t_max, |h| h.t);
            let part = Ray {
                origin: ray.at(t0),
                ..ray
            };
            let mut flight = |rng: &mut _| {
                sample_free_flight::<S, M>(self.medium, &part, t_end - t0, &mut path.beta, rng, c)
            };
            let flight = if t0 == 0.0 {
                draws.leading(Draw::FreeFlight, vertex, flight)
            } else {
                flight(draws.rng())
            };
            match (flight, hit) {
                (FreeFlight::Escaped, Some(h)) => {
                    self.gather_surface(path, &h);
                    t0 = h.t;
                    last = Some((h.t, h.light));
                }
                (FreeFlight::Collision { t }, _) => return FreeFlight::Collision { t: t0 + t },
                (flight, _) => return flight,
            }
        }
    }

    /// The nearest light surface `ray` (a camera ray where `camera`, which
    /// meets only those seen by the camera) meets after `after` (the
    /// distance and light of the last one met, which is not met again),
    /// within `ray.t_max`.
    fn next_surface(
        &self,
        ray: &Ray,
        camera: bool,
        after: Option<(f32, usize)>,
    ) -> Option<SurfaceHit> {
        let mut best: Option<SurfaceHit> = None;
        for &i in &self.surfaces {
            let light = self.lights.get(i);
            if camera && !light.camera_visible() {
                continue;
            }
            let Some(LightHit { t, radiance, pdf }) = light.hit(ray.origin, ray.dir, ray.t_max)
            else {
                continue;
            };
            let later = after.is_none_or(|(t0, i0)| (t, i) > (t0, i0));
            if later && best.is_none_or(|b| (t, i) < (b.t, b.light)) {
                best = Some(SurfaceHit {
                    light: i,
                    t,
                    radiance,
                    pdf,
                });
            }
        }
        best
    }

    /// Adds surface `h`'s light, seen along the path's ray, MIS-weighted
    /// against next-event estimation at the ray's origin.
    fn gather_surface(&self, path: &mut Path, h: &SurfaceHit) {
        // After the last scattering event only emission is gathered, and
        // a depth holdout hides what lies behind it (`t_max` above).
        if path.emission_only {
            return;
        }
        let weight = match &path.escape {
            Escape::Full => 1.0,
            Escape::Mis(pdf, choice) => Strategies::drawn_with(*pdf)
                .or(self.sampler.probability(choice, h.light) * h.pdf)
                .weight(),
        };
        let e = path.beta * h.radiance * weight;
        path.add_to_group(e, self.lights.group(h.light), self.light_groups);
        if path.depth == 1 {
            path.out.aov.direct += e;
        }
    }
}
