//! Level 0 of the bounds pyramid: the range of the stored voxels over each
//! 4^3 cell and the first layer of its +x, +y and +z neighbours (what a
//! trilinear lookup inside the cell reads), computed from the bricks
//! after quantisation, so the bounds hold for the values the renderer
//! reads. The builder makes it once per volume; the motion shell
//! (`dilate.rs`) widens its ranges with the same slack.

use crate::bounds::{BoundsLevel, CELL_LOG2};
use crate::layout::{BrickRef, BRICK, BRICK_LOG2};
use crate::volume::BrickVolume;
use glam::IVec3;
use rayon::prelude::*;

/// Slack on the stored bounds against float rounding in the trilinear
/// lerp, so `min <= density <= max` holds to the last bit.
pub(crate) const BOUND_SLACK: f32 = 1.0 / (1 << 20) as f32;

/// Level 0 of the pyramid: for each 4^3 cell, the range of the stored
/// voxels over `[o, o + 4]` per axis (the cell and the first layer of its
/// +x, +y and +z neighbours), widened by [`BOUND_SLACK`] unless the range
/// is a single value. Computed a brick at a time from one gathered 9^3
/// block (the brick and its +1 layer), in parallel over x-slabs of bricks,
/// each writing its own rows of the level.
pub(crate) fn brick_bounds(v: &BrickVolume) -> BoundsLevel {
    const SUB: usize = 1 << (BRICK_LOG2 - CELL_LOG2); // cells per brick side
    let dims = v.dims.map(|d| d << (BRICK_LOG2 - CELL_LOG2));
    let [_, by, bz] = v.dims.map(|d| d as i32);
    let (dy, dz) = (dims[1] as usize, dims[2] as usize);
    let mut cells = vec![0f32; 2 * dims.iter().map(|&d| d as usize).product::<usize>()];
    let slab = 2 * SUB * dy * dz; // floats per x-slab of bricks
    if slab > 0 {
        cells
            .par_chunks_mut(slab)
            .enumerate()
            .for_each(|(bx, out)| {
                for y in 0..by {
                    for z in 0..bz {
                        let ranges = brick_cell_ranges(v, IVec3::new(bx as i32, y, z));
                        for (k, &[lo, hi]) in ranges.iter().enumerate() {
                            let c = [
                                k / (SUB * SUB),
                                y as usize * SUB + (k / SUB) % SUB,
                                z as usize * SUB + k % SUB,
                            ];
                            let at = 2 * ((c[0] * dy + c[1]) * dz + c[2]);
                            let (lo, hi) = if lo == hi {
                                (lo, hi)
                            } else {
                                (lo - lo.abs() * BOUND_SLACK, hi + hi.abs() * BOUND_SLACK)
                            };
                            out[at] = lo;
                            out[at + 1] = hi;
                        }
                    }
                }
            });
    }
    BoundsLevel {
        dims,
        cells: cells.into(),
    }
}

/// The (min, max) of each 4^3 cell of brick `b` over its `[o, o + 4]` voxels.
#[allow(clippy::needless_range_loop)] // the indices are cell coordinates
fn brick_cell_ranges(v: &BrickVolume, b: IVec3) -> [[f32; 2]; 8] {
    let all_empty =
        (0..8).all(|k| v.brick_ref(b + IVec3::new(k >> 2, (k >> 1) & 1, k & 1)) == BrickRef::Empty);
    if all_empty {
        return [[0.0; 2]; 8];
    }
    const N: usize = BRICK as usize + 1;
    let mut block = [0f32; N * N * N];
    v.gather_block(b, &mut block);
    // Separable: over z, then y, then x, each window [0, 4] or [4, 8]
    // (CELL + 1 voxels, the cells share their middle layer).
    const S: usize = 1 << CELL_LOG2;
    let range = |vals: &[f32]| {
        vals.iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            })
    };
    let mut zr = [[(0f32, 0f32); 2]; N * N];
    for (xy, row) in block.chunks_exact(N).enumerate() {
        for c in 0..2 {
            zr[xy][c] = range(&row[c * S..=c * S + S]);
        }
    }
    let merge = |a: (f32, f32), b: (f32, f32)| (a.0.min(b.0), a.1.max(b.1));
    let mut yr = [[[(0f32, 0f32); 2]; 2]; N];
    for x in 0..N {
        for cy in 0..2 {
            for cz in 0..2 {
                yr[x][cy][cz] = (cy * S..=cy * S + S)
                    .map(|y| zr[x * N + y][cz])
                    .fold((f32::INFINITY, f32::NEG_INFINITY), merge);
            }
        }
    }
    std::array::from_fn(|k| {
        let (cx, cy, cz) = (k >> 2, (k >> 1) & 1, k & 1);
        let (lo, hi) = (cx * S..=cx * S + S)
            .map(|x| yr[x][cy][cz])
            .fold((f32::INFINITY, f32::NEG_INFINITY), merge);
        [lo, hi]
    })
}
