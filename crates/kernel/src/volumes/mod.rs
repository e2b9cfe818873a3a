//! The volumes of a scene: [`Volumes`], the [`Media`] every render walks.
//!
//! Each instance is a [`Medium`]: a density field already placed in render
//! space (its object-to-world transform folded into the field, as
//! [`BrickField`](crate::medium::BrickField) does), a density scale, an
//! albedo, a phase function, and optional emission.
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

use crate::counters::Counters;
use crate::medium::{
    Bounds3, DensityField, Interaction, Lattice, MajorantSegment, Media, Medium, Scaled,
};
use crate::sampling::Rng;
use crate::spectrum::Spectrum;

impl<F: DensityField> Medium<F> {
    fn interaction(&self, instance: usize, weight: Vec3) -> Interaction<'_> {
        Interaction {
            albedo: self.albedo,
            phase: &self.phase,
            instance: instance as u32,
            weight,
            holdout: self.holdout,
        }
    }
}

/// The media of a scene with their top-level BVH.
pub struct Volumes<F> {
    instances: Vec<Medium<F>>,
    top: TopLevel,
    bounds: Bounds3,
    voxel_size: f32,
    max_sigma_t: f32,
    emits: bool,
    chromatic: bool,
}

impl<F: DensityField> Volumes<F> {
    pub fn new(instances: Vec<Medium<F>>) -> Self {
        let boxes: Vec<Bounds3> = instances.iter().map(|i| i.field.bounds()).collect();
        let bounds = boxes.iter().fold(Bounds3::EMPTY, |u, &b| u.union(b));
        let voxel_size = instances
            .iter()
            .map(|i| i.field.voxel_size())
            .fold(f32::INFINITY, f32::min);
        // Overlaps add, so the sum bounds sigma_t everywhere.
        let max_sigma_t = instances
            .iter()
            .map(|i| i.density_scale * i.field.global_majorant())
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

    pub fn instances(&self) -> &[Medium<F>] {
        &self.instances
    }

    /// The instances, given back (to wrap their fields, say).
    pub fn into_instances(self) -> Vec<Medium<F>> {
        self.instances
    }

    /// The instances the ray meets within `[t_min, t_max]`, by entry.
    pub fn hits(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Hits {
        self.top.hits(origin, dir, t_min, t_max)
    }

    fn instance_segments(&self, hit: &Hit, origin: Vec3, dir: Vec3) -> Scaled<F::Segments<'_>> {
        let inst = &self.instances[hit.instance as usize];
        Scaled::new(
            inst.field.segments(origin, dir, hit.t0, hit.t1),
            inst.density_scale,
        )
    }
}

/// Segments of [`Volumes`]: one instance's own, or the merge of several.
///
/// The merge is boxed: it holds room for four instances' iterators, and a
/// walk takes its segments by value, so unboxed every walk (most of which
/// pass through one instance) would copy several hundred bytes.
pub enum VolumeSegments<'a, F: DensityField + 'a> {
    None,
    One(Scaled<F::Segments<'a>>),
    Many(Box<Merged<F::Segments<'a>>>),
}

impl<'a, F: DensityField + 'a> Iterator for VolumeSegments<'a, F> {
    type Item = MajorantSegment;

    // Always: out of line, every segment went through a call that
    // stored the walk's position and read it back, on the step's critical
    // path (thick cloud 0.964-0.967 of the time inlined).
    #[inline(always)]
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
                    inst.field.segments(origin, dir, t_min, t_max),
                    inst.density_scale,
                ))
            }
            _ => {
                let hits = self.top.hits(origin, dir, t_min, t_max);
                match hits.len() {
                    0 => VolumeSegments::None,
                    1 => VolumeSegments::One(self.instance_segments(&hits[0], origin, dir)),
                    _ => VolumeSegments::Many(Box::new(Merged::new(
                        hits.iter().map(|h| self.instance_segments(h, origin, dir)),
                    ))),
                }
            }
        }
    }

    /// One instance: its own extinction (the fast path); several: the sum
    /// over the instances containing `p`, in BVH order.
    #[inline]
    fn extinction<S: Spectrum>(&self, p: Vec3, time: f32) -> S {
        if self.instances.len() == 1 {
            let inst = &self.instances[0];
            return S::tinted(inst.sigma_t(p, time), inst.extinction_tint);
        }
        let mut sigma = S::ZERO;
        self.top.containing(p, |i| {
            let inst = &self.instances[i];
            sigma = sigma.add(S::tinted(inst.sigma_t(p, time), inst.extinction_tint));
        });
        sigma
    }

    fn chromatic(&self) -> bool {
        self.chromatic
    }

    /// One instance: its tint. Several: 1 when all are grey, else `None`
    /// (each channel is looked up).
    fn uniform_tint(&self) -> Option<Vec3> {
        match self.instances.as_slice() {
            [one] => Some(one.extinction_tint),
            _ => (!self.chromatic).then_some(Vec3::ONE),
        }
    }

    /// One instance: its field's own march (which may skip empty cells
    /// faster than its segments); several: the merged segments walked.
    fn march_lattice(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        mut visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        if self.instances.len() == 1 {
            let inst = &self.instances[0];
            let scale = inst.density_scale;
            return inst
                .field
                .march_lattice(origin, dir, t_max, lattice, |t, d| visit(t, scale * d));
        }
        lattice.visit_segments(self.majorants(origin, dir, 0.0, t_max), |t| {
            visit(t, self.extinction(origin + dir * t, 0.0))
        })
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
    fn interaction(&self, p: Vec3, time: f32, rng: &mut Rng) -> Interaction<'_> {
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

    fn emission(&self, p: Vec3, time: f32, instance: u32, c: &mut Counters) -> Vec3 {
        match &self.instances[instance as usize].emission {
            Some(e) => e.radiance(p, time, c),
            None => Vec3::ZERO,
        }
    }
}

/// One medium alone.
impl<F: DensityField> From<Medium<F>> for Volumes<F> {
    fn from(medium: Medium<F>) -> Self {
        Volumes::new(vec![medium])
    }
}
