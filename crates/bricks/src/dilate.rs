//! Bounds that stay true while the density moves: the motion-blur shell.
//!
//! A moving density is looked up at `x - d` for some displacement `d`
//! with `|d_i| <= radius_i` voxels per axis (the velocity grid's largest
//! value times the shutter's farthest time). So over the whole shutter
//! the density inside a level-0 cell is bounded by the (min, max) of the
//! cells within `ceil(radius_i / 4)` cells of it per axis: a box max
//! (min) filter of level 0, separable into three 1D passes. Density may
//! also move out of the brick grid, so the shell is the grid padded by
//! whole bricks on every side, with no voxels of its own: only its bounds
//! pyramid is walked (with `voxel_split` infinite, so no walk reads a
//! voxel of it), the density still comes from the volume.
//!
//! Cost: the filter is van Herk / Gil-Werman, three comparisons per cell
//! and pass whatever the radius; the shell's pyramid is as large as the
//! volume's plus the padding. Null collisions grow with the dilation:
//! every cell near a moving edge takes the densest value within reach.
//!
//! Small displacements (up to [`MAX_VOXEL_REACH`] voxels) are then
//! tightened from the voxels themselves: a cell's bounds become the range
//! of the voxels `[4c - ceil(R), 4c + 4 + ceil(R)]` per axis, exactly what
//! trilinear lookups at displaced points of the cell can read, instead of
//! whole neighbouring cells (a 1-voxel displacement widens a cell's reach
//! from 5 to 7 voxels instead of to 13).

use glam::{IVec3, Vec3};

use crate::bounds::{build_pyramid, BoundsLevel, CELL_LOG2};
use crate::cell_bounds::BOUND_SLACK;
use crate::layout::MAX_MAP_BRICKS;
use crate::layout::{BRICK, BRICK_LOG2};
use crate::volume::{Atlas, BrickVolume, SourceInfo};
use crate::BrickError;

impl BrickVolume {
    /// The shell of this volume for displacements of up to `radius`
    /// voxels per axis (see the module doc). Its local coordinates are
    /// this volume's plus [`BrickVolume::shell_offset`] of the result.
    pub fn motion_shell(&self, radius: Vec3) -> Result<BrickVolume, BrickError> {
        if !radius.is_finite() || radius.min_element() < 0.0 {
            return Err(BrickError::Unsupported(format!(
                "motion radius {radius} must be finite and >= 0 voxels"
            )));
        }
        let cell = (1u32 << CELL_LOG2) as f32;
        // Cells of reach per axis, and whole bricks of padding covering them.
        let reach = (radius / cell).ceil().as_ivec3();
        let pad = (reach + 1) / 2;
        let dims_i = IVec3::from_array(self.dims.map(|d| d as i32)) + 2 * pad;
        let count: u64 = dims_i.to_array().iter().map(|&d| d as u64).product();
        if count > MAX_MAP_BRICKS {
            return Err(BrickError::TooLarge(format!(
                "motion blur pads the grid to {dims_i} bricks, more than {MAX_MAP_BRICKS}; \
                 lower the shutter or velocity scale"
            )));
        }
        let dims = dims_i.to_array().map(|d| d as u32);
        let level0 = match self.levels.first() {
            Some(l0) => {
                let mut cells = dilated_level0(l0, dims, pad * 2, reach);
                let voxels = radius.ceil().as_ivec3();
                if voxels.max_element() <= MAX_VOXEL_REACH {
                    tighten_from_voxels(self, &mut cells, pad * 2, voxels);
                }
                cells
            }
            None => BoundsLevel {
                dims: [0; 3],
                cells: Vec::new().into(),
            },
        };
        let levels = if self.levels.is_empty() {
            Vec::new()
        } else {
            build_pyramid(level0)
        };
        Ok(BrickVolume {
            origin: self.origin - pad * BRICK,
            dims,
            index_to_world: self.index_to_world,
            map: vec![0u32; count as usize].into(),
            constants: Vec::new().into(),
            ranges: Vec::new().into(),
            atlas: Atlas::F32(Vec::new().into()),
            levels,
            info: SourceInfo {
                grid_name: format!("{} (motion shell)", self.info.grid_name),
                ..Default::default()
            },
            finest_partition: Default::default(),
        })
    }

    /// Where `shell`'s local coordinates put this volume's origin.
    pub fn shell_offset(&self, shell: &BrickVolume) -> Vec3 {
        (self.origin - shell.origin).as_vec3()
    }
}

/// Displacements up to this many voxels get bounds read from the voxels.
pub const MAX_VOXEL_REACH: i32 = 3;

/// Replaces the bounds of every non-empty cell of the shell's level 0
/// (cells `offset` in from the volume's) by the range of the volume's
/// voxels within `reach` voxels of the cell's `[4c, 4c + 4]` (see the
/// module doc), widened by the converter's slack. Empty cells stay empty:
/// their voxel box lies inside the neighbourhood that made them empty.
fn tighten_from_voxels(v: &BrickVolume, level: &mut BoundsLevel, offset: IVec3, reach: IVec3) {
    use rayon::prelude::*;
    let [_, ny, nz] = level.dims.map(|d| d as usize);
    let mut cells = level.cells.to_vec();
    let side = 1i32 << CELL_LOG2;
    cells
        .par_chunks_mut(2 * ny * nz)
        .enumerate()
        .for_each(|(x, plane)| {
            for y in 0..ny {
                for z in 0..nz {
                    let i = 2 * (y * nz + z);
                    if plane[i + 1] <= 0.0 {
                        continue;
                    }
                    let c = IVec3::new(x as i32, y as i32, z as i32) - offset;
                    let (lo, hi) = voxel_range(v, c * side - reach, c * side + side + reach);
                    (plane[i], plane[i + 1]) = if lo == hi {
                        (lo, hi)
                    } else {
                        (lo - lo.abs() * BOUND_SLACK, hi + hi.abs() * BOUND_SLACK)
                    };
                }
            }
        });
    level.cells = cells.into();
}

/// (min, max) of the volume's voxels in the box `[a, b]` (inclusive).
fn voxel_range(v: &BrickVolume, a: IVec3, b: IVec3) -> (f32, f32) {
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for x in a.x..=b.x {
        for y in a.y..=b.y {
            for z in a.z..=b.z {
                let d = v.voxel(IVec3::new(x, y, z));
                lo = lo.min(d);
                hi = hi.max(d);
            }
        }
    }
    (lo, hi)
}

/// Level 0 of the shell: the volume's level 0 placed `offset` cells in,
/// (0, 0) around it, then max-filtered (maxima) and min-filtered (minima)
/// over `reach` cells per axis.
fn dilated_level0(
    l0: &BoundsLevel,
    brick_dims: [u32; 3],
    offset: IVec3,
    reach: IVec3,
) -> BoundsLevel {
    let sub = 1usize << (BRICK_LOG2 - CELL_LOG2);
    let n = brick_dims.map(|d| d as usize * sub);
    let total = n[0] * n[1] * n[2];
    let (mut lo, mut hi) = (vec![0f32; total], vec![0f32; total]);
    let at = |x: usize, y: usize, z: usize| (x * n[1] + y) * n[2] + z;
    let [ox, oy, oz] = offset.to_array().map(|o| o as usize);
    for x in 0..l0.dims[0] as usize {
        for y in 0..l0.dims[1] as usize {
            for z in 0..l0.dims[2] as usize {
                let (a, b) = l0.get_inside([x as u32, y as u32, z as u32]);
                let i = at(x + ox, y + oy, z + oz);
                lo[i] = a;
                hi[i] = b;
            }
        }
    }
    for axis in 0..3 {
        let r = reach[axis] as usize;
        if r == 0 {
            continue;
        }
        filter_axis(&mut hi, n, axis, r, f32::max);
        filter_axis(&mut lo, n, axis, r, f32::min);
    }
    let mut cells = Vec::with_capacity(2 * total);
    for (a, b) in lo.into_iter().zip(hi) {
        cells.push(a);
        cells.push(b);
    }
    BoundsLevel {
        dims: n.map(|d| d as u32),
        cells: cells.into(),
    }
}

/// Replaces every line of `data` (dims `n`, x-major) along `axis` by its
/// running `pick` (max or min) over a window of `r` cells each side,
/// counting cells past the ends as 0 (no density there).
fn filter_axis(data: &mut [f32], n: [usize; 3], axis: usize, r: usize, pick: fn(f32, f32) -> f32) {
    let stride = [n[1] * n[2], n[2], 1][axis];
    let len = n[axis];
    let (others_a, others_b) = match axis {
        0 => (n[1], n[2]),
        1 => (n[0], n[2]),
        _ => (n[0], n[1]),
    };
    let mut line = vec![0f32; len];
    let mut out = vec![0f32; len];
    let mut scratch = Scratch::default();
    for a in 0..others_a {
        for b in 0..others_b {
            let start = match axis {
                0 => a * n[2] + b,
                1 => a * n[1] * n[2] + b,
                _ => (a * n[1] + b) * n[2],
            };
            for (i, v) in line.iter_mut().enumerate() {
                *v = data[start + i * stride];
            }
            window(&line, r, &mut out, pick, &mut scratch);
            for (i, v) in out.iter().enumerate() {
                data[start + i * stride] = *v;
            }
        }
    }
}

/// Buffers of [`window`], reused across lines.
#[derive(Default)]
struct Scratch {
    padded: Vec<f32>,
    prefix: Vec<f32>,
    suffix: Vec<f32>,
}

/// van Herk / Gil-Werman: `out[i] = pick(src[i - r ..= i + r])` with zeros
/// past the ends, in three `pick`s per cell whatever `r`.
fn window(src: &[f32], r: usize, out: &mut [f32], pick: fn(f32, f32) -> f32, s: &mut Scratch) {
    let w = 2 * r + 1;
    let m = src.len() + 2 * r;
    s.padded.clear();
    s.padded.resize(r, 0.0);
    s.padded.extend_from_slice(src);
    s.padded.resize(m, 0.0);
    s.prefix.clear();
    s.prefix.extend_from_slice(&s.padded);
    s.suffix.clear();
    s.suffix.extend_from_slice(&s.padded);
    for j in 1..m {
        if j % w != 0 {
            s.prefix[j] = pick(s.prefix[j - 1], s.padded[j]);
        }
    }
    for j in (0..m - 1).rev() {
        if (j + 1) % w != 0 {
            s.suffix[j] = pick(s.suffix[j + 1], s.padded[j]);
        }
    }
    // Window [i, i + 2r] of the padded line = src[i - r ..= i + r].
    for (i, o) in out.iter_mut().enumerate() {
        *o = pick(s.suffix[i], s.prefix[i + 2 * r]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_window_filter_is_the_brute_force_one() {
        let src: Vec<f32> = (0..37).map(|i| ((i * 7919) % 23) as f32 + 1.0).collect();
        for r in 0..9 {
            let mut out = vec![0.0; src.len()];
            window(&src, r, &mut out, f32::max, &mut Scratch::default());
            let mut low = vec![0.0; src.len()];
            window(&src, r, &mut low, f32::min, &mut Scratch::default());
            for i in 0..src.len() {
                let lo = i as i64 - r as i64;
                let hi = i as i64 + r as i64;
                let vals: Vec<f32> = (lo..=hi)
                    .map(|j| {
                        if j < 0 || j >= src.len() as i64 {
                            0.0
                        } else {
                            src[j as usize]
                        }
                    })
                    .collect();
                assert_eq!(
                    out[i],
                    vals.iter().cloned().fold(f32::MIN, f32::max),
                    "r {r} i {i}"
                );
                assert_eq!(
                    low[i],
                    vals.iter().cloned().fold(f32::MAX, f32::min),
                    "r {r} i {i}"
                );
            }
        }
    }
}
