//! Converting a float grid's tree into bricks: leaves become stored or
//! constant bricks, tiles become constant bricks, then the bounds pyramid is
//! built over what was stored (so it bounds the values the renderer reads,
//! after quantisation). Trees and streamed files share one builder
//! (`build.rs`): stored bricks are numbered in leaf order, constants in
//! map order.

use crate::bounds::{BoundsLevel, CELL_LOG2};
use crate::build::{write_leaves, Builder, Start};
use crate::layout::{BrickRef, Precision, BRICK, BRICK_LOG2};
use crate::volume::{Atlas, BrickVolume, SourceInfo};
use crate::BrickError;
use cirrus_vdb::{Grid, GridClass, Tree};
use glam::IVec3;
use rayon::prelude::*;

/// Largest brick map a conversion builds: 2^27 bricks (512 MiB of map,
/// 64 Gi voxels of bounds), far past production clouds.
pub const MAX_MAP_BRICKS: u64 = 1 << 27;

/// Slack on the stored bounds against float rounding in the trilinear
/// lerp, so `min <= density <= max` holds to the last bit.
pub(crate) const BOUND_SLACK: f32 = 1.0 / (1 << 20) as f32;

/// Converts a fog-volume (or unknown-class) float grid into bricks.
///
/// Density policy: inactive voxels are the background, which must be 0;
/// NaN, infinite and negative values are stored as 0 and counted in
/// [`SourceInfo::sanitized_voxels`]. Level sets are refused: their values
/// are distances, not densities.
pub fn convert(grid: &Grid, precision: Precision) -> Result<BrickVolume, BrickError> {
    let tree = grid.float_tree().ok_or_else(|| {
        BrickError::Unsupported(format!(
            "grid {:?} holds {} values; only float grids convert",
            grid.name,
            grid.tree.value_type().name()
        ))
    })?;
    if grid.class == GridClass::LevelSet {
        return Err(BrickError::Unsupported(format!(
            "grid {:?} is a level set (signed distances, not density); convert it to a fog volume first",
            grid.name
        )));
    }
    if tree.background() != 0.0 {
        return Err(BrickError::Unsupported(format!(
            "grid {:?} has background {}; a density grid needs background 0",
            grid.name,
            tree.background()
        )));
    }
    let mut volume = convert_tree(tree, precision)?;
    volume.index_to_world = grid.transform.index_to_world_matrix();
    volume.info.grid_name = grid.name.clone();
    Ok(volume)
}

/// Converts a float tree (any class, background 0) into bricks: the
/// same volume, bit for bit, as [`crate::convert_file`] streams from the
/// tree's file.
pub fn convert_tree(tree: &Tree<f32>, precision: Precision) -> Result<BrickVolume, BrickError> {
    let leaves = tree.leaves();
    let mut b = match Builder::start(
        tree.active_bbox(),
        tree.active_voxel_count(),
        leaves.len(),
        precision,
    )? {
        Start::Empty(v) => return Ok(v),
        Start::Build(b) => b,
    };
    let mut tiles = Ok(());
    tree.for_each_active_tile(|bbox, v, _| {
        if tiles.is_ok() {
            tiles = b.tile(bbox, v);
        }
    });
    tiles?;
    b.place_leaves(leaves.iter().map(|l| l.origin));
    write_leaves(b.sink(), leaves.len(), |i| {
        (&leaves[i].value_mask, &*leaves[i].values)
    })?;
    b.finish()
}

pub(crate) fn empty_volume(precision: Precision, active_voxels: u64) -> BrickVolume {
    let atlas = match precision {
        Precision::F32 => Atlas::F32(Vec::new().into()),
        Precision::F16 => Atlas::F16(Vec::new().into()),
        Precision::U8 => Atlas::U8(Vec::new().into()),
    };
    BrickVolume {
        origin: IVec3::ZERO,
        dims: [0; 3],
        index_to_world: glam::DMat4::IDENTITY,
        map: Vec::new().into(),
        constants: Vec::new().into(),
        ranges: Vec::new().into(),
        atlas,
        levels: Vec::new(),
        info: SourceInfo {
            active_voxels,
            ..Default::default()
        },
        finest_partition: Default::default(),
    }
}

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
