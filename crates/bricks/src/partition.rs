//! The cells a ray walk visits: an adaptive partition of the volume by the
//! bounds pyramid, fixed once per refinement rule so that each DDA step is
//! one table read instead of a search through the levels.
//!
//! The rule (see `dda.rs`) looks at a cell's bounds only: from the top level
//! down, a cell is kept whole when it is empty, uniform, tight enough
//! (`min >= TIGHT_ENOUGH x max`), or its slack across its width is at most
//! `split`; level-0 cells are always kept. A kept cell's ancestors were all
//! refined, for every point inside it, so the kept cells tile the volume
//! like the leaves of an octree, and the level of the leaf holding a point
//! depends on the point alone.
//!
//! Empty space is crossed faster still. An empty level-1 cell stores its
//! chessboard distance `d` (in level-1 cells, capped at 127) to the nearest
//! level-1 cell holding density: every cell less than `d` away is empty,
//! so the ray may jump to where it leaves that cube of `2d - 1` cells a side
//! in one step, however the cube straddles the pyramid's aligned cells
//! ("proximity clouds", Cohen and Sheffer 1994): one step crosses every
//! aligned empty cell inside that cube, between the puffs of a cloudscape or
//! from a cloud's edge to its bounding box.
//!
//! Layout: one `u8` per level-1 cell (8^3 voxels, one per brick): for a cell
//! with density, the level of the kept cell that contains it, or 0 when its
//! eight level-0 children are the kept cells; for an empty cell, `0x80 | d`.
//! A table per level-0 cell would be eight times larger for no gain:
//! level-0 cells need no decision. That is a quarter of the brick map (a
//! `u32` per brick): 128 MiB for the largest map the converter accepts
//! (2^27 bricks), 20 KiB for the corpus cloud.

use crate::bounds::{BoundsLevel, CELL_LOG2};
use crate::dda::TIGHT_ENOUGH;
use crate::volume::BrickVolume;
use glam::IVec3;

/// Flag of an empty level-1 cell's code; the low 7 bits are its distance.
const EMPTY: u8 = 0x80;

/// What the walk finds at a level-1 cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cell {
    /// The cell holds density and lies in a kept cell of this level.
    Kept(usize),
    /// The cell is empty, and so is every level-1 cell at a chessboard
    /// distance below `distance` (at least 1).
    Empty { distance: u32 },
}

/// Per level-1 cell, the kept cell or the empty cube holding it (see the module doc).
#[derive(Clone, Debug)]
pub struct CellPartition {
    /// Level-1 cells per axis.
    dims: [u32; 3],
    levels: Vec<u8>,
    /// Level-0 cells whose slack across their width exceeds this are walked
    /// voxel by voxel.
    pub(crate) voxel_split: f32,
}

/// Whether the walk keeps a cell of level `l` with bounds `(lo, hi)` whole.
#[inline]
pub(crate) fn keep_whole(lo: f32, hi: f32, l: usize, split: f32) -> bool {
    let width = (1u32 << (CELL_LOG2 + l as u32)) as f32;
    hi <= 0.0 || lo >= hi * TIGHT_ENOUGH || (hi - lo) * width <= split || l == 0
}

impl CellPartition {
    /// The kept cell or empty cube holding level-1 cell `c`, or `None`
    /// outside the volume.
    #[inline]
    pub fn cell_at(&self, c: IVec3) -> Option<Cell> {
        let [dx, dy, dz] = self.dims;
        // Negative coordinates wrap to huge u32s and fail the same test.
        let (x, y, z) = (c.x as u32, c.y as u32, c.z as u32);
        if x >= dx || y >= dy || z >= dz {
            return None;
        }
        let i = (x as usize * dy as usize + y as usize) * dz as usize + z as usize;
        let code = self.levels[i];
        Some(if code & EMPTY != 0 {
            Cell::Empty {
                distance: u32::from(code & !EMPTY),
            }
        } else {
            Cell::Kept(code as usize)
        })
    }
}

impl BrickVolume {
    /// The partition the walk uses when it refines cells whose slack
    /// exceeds `split` density x voxels, and walks level-0 cells whose
    /// slack exceeds `voxel_split` voxel by voxel.
    pub fn partition(&self, split: f32, voxel_split: f32) -> CellPartition {
        let split = split.max(0.0);
        let Some(level0) = self.levels.first() else {
            return CellPartition {
                dims: [0; 3],
                levels: Vec::new(),
                voxel_split,
            };
        };
        let dims = level0.dims.map(|d| d.div_ceil(2));
        let mut table = vec![0u8; dims.iter().map(|&d| d as usize).product()];
        let top = self.levels.len() - 1;
        if top >= 1 {
            let [tx, ty, tz] = self.levels[top].dims;
            for x in 0..tx as i32 {
                for y in 0..ty as i32 {
                    for z in 0..tz as i32 {
                        mark(&self.levels, top, [x, y, z], split, dims, &mut table);
                    }
                }
            }
            mark_empty_distances(&self.levels[1], &mut table);
        }
        CellPartition {
            dims,
            levels: table,
            voxel_split,
        }
    }
}

/// Replaces the code of every empty level-1 cell by `EMPTY | d`, with `d`
/// its chessboard distance to the nearest cell with density, capped at 127
/// (also where the volume has no density at all). The two-pass chamfer
/// transform with unit weights over the 26 neighbours is exact for the
/// chessboard metric (Rosenfeld and Pfaltz 1966).
fn mark_empty_distances(level1: &BoundsLevel, table: &mut [u8]) {
    const CAP: u8 = 127;
    let [dx, dy, dz] = level1.dims.map(|d| d as i32);
    let at = |x: i32, y: i32, z: i32| ((x * dy + y) * dz + z) as usize;
    let mut dist = vec![CAP; table.len()];
    for x in 0..dx {
        for y in 0..dy {
            for z in 0..dz {
                if level1.get_inside([x as u32, y as u32, z as u32]).1 > 0.0 {
                    dist[at(x, y, z)] = 0;
                }
            }
        }
    }
    // Forward pass: neighbours earlier in x-major order; backward: later.
    let mut relax = |x: i32, y: i32, z: i32, sign: i32| {
        let mut best = dist[at(x, y, z)];
        for (ox, oy, oz) in HALF_NEIGHBOURS {
            let (nx, ny, nz) = (x + sign * ox, y + sign * oy, z + sign * oz);
            if (0..dx).contains(&nx) && (0..dy).contains(&ny) && (0..dz).contains(&nz) {
                best = best.min(dist[at(nx, ny, nz)].saturating_add(1).min(CAP));
            }
        }
        dist[at(x, y, z)] = best;
    };
    for x in 0..dx {
        for y in 0..dy {
            for z in 0..dz {
                relax(x, y, z, 1);
            }
        }
    }
    for x in (0..dx).rev() {
        for y in (0..dy).rev() {
            for z in (0..dz).rev() {
                relax(x, y, z, -1);
            }
        }
    }
    for (code, d) in table.iter_mut().zip(dist) {
        if d > 0 {
            *code = EMPTY | d;
        }
    }
}

/// The 13 neighbours that come before a cell in x-major order.
const HALF_NEIGHBOURS: [(i32, i32, i32); 13] = [
    (-1, -1, -1),
    (-1, -1, 0),
    (-1, -1, 1),
    (-1, 0, -1),
    (-1, 0, 0),
    (-1, 0, 1),
    (-1, 1, -1),
    (-1, 1, 0),
    (-1, 1, 1),
    (0, -1, -1),
    (0, -1, 0),
    (0, -1, 1),
    (0, 0, -1),
];

/// Visits cell `c` of level `l` (>= 1): records its level over its level-1
/// cells if the rule keeps it whole, else visits its children. Level-1
/// cells that are refined keep their 0.
fn mark(levels: &[BoundsLevel], l: usize, c: [i32; 3], split: f32, dims: [u32; 3], out: &mut [u8]) {
    let (lo, hi) = levels[l].get(c);
    if keep_whole(lo, hi, l, split) {
        let span = 1i32 << (l - 1);
        let lo_c = c.map(|v| v * span);
        let hi_c = [0, 1, 2].map(|k| (lo_c[k] + span).min(dims[k] as i32));
        for x in lo_c[0]..hi_c[0] {
            for y in lo_c[1]..hi_c[1] {
                let row = (x as usize * dims[1] as usize + y as usize) * dims[2] as usize;
                out[row + lo_c[2] as usize..row + hi_c[2] as usize].fill(l as u8);
            }
        }
    } else if l > 1 {
        for k in 0..8 {
            let child = [
                2 * c[0] + (k >> 2),
                2 * c[1] + ((k >> 1) & 1),
                2 * c[2] + (k & 1),
            ];
            if (0..3).all(|a| (child[a] as u32) < levels[l - 1].dims[a]) {
                mark(levels, l - 1, child, split, dims, out);
            }
        }
    }
}
