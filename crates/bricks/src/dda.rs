//! Front-to-back majorant segments along a ray, from the bounds pyramid.
//!
//! At each step the walk finds the cell that contains the ray just past the
//! current `t`, then looks at the pyramid from the coarsest level down:
//! - an empty cell (max 0) is skipped whole, at the coarsest level that is
//!   empty, so empty space costs a step per coarse cell;
//! - a uniform cell (min == max: a tile, a constant region) is one segment
//!   at whatever level it is uniform;
//! - a cell whose minorant is at least half its majorant is one segment
//!   (delta tracking there takes at most one null collision per real one
//!   on average, so finer cells would buy little for more steps);
//! - a cell whose bounds differ by less than `split` across its width (in
//!   density x voxels) is one segment: the caller sets `split` to the
//!   optical-depth slack it accepts, which is Blender Cycles' rule for its
//!   majorant octree (a node splits while range x size x scale > 1.442):
//!   crossing such a cell costs on average at most that many extra null
//!   collisions, so refining it would cost more steps than it saves;
//! - otherwise the walk descends, down to 4^3 cells, which are always one
//!   segment each.
//!
//! - at extreme optical thickness (the caller's `voxel_split`: a finest
//!   cell whose bounds differ by that many density x voxels), the walk goes
//!   down to single voxel cells bounded by their eight corners, so a steep
//!   edge in a dense medium does not cost millions of null collisions.
//!
//! Neighbouring segments with the same bounds merge into one. The ray is
//! given in local index coordinates of the volume (`BrickVolume::local_from_world`
//! applied to a world ray): an affine map keeps the ray parameter, so `t`
//! stays the caller's (world) distance along its direction.
//!
//! Robustness: the cell is located at `t + nudge` (a relative and an
//! absolute epsilon along the ray) so a point on a cell face is placed in the
//! cell being entered, and every step advances `t` by at least the nudge,
//! so the walk ends after at most (length / nudge) steps whatever the
//! rounding: no infinite loop for rays along faces, edges or corners.

use crate::bounds::CELL_LOG2;
use crate::volume::BrickVolume;
use glam::Vec3;

/// A cell with `minorant >= TIGHT_ENOUGH * majorant` is not refined.
pub const TIGHT_ENOUGH: f32 = 0.5;

/// Over `[t0, t1]` the density lies within `[minorant, majorant]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaySegment {
    pub t0: f32,
    pub t1: f32,
    pub minorant: f32,
    pub majorant: f32,
}

/// Iterator of [`RaySegment`]s; see the module doc.
pub struct SegmentIter<'a> {
    volume: &'a BrickVolume,
    origin: Vec3,
    dir: Vec3,
    inv_dir: Vec3,
    t: f32,
    t_end: f32,
    pending: Option<RaySegment>,
    /// Pyramid steps taken (cells visited), for statistics.
    pub steps: u32,
    /// Level of the last cell visited.
    level: usize,
    /// Absolute part of the nudge: 1e-5 voxels along the ray's major axis.
    nudge_abs: f32,
    /// Cells whose (max - min) x width in voxels is at most this are not refined.
    split: f32,
    /// Finest cells whose (max - min) x width exceeds this are walked voxel by voxel.
    voxel_split: f32,
}

/// Slab test of a ray against the box [lo, hi]: the parameter interval inside.
pub fn ray_box(origin: Vec3, inv_dir: Vec3, lo: Vec3, hi: Vec3) -> (f32, f32) {
    let a = (lo - origin) * inv_dir;
    let b = (hi - origin) * inv_dir;
    // NaN (0 * inf for a ray on a slab face) is dropped by min/max.
    let t0 = a.min(b).max_element();
    let t1 = a.max(b).min_element();
    (t0, t1)
}

impl<'a> SegmentIter<'a> {
    pub fn new(volume: &'a BrickVolume, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self {
        let inv_dir = dir.recip();
        let (b0, b1) = ray_box(origin, inv_dir, Vec3::ZERO, volume.local_extent());
        // For exits: a zero component never exits (+inf, whatever the sign of zero).
        let inv_dir = Vec3::select(dir.cmpeq(Vec3::ZERO), Vec3::INFINITY, inv_dir);
        let valid = origin.is_finite() && dir.is_finite() && dir != Vec3::ZERO;
        let (t, t_end) = if valid {
            (t_min.max(b0), t_max.min(b1))
        } else {
            (0.0, 0.0)
        };
        SegmentIter {
            volume,
            origin,
            dir,
            inv_dir,
            t,
            t_end,
            pending: None,
            steps: 0,
            level: 0,
            nudge_abs: 1e-5 / dir.abs().max_element(),
            split: 0.0,
            voxel_split: f32::INFINITY,
        }
    }

    /// The next raw (unmerged) segment, or `None` at the end of the ray.
    fn step(&mut self) -> Option<RaySegment> {
        let levels = &self.volume.levels;
        let top = levels.len().saturating_sub(1);
        while self.t < self.t_end {
            self.steps += 1;
            let nudge = self.t.abs() * 1e-6 + self.nudge_abs;
            let p = self.origin + self.dir * (self.t + nudge);
            let voxel = p.floor().as_ivec3();
            let bounds_at =
                |l: usize| levels[l].get((voxel >> (CELL_LOG2 + l as u32) as i32).to_array());
            // Start one level above where the last step ended: climb while the
            // parent is empty (to skip empty space at the coarsest level),
            // then descend to the first cell that is empty, tight enough, or
            // finest. Starting low only ever gives finer (still valid) cells.
            let mut l = (self.level + 1).min(top);
            while l < top && bounds_at(l + 1).1 <= 0.0 {
                l += 1;
            }
            let (mut lo, mut hi) = loop {
                let (lo, hi) = bounds_at(l);
                let width = (1u32 << (CELL_LOG2 + l as u32)) as f32;
                if hi <= 0.0 || lo >= hi * TIGHT_ENOUGH || (hi - lo) * width <= self.split || l == 0
                {
                    break (lo, hi);
                }
                l -= 1;
            };
            self.level = l;
            // Exit through the cell's far faces (the near ones are behind us).
            let mut size = (1i32 << (CELL_LOG2 + l as u32)) as f32;
            let mut cell_lo = (voxel >> (CELL_LOG2 + l as u32) as i32).as_vec3() * size;
            if l == 0 && hi > lo && (hi - lo) * size > self.voxel_split {
                // A finest cell so optically thick that even its few voxels
                // of slack cost many null collisions: bound the one voxel
                // cell [v, v + 1) by its eight corner voxels instead.
                (lo, hi) = self.volume.voxel_cell_range(voxel);
                size = 1.0;
                cell_lo = voxel.as_vec3();
            }
            let far =
                cell_lo + Vec3::select(self.dir.cmpge(Vec3::ZERO), Vec3::splat(size), Vec3::ZERO);
            let exit = ((far - self.origin) * self.inv_dir).min_element();
            let t0 = self.t;
            let t1 = exit.max(t0 + nudge).min(self.t_end);
            self.t = t1;
            if hi > 0.0 {
                return Some(RaySegment {
                    t0,
                    t1,
                    minorant: lo,
                    majorant: hi,
                });
            }
        }
        None
    }
}

impl Iterator for SegmentIter<'_> {
    type Item = RaySegment;

    fn next(&mut self) -> Option<RaySegment> {
        loop {
            match (self.step(), self.pending) {
                (None, _) => return self.pending.take(),
                (Some(s), None) => self.pending = Some(s),
                (Some(s), Some(p)) => {
                    if p.t1 == s.t0 && p.majorant == s.majorant && p.minorant == s.minorant {
                        self.pending = Some(RaySegment { t1: s.t1, ..p });
                    } else {
                        self.pending = Some(s);
                        return Some(p);
                    }
                }
            }
        }
    }
}

impl BrickVolume {
    /// Majorant segments of the ray `origin + t * dir` (local index
    /// coordinates) within `[t_min, t_max]`.
    pub fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> SegmentIter<'_> {
        SegmentIter::new(self, origin, dir, t_min, t_max)
    }

    /// Segments that stop refining where a cell's bounds differ by at most
    /// `split` density x voxels across its width, and walk finest cells
    /// whose bounds differ by more than `voxel_split` voxel by voxel (see
    /// the module doc).
    pub fn segments_with_split(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
        split: f32,
        voxel_split: f32,
    ) -> SegmentIter<'_> {
        SegmentIter {
            split: split.max(0.0),
            voxel_split,
            ..SegmentIter::new(self, origin, dir, t_min, t_max)
        }
    }
}
