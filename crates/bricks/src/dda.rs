//! Front-to-back majorant segments along a ray, from the bounds pyramid.
//!
//! At each step the walk finds the cell that contains the ray just past the
//! current `t`: the cell the pyramid would give looking from the coarsest
//! level down, read from a [`CellPartition`] made once for the rule
//! (`partition.rs`), so a step is a table read and a slab exit whatever the
//! depth. The rule:
//! - an empty cell (max 0) is skipped whole; where a whole brick is empty
//!   the walk jumps the largest empty cube of bricks around it (the
//!   partition stores each empty brick's distance to density), so empty
//!   space costs a step per cube;
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
//! - at extreme optical thickness (the partition's `voxel_split`: a finest
//!   cell whose bounds differ by that many density x voxels), the walk goes
//!   down to single voxel cells bounded by their eight corners, so a steep
//!   edge in a dense medium does not cost millions of null collisions.
//!
//! Each segment is yielded as the walk leaves its cell, never held back to
//! merge with a neighbour of the same bounds: such neighbours are rare
//! (2% more segments on the corpus cloud without merging), and merging
//! would cost every walk one step past the segment it ends in (a free
//! flight ends at its collision, a shadow ray at its roulette), measured
//! at about 8% of a path-traced render. The ray is
//! given in local index coordinates of the volume (`BrickVolume::local_from_world`
//! applied to a world ray): an affine map keeps the ray parameter, so `t`
//! stays the caller's (world) distance along its direction.
//!
//! Robustness: the cell is located at `t + nudge` (a relative and an
//! absolute epsilon along the ray) so a point on a cell face is placed in the
//! cell being entered, and every step advances `t` by at least the nudge,
//! so the walk ends after at most (length / nudge) steps whatever the
//! rounding: no infinite loop for rays along faces, edges or corners.

use crate::aabb::Bounds3;
use crate::bounds::CELL_LOG2;
use crate::partition::{Cell, CellPartition};
use crate::segment::MajorantSegment;
use crate::volume::BrickVolume;
use crate::voxel_of::voxel_of;
use glam::{BVec3A, IVec3, Vec3, Vec3A};

/// A ray in a volume's local index space, clipped to the volume's box, and
/// the walk's position `t` along it: what every cell walk over a
/// [`CellPartition`] shares (the segment walk here, the lattice march in
/// `lattice.rs`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CellRay {
    /// In vector lanes, as are the direction and its inverse: every step
    /// computes with all three axes at once.
    origin: Vec3A,
    dir: Vec3A,
    /// `1 / dir`, with `+inf` where a component is zero (it never exits).
    inv_dir: Vec3A,
    /// Where the walk is.
    pub t: f32,
    /// Where the ray leaves the volume (or ends).
    pub t_end: f32,
    /// Absolute part of the nudge: 1e-5 voxels along the ray's major axis.
    nudge_abs: f32,
    /// Per axis, whether the ray leaves a cell through its upper face.
    upward: BVec3A,
}

impl CellRay {
    /// The ray clipped to the volume's box and to `[t_min, t_max]`; a ray
    /// with a non-finite or zero direction is empty, and so is one whose
    /// exit from the box is not finite (a direction too small to leave
    /// it), so every walk has a finite length to cross.
    ///
    /// The clip treats a zero direction component as lying in its slab
    /// or not by the origin alone ([`Bounds3::clip_ray`]): a slab test
    /// with `1 / 0 = inf` gives `0 * inf = NaN` for an origin on one of
    /// that axis's faces, which an ordered `min`/`max` can carry into the
    /// ray's end, and a walk toward `t = inf` takes ~1e8 steps.
    pub fn new(volume: &BrickVolume, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self {
        // For exits: a zero component never exits (+inf, whatever the sign of zero).
        let inv_dir = Vec3::select(dir.cmpeq(Vec3::ZERO), Vec3::INFINITY, dir.recip());
        let valid = origin.is_finite() && dir.is_finite() && dir != Vec3::ZERO;
        let clipped = valid
            .then(|| {
                Bounds3::new(Vec3::ZERO, volume.local_extent()).clip_ray(origin, dir, t_min, t_max)
            })
            .flatten()
            .filter(|&(t0, t1)| t0.is_finite() && t1.is_finite());
        let (t, t_end) = clipped.unwrap_or((0.0, 0.0));
        CellRay {
            origin: origin.into(),
            dir: dir.into(),
            inv_dir: inv_dir.into(),
            t,
            t_end,
            nudge_abs: 1e-5 / dir.abs().max_element(),
            upward: Vec3A::from(dir).cmpge(Vec3A::ZERO),
        }
    }

    /// The point at `t`.
    #[inline]
    pub fn point(&self, t: f32) -> Vec3A {
        self.origin + self.dir * t
    }

    /// How far past `t` the walk looks up the cell it is in (see the
    /// module doc's robustness note).
    #[inline]
    pub fn nudge(&self) -> f32 {
        self.t.abs() * 1e-6 + self.nudge_abs
    }

    /// Moves `t` to where the ray leaves the box `[lo, hi]` through its far
    /// faces (the near ones are behind it), by at least `nudge` and at most
    /// to the end of the ray; returns the `t` it left from. Every step ends
    /// here, so every step makes progress (the module doc's guarantee).
    #[inline]
    pub fn leave(&mut self, lo: Vec3A, hi: Vec3A, nudge: f32) -> f32 {
        let far = Vec3A::select(self.upward, hi, lo);
        let exits = (far - self.origin) * self.inv_dir;
        let t0 = self.t;
        // An exit at or behind `t0` means the point the walk located by
        // rounded onto this cell's far face: the points the lookups see
        // stay in this cell until that coordinate moves one ulp past the
        // face, which takes `ulp / |d|` along the ray. Such an exit is
        // moved on by that much. For an axis the ray crosses at any speed
        // that is less than the nudge, and the step is the nudge as
        // before; for an axis the ray creeps along (a component of 1e-7
        // beside 1) it is long, and the walk goes on to the next face it
        // does cross rather than creep by the nudge (which took ~1e5 steps
        // per cell). `|far| x EPSILON` bounds the face's ulp.
        let behind = exits.cmple(Vec3A::splat(t0));
        let creep = far.abs() * f32::EPSILON * self.inv_dir.abs();
        let exits = Vec3A::select(behind, exits + creep, exits);
        // Only an exit ahead of the walk bounds the step. An axis the ray
        // never crosses, from a point on one of its faces, gives
        // 0 x inf = NaN, which compares false and is dropped with the rest.
        let ahead = exits.cmpgt(Vec3A::splat(t0));
        let exit = Vec3A::select(ahead, exits, Vec3A::INFINITY).min_element();
        // `exit` is never NaN, nor are the ray's ends, so plain compares
        // give `exit.max(..).min(t_end)` without the NaN fix-ups
        // `f32::max` and `min` compile to, a few cycles on the step's
        // critical path. No exit ahead at all (only by rounding on the
        // major axis) still moves the walk by the nudge.
        let least = t0 + nudge;
        let t = if exit > least && exit < f32::INFINITY {
            exit
        } else {
            least
        };
        self.t = if t < self.t_end { t } else { self.t_end };
        t0
    }

    /// Moves `t` past the empty cube of level-1 cells within
    /// `distance - 1` of level-1 cell `c1` (a [`Cell::Empty`]).
    #[inline]
    pub fn leave_empty(&mut self, c1: IVec3, distance: u32, nudge: f32) {
        let r = distance as i32 - 1;
        let side = (1 << (CELL_LOG2 + 1)) as f32;
        let lo = (c1 - r).as_vec3a() * side;
        let hi = (c1 + (r + 1)).as_vec3a() * side;
        self.leave(lo, hi, nudge);
    }
}

/// Iterator of [`MajorantSegment`]s; see the module doc.
pub struct SegmentIter<'a> {
    volume: &'a BrickVolume,
    partition: &'a CellPartition,
    ray: CellRay,
    /// Pyramid steps taken (cells visited), for statistics.
    pub steps: u32,
}

impl<'a> SegmentIter<'a> {
    pub fn new(
        volume: &'a BrickVolume,
        partition: &'a CellPartition,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> Self {
        SegmentIter {
            volume,
            partition,
            ray: CellRay::new(volume, origin, dir, t_min, t_max),
            steps: 0,
        }
    }
}

impl Iterator for SegmentIter<'_> {
    type Item = MajorantSegment;

    /// The segment of the next cell with density, or `None` at the end of
    /// the ray.
    #[inline]
    fn next(&mut self) -> Option<MajorantSegment> {
        loop {
            match self.walk() {
                Found::Segment(s) => return Some(s),
                Found::End => return None,
                Found::VoxelCell(voxel, nudge) => {
                    if let Some(s) = self.voxel_cell(voxel, nudge) {
                        return Some(s);
                    }
                }
            }
        }
    }
}

/// Where [`SegmentIter::walk`] stopped.
enum Found {
    Segment(MajorantSegment),
    End,
    /// A finest cell to be walked voxel by voxel, at this voxel (located
    /// with this nudge).
    VoxelCell(IVec3, f32),
}

impl SegmentIter<'_> {
    /// Walks to the next segment of a kept cell with density, or to the
    /// end, or to a cell the walk takes voxel by voxel. Nothing in the loop
    /// calls out, so the ray stays in registers: with the rare voxel cells'
    /// call inside it, every call of `next` saved and restored them all.
    #[inline(always)]
    fn walk(&mut self) -> Found {
        let levels = &self.volume.levels;
        let ray = &mut self.ray;
        while ray.t < ray.t_end {
            self.steps += 1;
            let nudge = ray.nudge();
            let voxel = voxel_of(ray.point(ray.t + nudge));
            // The kept cell or empty cube holding `p` (`partition.rs`): one
            // table read. A point outside the volume (only ever by a nudge
            // past its face) is in an empty level-0 cell.
            let c1 = voxel >> (CELL_LOG2 + 1) as i32;
            // The level-0 cell's bounds, read beside the partition's code
            // rather than after it: most kept cells of a dense cloud are
            // finest cells, and the code's level then no longer delays
            // their read (the walk is a chain of dependent reads).
            let finest = levels.first().map_or((0.0, 0.0), |l0| {
                l0.get((voxel >> CELL_LOG2 as i32).to_array())
            });
            let (l, (lo, hi)) = match self.partition.cell_at(c1) {
                Some(Cell::Kept(0)) => (0, finest),
                // Level-l cells hold whole level-1 cells, and level 0 has
                // twice level 1's cells per axis: `voxel >> shift` is inside.
                Some(Cell::Kept(l)) => (
                    l,
                    levels[l].get_inside(
                        (voxel >> (CELL_LOG2 + l as u32) as i32)
                            .as_uvec3()
                            .to_array(),
                    ),
                ),
                Some(Cell::Empty { distance }) => {
                    ray.leave_empty(c1, distance, nudge);
                    continue;
                }
                None => (0, (0.0, 0.0)),
            };
            let shift = (CELL_LOG2 + l as u32) as i32;
            let size = (1i32 << shift) as f32;
            if l == 0 && hi > lo && (hi - lo) * size > self.partition.voxel_split {
                return Found::VoxelCell(voxel, nudge);
            }
            let cell_lo = (voxel >> shift).as_vec3a() * size;
            let t0 = ray.leave(cell_lo, cell_lo + Vec3A::splat(size), nudge);
            if hi > 0.0 {
                return Found::Segment(MajorantSegment {
                    t0,
                    t1: ray.t,
                    minorant: lo,
                    majorant: hi,
                });
            }
        }
        Found::End
    }

    /// A finest cell so optically thick that even its few voxels of slack
    /// cost many null collisions: the one voxel cell `[voxel, voxel + 1)`
    /// bounded by its eight corner voxels instead, its segment if it has
    /// density.
    #[cold]
    #[inline(never)]
    fn voxel_cell(&mut self, voxel: IVec3, nudge: f32) -> Option<MajorantSegment> {
        let (lo, hi) = self.volume.voxel_cell_range(voxel);
        let cell_lo = voxel.as_vec3a();
        let t0 = self.ray.leave(cell_lo, cell_lo + Vec3A::ONE, nudge);
        (hi > 0.0).then_some(MajorantSegment {
            t0,
            t1: self.ray.t,
            minorant: lo,
            majorant: hi,
        })
    }
}

impl BrickVolume {
    /// Majorant segments of the ray `origin + t * dir` (local index
    /// coordinates) within `[t_min, t_max]`, refined down to level-0 cells
    /// wherever their bounds differ (split 0, no per-voxel cells).
    pub fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> SegmentIter<'_> {
        let finest = self
            .finest_partition
            .get_or_init(|| self.partition(0.0, f32::INFINITY));
        SegmentIter::new(self, finest, origin, dir, t_min, t_max)
    }

    /// Segments over the cells of `partition` (made by
    /// [`BrickVolume::partition`] from this volume).
    pub fn segments_in<'a>(
        &'a self,
        partition: &'a CellPartition,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> SegmentIter<'a> {
        SegmentIter::new(self, partition, origin, dir, t_min, t_max)
    }
}
