//! Converting a float grid's tree into bricks: leaves become stored or
//! constant bricks, tiles become constant bricks, then the bounds pyramid is
//! built over what was stored (so it bounds the values the renderer reads,
//! after quantisation).

use crate::bounds::{build_pyramid, BoundsLevel, CELL_LOG2};
use crate::layout::{BrickRef, Precision, BRICK, BRICK_LOG2, BRICK_VOXELS, MAX_BRICK_INDEX};
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
const BOUND_SLACK: f32 = 1.0 / (1 << 20) as f32;

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

/// What fills one brick of the map while converting.
#[derive(Clone, Copy)]
enum Fill {
    Empty,
    Constant(f32),
    Leaf(u32),
}

/// A leaf's bricked voxels after sanitising and quantising.
struct LeafBrick {
    /// `None`: all voxels equal this value.
    constant: Option<f32>,
    bytes: Vec<u8>,
    range: (f32, f32),
    max_error: f32,
    sanitized: u64,
}

pub fn convert_tree(tree: &Tree<f32>, precision: Precision) -> Result<BrickVolume, BrickError> {
    let active_voxels = tree.active_voxel_count();
    let Some(bbox) = tree.active_bbox() else {
        return Ok(empty_volume(precision, active_voxels));
    };
    // Trilinear support reaches one voxel past the active box on each side.
    let lo = IVec3::from_array(bbox.min.to_array()) - 1;
    let hi = IVec3::from_array(bbox.max.to_array()) + 1;
    let origin = IVec3::new(
        lo.x.div_euclid(BRICK),
        lo.y.div_euclid(BRICK),
        lo.z.div_euclid(BRICK),
    ) * BRICK;
    let end = IVec3::new(
        hi.x.div_euclid(BRICK),
        hi.y.div_euclid(BRICK),
        hi.z.div_euclid(BRICK),
    ) + 1;
    let dims_i = end - origin / BRICK;
    let dims = [dims_i.x as u32, dims_i.y as u32, dims_i.z as u32];
    let count: u64 = dims.iter().map(|&d| d as u64).product();
    if count > MAX_MAP_BRICKS {
        return Err(BrickError::TooLarge(format!(
            "{dims:?} bricks ({count}) exceed the limit of {MAX_MAP_BRICKS}"
        )));
    }
    let index = |b: IVec3| {
        (b.x as usize * dims[1] as usize + b.y as usize) * dims[2] as usize + b.z as usize
    };
    let brick_of =
        |c: cirrus_vdb::Coord| (IVec3::from_array(c.to_array()) - origin) >> BRICK_LOG2 as i32;

    // 1. What fills each brick: tiles first, then leaves (a leaf and a tile never overlap).
    let mut fills = vec![Fill::Empty; count as usize];
    let mut sanitized_tiles = 0u64;
    tree.for_each_active_tile(|b, v, _| {
        let v = if v.is_finite() && v > 0.0 {
            v
        } else {
            sanitized_tiles += b.volume();
            0.0
        };
        if v == 0.0 {
            return;
        }
        let (b0, b1) = (brick_of(b.min), brick_of(b.max));
        for x in b0.x..=b1.x {
            for y in b0.y..=b1.y {
                for z in b0.z..=b1.z {
                    fills[index(IVec3::new(x, y, z))] = Fill::Constant(v);
                }
            }
        }
    });
    for (i, leaf) in tree.leaves().iter().enumerate() {
        fills[index(brick_of(leaf.origin))] = Fill::Leaf(i as u32);
    }

    // 2. Sanitise and quantise every leaf, in parallel.
    let leaf_bricks: Vec<LeafBrick> = tree
        .leaves()
        .par_iter()
        .map(|leaf| {
            let mut values = [0f32; BRICK_VOXELS];
            let mut sanitized = 0;
            for n in leaf.value_mask.iter_on() {
                let v = leaf.values[n];
                if v.is_finite() && v >= 0.0 {
                    values[n] = v;
                } else {
                    sanitized += 1;
                }
            }
            quantise(&values, precision, sanitized)
        })
        .collect::<Result<_, _>>()?;

    // 3. Number the stored bricks and constants; lay out the atlas.
    let mut map = vec![0u32; count as usize];
    let mut constants = Vec::new();
    let mut ranges = Vec::new();
    let mut atlas_bytes = Vec::new();
    let (mut stored, mut constant) = (0u64, 0u64);
    let mut info = SourceInfo {
        active_voxels,
        sanitized_voxels: sanitized_tiles,
        ..Default::default()
    };
    for (slot, fill) in map.iter_mut().zip(&fills) {
        let r = match *fill {
            Fill::Empty => BrickRef::Empty,
            Fill::Constant(v) => {
                constant += 1;
                constants.push(v);
                BrickRef::Constant((constants.len() - 1) as u32)
            }
            Fill::Leaf(i) => {
                let lb = &leaf_bricks[i as usize];
                info.max_error = info.max_error.max(lb.max_error);
                info.sanitized_voxels += lb.sanitized;
                match lb.constant {
                    Some(0.0) => BrickRef::Empty,
                    Some(v) => {
                        constant += 1;
                        constants.push(v);
                        BrickRef::Constant((constants.len() - 1) as u32)
                    }
                    None => {
                        stored += 1;
                        atlas_bytes.extend_from_slice(&lb.bytes);
                        ranges.extend([lb.range.0, lb.range.1]);
                        BrickRef::Stored((stored - 1) as u32)
                    }
                }
            }
        };
        *slot = r.encode();
    }
    if stored > MAX_BRICK_INDEX as u64 || constants.len() as u64 > MAX_BRICK_INDEX as u64 {
        return Err(BrickError::TooLarge(format!(
            "{stored} stored bricks exceed 2^30"
        )));
    }
    drop(leaf_bricks);
    info.bricks_stored = stored;
    info.bricks_constant = constant;
    info.bricks_empty = count - stored - constant;
    let atlas = match precision {
        Precision::F32 => Atlas::F32(bytemuck::pod_collect_to_vec::<u8, f32>(&atlas_bytes).into()),
        Precision::F16 => Atlas::F16(bytemuck::pod_collect_to_vec::<u8, u16>(&atlas_bytes).into()),
        Precision::U8 => Atlas::U8(atlas_bytes.into()),
    };
    if precision != Precision::U8 {
        ranges.clear();
    }
    let mut volume = BrickVolume {
        origin,
        dims,
        index_to_world: glam::DMat4::IDENTITY,
        map: map.into(),
        constants: constants.into(),
        ranges: ranges.into(),
        atlas,
        levels: Vec::new(),
        info,
        finest_partition: Default::default(),
    };
    let level0 = brick_bounds(&volume);
    volume.levels = build_pyramid(level0);
    Ok(volume)
}

fn empty_volume(precision: Precision, active_voxels: u64) -> BrickVolume {
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

/// Encodes one brick's voxels at `precision`, measuring the error.
fn quantise(
    values: &[f32; BRICK_VOXELS],
    precision: Precision,
    sanitized: u64,
) -> Result<LeafBrick, BrickError> {
    let (lo, hi) = values
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let mut brick = LeafBrick {
        constant: None,
        bytes: Vec::new(),
        range: (lo, 0.0),
        max_error: 0.0,
        sanitized,
    };
    if lo == hi {
        brick.constant = Some(lo);
        return Ok(brick);
    }
    let mut err = 0f32;
    match precision {
        Precision::F32 => brick.bytes = bytemuck::cast_slice(values).to_vec(),
        Precision::F16 => {
            if hi > half::f16::MAX.to_f32() {
                return Err(BrickError::Unsupported(format!(
                    "density {hi} does not fit in f16 (max 65504); use f32"
                )));
            }
            let h: Vec<u16> = values
                .iter()
                .map(|&v| {
                    let q = half::f16::from_f32(v);
                    err = err.max((q.to_f32() - v).abs());
                    q.to_bits()
                })
                .collect();
            brick.bytes = bytemuck::cast_slice(&h).to_vec();
        }
        Precision::U8 => {
            // voldata's scheme: 255 steps between the brick's min and max;
            // the error is at most half a step, (hi - lo) / 510.
            let step = (hi - lo) / 255.0;
            brick.range = (lo, step);
            brick.bytes = values
                .iter()
                .map(|&v| {
                    let q = ((v - lo) / step).round().clamp(0.0, 255.0);
                    err = err.max((lo + q * step - v).abs());
                    q as u8
                })
                .collect();
        }
    }
    brick.max_error = err;
    Ok(brick)
}

/// Level 0 of the pyramid: for each 4^3 cell, the range of the stored
/// voxels over `[o, o + 4]` per axis (the cell and the first layer of its
/// +x, +y and +z neighbours), widened by [`BOUND_SLACK`] unless the range
/// is a single value. Computed a brick at a time from one gathered 9^3
/// block (the brick and its +1 layer), in parallel over bricks.
fn brick_bounds(v: &BrickVolume) -> BoundsLevel {
    const SUB: usize = 1 << (BRICK_LOG2 - CELL_LOG2); // cells per brick side
    let dims = v.dims.map(|d| d << (BRICK_LOG2 - CELL_LOG2));
    let [bx, by, bz] = v.dims.map(|d| d as i32);
    let per_brick: Vec<[[f32; 2]; SUB * SUB * SUB]> = (0..bx * by * bz)
        .into_par_iter()
        .map(|i| brick_cell_ranges(v, IVec3::new(i / (by * bz), (i / bz) % by, i % bz)))
        .collect();
    let mut cells = vec![0f32; 2 * dims.iter().map(|&d| d as usize).product::<usize>()];
    let (dy, dz) = (dims[1] as usize, dims[2] as usize);
    for (i, ranges) in per_brick.iter().enumerate() {
        let b = [
            i / (by * bz) as usize,
            (i / bz as usize) % by as usize,
            i % bz as usize,
        ];
        for (k, &[lo, hi]) in ranges.iter().enumerate() {
            let c = [
                b[0] * SUB + k / (SUB * SUB),
                b[1] * SUB + (k / SUB) % SUB,
                b[2] * SUB + k % SUB,
            ];
            let at = 2 * ((c[0] * dy + c[1]) * dz + c[2]);
            let (lo, hi) = if lo == hi {
                (lo, hi)
            } else {
                (lo - lo.abs() * BOUND_SLACK, hi + hi.abs() * BOUND_SLACK)
            };
            cells[at] = lo;
            cells[at + 1] = hi;
        }
    }
    BoundsLevel {
        dims,
        cells: cells.into(),
    }
}

/// The (min, max) of each 4^3 cell of brick `b` over its `[o, o + 4]` voxels.
fn brick_cell_ranges(v: &BrickVolume, b: IVec3) -> [[f32; 2]; 8] {
    let all_empty =
        (0..8).all(|k| v.brick_ref(b + IVec3::new(k >> 2, (k >> 1) & 1, k & 1)) == BrickRef::Empty);
    if all_empty {
        return [[0.0; 2]; 8];
    }
    const N: usize = BRICK as usize + 1;
    let mut block = [0f32; N * N * N];
    let o = b * BRICK;
    for x in 0..N {
        for y in 0..N {
            for z in 0..N {
                block[(x * N + y) * N + z] = v.voxel(o + IVec3::new(x as i32, y as i32, z as i32));
            }
        }
    }
    let size = 1usize << CELL_LOG2;
    std::array::from_fn(|k| {
        let c = [(k >> 2) * size, ((k >> 1) & 1) * size, (k & 1) * size];
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for x in c[0]..=c[0] + size {
            for y in c[1]..=c[1] + size {
                for z in c[2]..=c[2] + size {
                    let s = block[(x * N + y) * N + z];
                    lo = lo.min(s);
                    hi = hi.max(s);
                }
            }
        }
        [lo, hi]
    })
}
