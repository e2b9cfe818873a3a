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
use glam::IVec3;
use rayon::prelude::*;

/// A cell with `minorant >= TIGHT_ENOUGH * majorant` is not refined.
pub const TIGHT_ENOUGH: f32 = 0.5;

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
        // Two independent products (see `BoundsLevel::index`).
        let (dy, dz) = (dy as usize, dz as usize);
        let i = x as usize * (dy * dz) + (y as usize * dz + z as usize);
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

impl CellPartition {
    /// Level-1 cells per axis.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// The table as stored, one code a level-1 cell, x-major (see the
    /// module doc's layout): what a device walk uploads to read as this
    /// walk does.
    pub fn codes(&self) -> &[u8] {
        &self.levels
    }

    /// The slack past which a level-0 cell is walked voxel by voxel.
    pub fn voxel_split(&self) -> f32 {
        self.voxel_split
    }
}

impl CellPartition {
    /// The partition of a bounds pyramid (`levels`, finest first) that the
    /// walk uses when it refines cells whose slack exceeds `split` density
    /// x voxels, and walks level-0 cells whose slack exceeds `voxel_split`
    /// voxel by voxel.
    pub fn refined(levels: &[BoundsLevel], split: f32, voxel_split: f32) -> CellPartition {
        let split = split.max(0.0);
        let Some(level0) = levels.first() else {
            return CellPartition {
                dims: [0; 3],
                levels: Vec::new(),
                voxel_split,
            };
        };
        let dims = level0.dims.map(|d| d.div_ceil(2));
        let top = levels.len() - 1;
        let table = if top >= 1 {
            let mut table = kept_levels(levels, split);
            mark_empty_distances(&levels[1], &mut table);
            table
        } else {
            vec![0u8; dims.iter().map(|&d| d as usize).product()]
        };
        CellPartition {
            dims,
            levels: table,
            voxel_split,
        }
    }
}

impl CellPartition {
    /// The partition a ray march uses: every cell holding density is kept
    /// at `level` (clamped to the pyramid's levels), never refined by its
    /// bounds, and no cell is walked voxel by voxel; empty level-1 cells
    /// keep their distances. A march needs to know only where density is,
    /// not how tight its bound is, and it looks every lattice point up
    /// anyway: so a coarse kept cell costs one step for the several lattice
    /// points inside it, and the lookups it adds are those of the empty
    /// voxels sharing a kept cell with density, which return at the brick
    /// map.
    pub fn occupancy(levels: &[BoundsLevel], level: usize) -> CellPartition {
        let mut p = CellPartition::refined(levels, f32::INFINITY, f32::INFINITY);
        let top = levels.len().saturating_sub(1);
        let code = level.min(top) as u8;
        for c in p.levels.iter_mut().filter(|c| **c & EMPTY == 0) {
            *c = code;
        }
        p
    }
}

/// Replaces the code of every empty level-1 cell by `EMPTY | d`, with `d`
/// its chessboard distance to the nearest cell with density, capped at 127
/// (also where the volume has no density at all).
///
/// The chessboard distance is separable: the distance over a box is the
/// 1-D transform `out[i] = min_j max(|i - j|, g[j])` applied along z, then
/// y, then x (a cube of radius r holds a cell with density exactly when
/// its x-line holds a cell whose yz-square of radius r does). Each pass
/// runs over independent lines in parallel; the cap is the starting value
/// of every empty cell. Equal, cell for cell, to the two-pass 26-neighbour
/// chamfer transform (Rosenfeld and Pfaltz 1966; the tests compare them).
fn mark_empty_distances(level1: &BoundsLevel, table: &mut [u8]) {
    let [dx, dy, dz] = level1.dims.map(|d| d as usize);
    if dx * dy * dz == 0 {
        return;
    }
    let plane = dy * dz;
    let mut dist = vec![0u8; table.len()];
    dist.par_chunks_mut(plane).enumerate().for_each(|(x, out)| {
        let mut line = Vec::new();
        let mut stack = Vec::new();
        for y in 0..dy {
            for z in 0..dz {
                let filled = level1.get_inside([x as u32, y as u32, z as u32]).1 > 0.0;
                out[y * dz + z] = if filled { 0 } else { CAP };
            }
            // z: contiguous lines.
            distance_line(&mut out[y * dz..(y + 1) * dz], &mut line, &mut stack);
        }
        // y: lines of the plane, gathered.
        let mut col = vec![0u8; dy];
        for z in 0..dz {
            for y in 0..dy {
                col[y] = out[y * dz + z];
            }
            distance_line(&mut col, &mut line, &mut stack);
            for y in 0..dy {
                out[y * dz + z] = col[y];
            }
        }
    });
    // x: per y, the dx x dz block of lines across every plane, transformed
    // into its own buffer, then written back plane by plane.
    let rows: Vec<Vec<u8>> = (0..dy)
        .into_par_iter()
        .map(|y| {
            let mut block = vec![0u8; dx * dz];
            let (mut col, mut line, mut stack) = (vec![0u8; dx], Vec::new(), Vec::new());
            for z in 0..dz {
                for x in 0..dx {
                    col[x] = dist[x * plane + y * dz + z];
                }
                distance_line(&mut col, &mut line, &mut stack);
                for x in 0..dx {
                    block[x * dz + z] = col[x];
                }
            }
            block
        })
        .collect();
    table
        .par_chunks_mut(plane)
        .enumerate()
        .for_each(|(x, codes)| {
            for (y, row) in rows.iter().enumerate() {
                let d = &row[x * dz..(x + 1) * dz];
                for (code, &d) in codes[y * dz..(y + 1) * dz].iter_mut().zip(d) {
                    if d > 0 {
                        *code = EMPTY | d;
                    }
                }
            }
        });
}

/// Largest distance stored: 7 bits.
const CAP: u8 = 127;

/// The 1-D chessboard transform of `g` in place: `g[i] = min_j max(|i -
/// j|, g[j])`, as the smaller of a left and a right sweep. A sweep keeps the
/// candidates no later one dominates (a later `j` with `g[j]` no larger
/// beats an earlier one at every `i` ahead): their `g` rise as their
/// positions do, so `max(i - j, g[j])` is smallest where `g[j] + j` first
/// reaches `i`, found by binary search among at most 128 candidates.
fn distance_line(g: &mut [u8], left: &mut Vec<u8>, stack: &mut Vec<(u32, u8)>) {
    fn sweep(g: &[u8], out: &mut [u8], stack: &mut Vec<(u32, u8)>, rev: bool) {
        let n = g.len();
        stack.clear();
        for k in 0..n {
            let i = if rev { n - 1 - k } else { k };
            let v = g[i];
            while stack.last().is_some_and(|&(_, t)| t >= v) {
                stack.pop();
            }
            stack.push((k as u32, v));
            // First candidate with g + j >= k: its g, or the distance to the one before.
            let p = stack.partition_point(|&(j, t)| t as u32 + j < k as u32);
            let mut best = stack[p.min(stack.len() - 1)].1 as u32;
            if p > 0 {
                best = best.min(k as u32 - stack[p - 1].0);
            }
            let o = &mut out[i];
            *o = if rev {
                (*o as u32).min(best) as u8
            } else {
                best as u8
            };
        }
    }
    left.clear();
    left.resize(g.len(), 0);
    sweep(g, left, stack, false);
    sweep(g, left, stack, true);
    g.copy_from_slice(left);
}

/// Per level-1 cell, the level of the kept cell holding it (0 where its
/// level-1 ancestor is refined too): from the top down, a cell inherits
/// its parent's decision once an ancestor was kept whole, else applies the
/// rule to itself. One level at a time, in parallel over x-planes.
fn kept_levels(levels: &[BoundsLevel], split: f32) -> Vec<u8> {
    const REFINED: u8 = u8::MAX;
    let top = levels.len() - 1;
    let mut above: Vec<u8> = Vec::new();
    for l in (1..=top).rev() {
        let [_, dy, dz] = levels[l].dims.map(|d| d as usize);
        let mut codes = vec![0u8; levels[l].cell_count()];
        if dy * dz > 0 {
            let up = (l < top).then(|| (&above, levels[l + 1].dims.map(|d| d as usize)));
            codes
                .par_chunks_mut(dy * dz)
                .enumerate()
                .for_each(|(x, plane)| {
                    for y in 0..dy {
                        for z in 0..dz {
                            let inherited = up.and_then(|(above, [_, py, pz])| {
                                let c = above[((x / 2) * py + y / 2) * pz + z / 2];
                                (c != REFINED).then_some(c)
                            });
                            plane[y * dz + z] = inherited.unwrap_or_else(|| {
                                let (lo, hi) = levels[l].get_inside([x as u32, y as u32, z as u32]);
                                if keep_whole(lo, hi, l, split) {
                                    l as u8
                                } else {
                                    REFINED
                                }
                            });
                        }
                    }
                });
        }
        above = codes;
    }
    for c in above.iter_mut() {
        if *c == REFINED {
            *c = 0;
        }
    }
    above
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounds::build_pyramid;
    use cirrus_testkit::SplitMix64;

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
    fn mark(
        levels: &[BoundsLevel],
        l: usize,
        c: [i32; 3],
        split: f32,
        dims: [u32; 3],
        out: &mut [u8],
    ) {
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

    /// The partition codes as the recursive walk and the sequential
    /// chamfer transform made them before they ran in parallel.
    fn reference(levels: &[BoundsLevel], split: f32) -> Vec<u8> {
        let dims = levels[0].dims.map(|d| d.div_ceil(2));
        let mut table = vec![0u8; dims.iter().map(|&d| d as usize).product()];
        let top = levels.len() - 1;
        let [tx, ty, tz] = levels[top].dims;
        for x in 0..tx as i32 {
            for y in 0..ty as i32 {
                for z in 0..tz as i32 {
                    mark(levels, top, [x, y, z], split, dims, &mut table);
                }
            }
        }
        let level1 = &levels[1];
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
        table
    }

    #[test]
    fn parallel_passes_equal_the_recursive_walk_and_the_chamfer_transform() {
        let mut rng = SplitMix64(7);
        let mut checked = 0;
        for case in 0..60 {
            // Level-0 grids of every small shape, from empty to dense, with
            // runs longer than the distance cap in the larger ones.
            let dims = if case < 50 {
                [
                    1 + rng.next_u64() % 40,
                    1 + rng.next_u64() % 40,
                    1 + rng.next_u64() % 40,
                ]
            } else {
                [600, 3 + rng.next_u64() % 4, 2 + rng.next_u64() % 5]
            }
            .map(|d| d as u32);
            let fill = [0.0, 0.001, 0.02, 0.2, 0.7][case % 5];
            let n = dims.iter().map(|&d| d as usize).product::<usize>();
            let mut cells = vec![0f32; 2 * n];
            for c in cells.chunks_exact_mut(2) {
                if rng.unit() < fill {
                    let hi = rng.unit();
                    c[0] = hi * rng.unit();
                    c[1] = hi;
                }
            }
            let levels = build_pyramid(BoundsLevel {
                dims,
                cells: cells.into(),
            });
            if levels.len() < 2 {
                continue;
            }
            for split in [0.0, 0.5, 4.0, 1e9] {
                let mut table = kept_levels(&levels, split);
                mark_empty_distances(&levels[1], &mut table);
                assert_eq!(
                    table,
                    reference(&levels, split),
                    "case {case} dims {dims:?} split {split}"
                );
                checked += 1;
            }
        }
        assert!(checked > 150);
    }

    #[test]
    fn the_line_transform_is_the_brute_force_minimum() {
        let mut rng = SplitMix64(3);
        let (mut left, mut stack) = (Vec::new(), Vec::new());
        for _ in 0..2000 {
            let n = 1 + (rng.next_u64() % 300) as usize;
            let g: Vec<u8> = (0..n)
                .map(|_| {
                    if rng.next_u64() & 3 == 0 {
                        (rng.next_u64() % 128) as u8
                    } else {
                        CAP
                    }
                })
                .collect();
            let want: Vec<u8> = (0..n)
                .map(|i| {
                    (0..n)
                        .map(|j| (i.abs_diff(j)).max(g[j] as usize))
                        .min()
                        .unwrap() as u8
                })
                .collect();
            let mut got = g.clone();
            distance_line(&mut got, &mut left, &mut stack);
            assert_eq!(got, want, "{g:?}");
        }
    }
}
