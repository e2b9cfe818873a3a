//! The jittered lattice of a ray march, and the march of a volume's
//! occupied cells.
//!
//! A march samples the points `t_k = org + (k + u) h`, `k = 0, 1, ...`,
//! with one uniform `u` per ray and `org` where the ray enters its first
//! cell with density; only points where the density may be non-zero need a
//! lookup (every other point adds nothing to the march's sums).
//!
//! Two ways to find those points:
//! - [`Lattice::visit_segments`], over any majorant segments: a step per
//!   segment, then the segment's points. Fits every field.
//! - [`BrickVolume::march_occupied`], over a [`CellPartition`]'s level-1
//!   cells: a table read per point, and a step only where the ray enters
//!   an empty cube (skipped whole). Inside a cloud a ray march at one
//!   voxel per step crosses a level-1 cell (8 voxels) in a few points, and
//!   a segment walk's step (locate, bound, exit) cost about as much
//!   as a lookup per point on the corpus cloud; the table read costs a
//!   fraction of that.
//!
//! Both find every point with density (the property tests compare them
//! with a march of every point): empty cells (bounds 0) hold no density,
//! the trilinear stencil included (`bounds.rs`), so whatever either skips
//! has density 0.

use crate::dda::CellRay;
use crate::partition::{Cell, CellPartition};
use crate::segment::MajorantSegment;
use crate::volume::BrickVolume;
use crate::voxel_of::voxel_of;
use crate::CELL_LOG2;
use glam::{Vec3, Vec3A};

/// The points `t_k = org + (k + u) h` of a jittered march: `h` the step,
/// `u` in `[0, 1)` the ray's jitter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lattice {
    h: f32,
    u: f32,
    /// `1 / h`: a march finds the point after each empty cube it skips.
    inv_h: f32,
}

impl Lattice {
    pub fn new(h: f32, u: f32) -> Self {
        Lattice {
            h,
            u,
            inv_h: h.recip(),
        }
    }

    /// Point `k` of the lattice starting at `org`.
    #[inline]
    pub fn at(self, org: f32, k: i64) -> f32 {
        org + (k as f32 + self.u) * self.h
    }

    /// The index of the first point at or after `t`.
    #[inline]
    pub fn first_from(self, org: f32, t: f32) -> i64 {
        ((t - org) * self.inv_h - self.u).ceil() as i64
    }

    /// Calls `visit(t)` at each point inside a segment with a positive
    /// majorant, `org` the first such segment's start, until `visit`
    /// returns false. Returns the segments walked.
    pub fn visit_segments(
        self,
        segments: impl Iterator<Item = MajorantSegment>,
        mut visit: impl FnMut(f32) -> bool,
    ) -> u64 {
        let mut walked = 0;
        let mut origin = None;
        let mut next_k = 0i64;
        for s in segments {
            walked += 1;
            if s.majorant.is_nan() || s.majorant <= 0.0 {
                continue;
            }
            let org = *origin.get_or_insert(s.t0);
            // Never revisit a point that rounding placed in the previous
            // segment too.
            let mut k = next_k.max(self.first_from(org, s.t0));
            loop {
                let t = self.at(org, k);
                if t >= s.t1 {
                    break;
                }
                k += 1;
                if !visit(t) {
                    return walked;
                }
            }
            next_k = k;
        }
        walked
    }
}

impl BrickVolume {
    /// Calls `visit(t, density)` at each lattice point of the ray
    /// `origin + t * dir` (local index coordinates) within `[0, t_max]`
    /// that lies in a kept cell of `partition` (made from
    /// this volume), with the trilinear density there, until `visit`
    /// returns false. Returns the walk's steps: one to find the first kept
    /// cell, one per empty cube skipped.
    pub fn march_occupied(
        &self,
        partition: &CellPartition,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        let ray = (origin, dir, t_max);
        #[cfg(target_arch = "x86_64")]
        if let Some(atlas) = self.f16c_atlas() {
            // SAFETY: `f16c_atlas` is `Some` only where the CPU has F16C.
            return unsafe { self.march_occupied_f16c(atlas, partition, ray, lattice, visit) };
        }
        self.march_with(partition, ray, lattice, |p| self.trilinear(p), visit)
    }

    /// [`Self::march_occupied`] compiled with F16C, over an f16 atlas: the
    /// lookups inline into the march (a `target_feature` function inlines
    /// only into another), where each point paid two calls. Measured on
    /// the corpus cloud's ray march, a lookup every point: 0.944 of the
    /// time on one thread.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "f16c")]
    fn march_occupied_f16c(
        &self,
        atlas: &[u16],
        partition: &CellPartition,
        ray: (Vec3, Vec3, f32),
        lattice: Lattice,
        visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        self.march_with(
            partition,
            ray,
            lattice,
            |p| self.trilinear_f16c_inlined(atlas, p),
            visit,
        )
    }

    /// The march of [`Self::march_occupied`] with `lookup` for the density.
    #[inline(always)]
    fn march_with(
        &self,
        partition: &CellPartition,
        (origin, dir, t_max): (Vec3, Vec3, f32),
        lattice: Lattice,
        lookup: impl Fn(Vec3) -> f32,
        mut visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        const C1_SHIFT: i32 = (CELL_LOG2 + 1) as i32;
        let mut ray = CellRay::new(self, origin, dir, 0.0, t_max);
        let mut steps = 1;
        // `org`: where the ray enters its first kept cell, found as the
        // segment walk would (at `t` plus the nudge).
        let org = loop {
            if ray.t >= ray.t_end {
                return steps;
            }
            let nudge = ray.nudge();
            let voxel = voxel_of(ray.point(ray.t + nudge));
            let c1 = voxel >> C1_SHIFT;
            match partition.cell_at(c1) {
                Some(Cell::Kept(_)) => break ray.t,
                Some(Cell::Empty { distance }) => ray.leave_empty(c1, distance, nudge),
                // Past the volume's face by the nudge: an empty level-0
                // cell, as the segment walk takes it.
                None => {
                    let size = (1 << CELL_LOG2) as f32;
                    let lo = (voxel >> CELL_LOG2 as i32).as_vec3a() * size;
                    ray.leave(lo, lo + Vec3A::splat(size), nudge);
                }
            }
            steps += 1;
        };
        let mut k = 0i64;
        loop {
            let t = lattice.at(org, k);
            if t >= ray.t_end {
                return steps;
            }
            let p = origin + dir * t;
            let c1 = voxel_of(p.into()) >> C1_SHIFT;
            k += 1;
            match partition.cell_at(c1) {
                Some(Cell::Kept(_)) => {
                    let more = visit(t, lookup(p));
                    if !more {
                        return steps;
                    }
                }
                Some(Cell::Empty { distance }) => {
                    // Every later point inside the cube is empty too
                    // (the cube is convex and holds `p`).
                    steps += 1;
                    ray.t = t;
                    ray.leave_empty(c1, distance, ray.nudge());
                    k = k.max(lattice.first_from(org, ray.t));
                }
                // Outside the volume only by rounding at its face.
                None => {}
            }
        }
    }
}
