//! Several volume instances in one scene: [`Volumes`], the [`Media`] the
//! scene files render.
//!
//! Each [`VolumeInstance`] is a density field already placed in render
//! space (its object-to-world transform folded into the field, as
//! [`BrickField`](crate::medium::BrickField) does), a density scale, an
//! albedo, a phase function, and optional [`Emission`].
//!
//! - `bvh`: the top-level BVH (obvhs) that finds the instances a ray meets.
//! - `merge`: where instances overlap, extinction and the majorant (and
//!   minorant) segments add.
//!
//! Costs: one instance takes a fast path with no BVH and no merge (its own
//! segments, scaled); a ray that misses every instance costs one box test;
//! a ray through one instance walks that instance's segments alone.

mod bvh;
mod merge;

pub use bvh::{Hit, Hits, TopLevel};
pub use merge::Merged;

use glam::Vec3;

use crate::blackbody::Blackbody;
use crate::medium::{Bounds3, DensityField, Interaction, MajorantSegment, Media, Scaled};
use crate::phase::Phase;
use crate::sampling::Rng;
use crate::stats::Counters;

/// What an instance emits: blackbody radiation from a temperature grid,
/// and/or a scalar emission grid times a colour. Each grid is its own
/// field with its own bounds, so lookups happen only where it lives.
pub struct Emission<F> {
    pub temperature: Option<(F, Blackbody)>,
    /// The grid and the colour its values multiply (scale included).
    pub grid: Option<(F, Vec3)>,
}

impl<F: DensityField> Emission<F> {
    /// Emitted radiance `Le` at `p`.
    #[inline]
    pub fn radiance(&self, p: Vec3, c: &mut Counters) -> Vec3 {
        self.radiance_at(p, 0.0, c)
    }

    /// Emitted radiance `Le` at `p` at shutter time `time`: the grids move
    /// with their own velocity (set on each field), as the density does.
    #[inline]
    pub fn radiance_at(&self, p: Vec3, time: f32, c: &mut Counters) -> Vec3 {
        let inside = |f: &F| f.bounds().contains(p);
        let mut le = Vec3::ZERO;
        if let Some((field, bb)) = &self.temperature {
            if inside(field) {
                c.emission_lookups += 1;
                le += bb.radiance(field.density_at(p, time));
            }
        }
        if let Some((field, colour)) = &self.grid {
            if inside(field) {
                c.emission_lookups += 1;
                le += *colour * field.density_at(p, time).max(0.0);
            }
        }
        le
    }
}

/// One volume of a scene.
pub struct VolumeInstance<F> {
    pub density: F,
    /// The largest channel's extinction per unit density, in
    /// 1 / render-space units.
    pub density_scale: f32,
    /// Each channel's extinction relative to `density_scale`, in [0, 1]
    /// ([`Medium`](crate::Medium) states the convention).
    pub extinction_tint: Vec3,
    pub albedo: Vec3,
    pub phase: Phase,
    pub emission: Option<Emission<F>>,
    /// A matte: lights and shadows the others, never seen by the camera.
    pub holdout: bool,
}

impl<F: DensityField> VolumeInstance<F> {
    /// An instance with the Henyey-Greenstein phase function of asymmetry
    /// `g` ([`Phase::hg`]); [`VolumeInstance::with_phase`] sets any other.
    pub fn new(density: F, density_scale: f32, albedo: Vec3, g: f32) -> Self {
        Self {
            density,
            density_scale,
            extinction_tint: Vec3::ONE,
            albedo,
            phase: Phase::hg(g),
            emission: None,
            holdout: false,
        }
    }

    pub fn with_phase(self, phase: Phase) -> Self {
        Self { phase, ..self }
    }

    pub fn with_extinction_tint(self, extinction_tint: Vec3) -> Self {
        Self {
            extinction_tint,
            ..self
        }
    }

    #[inline]
    fn sigma_t(&self, p: Vec3, time: f32) -> f32 {
        self.density_scale * self.density.density_at(p, time)
    }

    fn interaction(&self, instance: usize, weight: Vec3) -> Interaction<'_> {
        Interaction {
            albedo: self.albedo,
            phase: &self.phase,
            instance: instance as u32,
            weight,
        }
    }
}

/// The instances of a scene with their top-level BVH.
pub struct Volumes<F> {
    instances: Vec<VolumeInstance<F>>,
    top: TopLevel,
    bounds: Bounds3,
    voxel_size: f32,
    max_sigma_t: f32,
    emits: bool,
    chromatic: bool,
}

impl<F: DensityField> Volumes<F> {
    pub fn new(instances: Vec<VolumeInstance<F>>) -> Self {
        let boxes: Vec<Bounds3> = instances.iter().map(|i| i.density.bounds()).collect();
        let bounds = boxes.iter().fold(Bounds3::EMPTY, |u, &b| u.union(b));
        let voxel_size = instances
            .iter()
            .map(|i| i.density.voxel_size())
            .fold(f32::INFINITY, f32::min);
        // Overlaps add, so the sum bounds sigma_t everywhere.
        let max_sigma_t = instances
            .iter()
            .map(|i| i.density_scale * i.density.global_majorant())
            .sum();
        let emits = instances.iter().any(|i| i.emission.is_some());
        let chromatic = instances.iter().any(|i| i.extinction_tint != Vec3::ONE);
        Self {
            top: TopLevel::new(boxes),
            instances,
            bounds,
            voxel_size,
            max_sigma_t,
            emits,
            chromatic,
        }
    }

    pub fn instances(&self) -> &[VolumeInstance<F>] {
        &self.instances
    }

    /// The instances the ray meets within `[t_min, t_max]`, by entry.
    pub fn hits(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Hits {
        self.top.hits(origin, dir, t_min, t_max)
    }

    fn instance_segments(&self, hit: &Hit, origin: Vec3, dir: Vec3) -> Scaled<F::Segments<'_>> {
        let inst = &self.instances[hit.instance as usize];
        Scaled::new(
            inst.density.segments(origin, dir, hit.t0, hit.t1),
            inst.density_scale,
        )
    }
}

/// Segments of [`Volumes`]: one instance's own, or the merge of several.
pub enum VolumeSegments<'a, F: DensityField + 'a> {
    None,
    One(Scaled<F::Segments<'a>>),
    Many(Merged<F::Segments<'a>>),
}

impl<'a, F: DensityField + 'a> Iterator for VolumeSegments<'a, F> {
    type Item = MajorantSegment;

    #[inline]
    fn next(&mut self) -> Option<MajorantSegment> {
        match self {
            VolumeSegments::None => None,
            VolumeSegments::One(s) => s.next(),
            VolumeSegments::Many(m) => m.next(),
        }
    }
}

impl<F: DensityField> Media for Volumes<F> {
    type Majorants<'a>
        = VolumeSegments<'a, F>
    where
        Self: 'a;

    fn majorants(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Majorants<'_> {
        match self.instances.len() {
            0 => VolumeSegments::None,
            // The fast path: no BVH, no merge; the field clips itself.
            1 => {
                let inst = &self.instances[0];
                VolumeSegments::One(Scaled::new(
                    inst.density.segments(origin, dir, t_min, t_max),
                    inst.density_scale,
                ))
            }
            _ => {
                let hits = self.top.hits(origin, dir, t_min, t_max);
                match hits.len() {
                    0 => VolumeSegments::None,
                    1 => VolumeSegments::One(self.instance_segments(&hits[0], origin, dir)),
                    _ => VolumeSegments::Many(Merged::new(
                        hits.iter().map(|h| self.instance_segments(h, origin, dir)),
                    )),
                }
            }
        }
    }

    #[inline]
    fn sigma_t(&self, p: Vec3) -> f32 {
        self.sigma_t_at(p, 0.0)
    }

    #[inline]
    fn sigma_t_at(&self, p: Vec3, time: f32) -> f32 {
        if self.instances.len() == 1 {
            return self.instances[0].sigma_t(p, time);
        }
        let mut sigma = 0.0;
        self.top
            .containing(p, |i| sigma += self.instances[i].sigma_t(p, time));
        sigma
    }

    fn chromatic(&self) -> bool {
        self.chromatic
    }

    #[inline]
    fn sigma_t_rgb_at(&self, p: Vec3, time: f32) -> Vec3 {
        if self.instances.len() == 1 {
            let inst = &self.instances[0];
            return inst.extinction_tint * inst.sigma_t(p, time);
        }
        let mut sigma = Vec3::ZERO;
        self.top.containing(p, |i| {
            let inst = &self.instances[i];
            sigma += inst.extinction_tint * inst.sigma_t(p, time);
        });
        sigma
    }

    fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    fn voxel_size(&self) -> f32 {
        self.voxel_size
    }

    fn max_sigma_t(&self) -> f32 {
        self.max_sigma_t
    }

    /// One instance: its material, no random number. Several: each
    /// instance containing `p` with probability `sigma_t,i / sigma_t`
    /// (largest channels, for chromatic media, with the per-channel
    /// correction in [`Interaction::weight`]); a random number is drawn
    /// only when two or more have density there.
    fn interaction(&self, p: Vec3, rng: &mut Rng) -> Interaction<'_> {
        self.interaction_at(p, 0.0, rng)
    }

    /// As [`interaction`](Media::interaction), with each instance's
    /// extinction at shutter time `time`.
    fn interaction_at(&self, p: Vec3, time: f32, rng: &mut Rng) -> Interaction<'_> {
        if self.instances.len() == 1 {
            return self.instances[0].interaction(0, Vec3::ONE);
        }
        let mut found: smallvec::SmallVec<[(usize, f32); 4]> = smallvec::SmallVec::new();
        let mut total = 0.0;
        let mut total_rgb = Vec3::ZERO;
        self.top.containing(p, |i| {
            let s = self.instances[i].sigma_t(p, time);
            if s > 0.0 {
                found.push((i, s));
                total += s;
                total_rgb += self.instances[i].extinction_tint * s;
            }
        });
        let chosen = match found.len() {
            0 => {
                // A collision accepted on a minorant where rounding put the
                // lookup at 0: any instance containing p will do.
                let mut first = 0;
                let mut seen = false;
                self.top.containing(p, |i| {
                    if !seen {
                        first = i;
                        seen = true;
                    }
                });
                first
            }
            1 => return self.instances[found[0].0].interaction(found[0].0, Vec3::ONE),
            _ => {
                let mut x = rng.uniform() * total;
                let mut pick = found[found.len() - 1].0;
                for &(i, s) in &found {
                    if x < s {
                        pick = i;
                        break;
                    }
                    x -= s;
                }
                pick
            }
        };
        let weight = if self.chromatic && found.len() > 1 {
            // sigma_t,i,c / (sigma_t,c q_i) with q_i = s_i / total.
            let tint = self.instances[chosen].extinction_tint;
            let ratio = (tint * total) / total_rgb;
            Vec3::select(total_rgb.cmpgt(Vec3::ZERO), ratio, Vec3::ZERO)
        } else {
            Vec3::ONE
        };
        self.instances[chosen].interaction(chosen, weight)
    }

    fn emits(&self) -> bool {
        self.emits
    }

    #[inline]
    fn holdout(&self, instance: u32) -> bool {
        self.instances[instance as usize].holdout
    }

    #[inline]
    fn emission(&self, p: Vec3, instance: u32, c: &mut Counters) -> Vec3 {
        self.emission_at(p, 0.0, instance, c)
    }

    #[inline]
    fn emission_at(&self, p: Vec3, time: f32, instance: u32, c: &mut Counters) -> Vec3 {
        match &self.instances[instance as usize].emission {
            Some(e) => e.radiance_at(p, time, c),
            None => Vec3::ZERO,
        }
    }
}
