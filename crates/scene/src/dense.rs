//! A grid read into a dense array over an index box, for array libraries
//! (numpy through the Python bindings).

use std::path::Path;

use cirrus_vdb::{Coord, ValueType, VolumeFile};

use crate::error::{Error, Result};

/// The most values one dense read may hold (8 GiB of f32): a box that a
/// typo made huge is refused before anything is allocated.
pub const MAX_DENSE_VALUES: u64 = 1 << 31;

/// Values over an inclusive index box, x slowest and the channel fastest
/// (C order for the shape `[nx, ny, nz]` or `[nx, ny, nz, 3]`).
#[derive(Clone, Debug, PartialEq)]
pub struct Dense {
    pub shape: Vec<usize>,
    /// Float and vec3s grids; `None` for the others.
    pub f32: Option<Vec<f32>>,
    /// Double, integer and boolean grids (exact in f64 up to 2^53).
    pub f64: Option<Vec<f64>>,
}

/// Grid `name` of `path` over `[lo, hi]` (inclusive, index space); without
/// a box, over the grid's active box (an empty grid gives shape `[0, 0, 0]`).
/// Inactive voxels hold the background, as OpenVDB's dense copy does.
pub fn read_dense(path: &Path, name: &str, bbox: Option<([i32; 3], [i32; 3])>) -> Result<Dense> {
    let file = VolumeFile::open(path)?;
    let index = file
        .find_grid(name)
        .map_err(|e| Error::input(e.to_string()))?;
    let grid = file.read_grid(index)?;
    let tree = &grid.tree;
    let (lo, hi) = match bbox {
        Some(b) => b,
        None => match tree.active_bbox() {
            Some(b) => (b.min.to_array(), b.max.to_array()),
            None => ([0; 3], [-1; 3]),
        },
    };
    let dims: Vec<u64> = (0..3)
        .map(|a| (i64::from(hi[a]) - i64::from(lo[a]) + 1).max(0) as u64)
        .collect();
    let n = tree.background_components().1;
    let count = dims
        .iter()
        .try_fold(n as u64, |acc, &d| acc.checked_mul(d))
        .unwrap_or(u64::MAX);
    if count > MAX_DENSE_VALUES {
        return Err(Error::input(format!(
            "{}: a dense box of {}x{}x{} x {n} values is over the limit of {MAX_DENSE_VALUES}",
            path.display(),
            dims[0],
            dims[1],
            dims[2]
        )));
    }
    let mut values = Vec::with_capacity(count as usize);
    for x in 0..dims[0] as i32 {
        for y in 0..dims[1] as i32 {
            for z in 0..dims[2] as i32 {
                let c = Coord::new(lo[0] + x, lo[1] + y, lo[2] + z);
                let (v, _, _) = tree.probe_components(c);
                values.extend_from_slice(&v[..n]);
            }
        }
    }
    let mut shape: Vec<usize> = dims.iter().map(|&d| d as usize).collect();
    if n > 1 {
        shape.push(n);
    }
    let single = matches!(tree.value_type(), ValueType::Float | ValueType::Vec3f);
    Ok(Dense {
        shape,
        f32: single.then(|| values.iter().map(|&v| v as f32).collect()),
        f64: (!single).then_some(values),
    })
}
