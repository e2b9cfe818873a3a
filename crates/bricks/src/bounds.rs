//! The majorant/minorant hierarchy: per brick, then per 2^3 block of the
//! level below, a (min, max) pair that bounds the trilinearly interpolated
//! density anywhere inside the cell.
//!
//! Level 0 cells are `CELL` = 4 voxels a side (8 per brick); level `k`
//! cells are `4 << k` voxels a side, so level 1 is the brick. A cell's
//! bounds are taken over the voxels `[o, o + CELL]` per axis: trilinear
//! interpolation at any point of `[o, o + CELL)` reads exactly those (its
//! corner voxels are `floor(p)` and `floor(p) + 1`), and is a convex
//! combination of them, so it can neither exceed their max nor fall below
//! their min. Cells finer than a brick are what lets the bounds follow a
//! cloud's soft edges: at 4 voxels (+1 for the filter) they are tighter than
//! pbrt-v4's 64^3 grid over a few-hundred-voxel cloud, whose cells are a few
//! voxels wide but padded by one voxel on both sides. Coarser cells take the max of
//! their children's maxima and the min of their minima (a child outside the
//! grid counts as (0, 0): the density there is zero). The pyramid stops at a
//! single cell or at [`MAX_LEVELS`].
//!
//! Stored as f32 pairs, 8 bytes a cell; the whole pyramid is about
//! 8/7 x 64 bytes per brick (an eighth of a u8 brick's voxels).

use crate::section::Section;

/// log2 of the side of a level-0 cell in voxels.
pub const CELL_LOG2: u32 = 2;
/// Most levels: level 8 cells are 1024 voxels wide.
pub const MAX_LEVELS: usize = 9;

/// One level of the pyramid: a dense grid of (min, max) pairs.
#[derive(Clone, Debug)]
pub struct BoundsLevel {
    /// Cells per axis.
    pub dims: [u32; 3],
    /// `2 * dims.x * dims.y * dims.z` floats: min then max, x-major.
    pub cells: Section<f32>,
}

impl BoundsLevel {
    /// The x-major index of cell `c`, as `x (dy dz) + (y dz + z)`: the
    /// two products independent, where `(x dy + y) dz + z` chains them
    /// (the index is on every cell walk step's critical path).
    #[inline]
    pub fn index(&self, c: [u32; 3]) -> usize {
        let [_, dy, dz] = self.dims.map(|d| d as usize);
        c[0] as usize * (dy * dz) + (c[1] as usize * dz + c[2] as usize)
    }

    /// (min, max) of a cell; cells outside the level are (0, 0).
    #[inline]
    pub fn get(&self, c: [i32; 3]) -> (f32, f32) {
        if c.iter()
            .zip(self.dims)
            .any(|(&v, d)| v < 0 || v as u32 >= d)
        {
            return (0.0, 0.0);
        }
        let i = 2 * self.index([c[0] as u32, c[1] as u32, c[2] as u32]);
        (self.cells[i], self.cells[i + 1])
    }

    /// (min, max) of a cell the caller knows to be inside the level.
    #[inline]
    pub fn get_inside(&self, c: [u32; 3]) -> (f32, f32) {
        debug_assert!((0..3).all(|k| c[k] < self.dims[k]));
        let i = 2 * self.index(c);
        (self.cells[i], self.cells[i + 1])
    }

    pub fn cell_count(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }

    pub fn bytes(&self) -> usize {
        self.cells.len() * 4
    }
}

/// Builds the coarser levels above `level0`, each in parallel over its x-planes.
pub fn build_pyramid(level0: BoundsLevel) -> Vec<BoundsLevel> {
    use rayon::prelude::*;
    let mut levels = vec![level0];
    while levels.len() < MAX_LEVELS {
        let below = levels.last().unwrap();
        if below.dims.iter().all(|&d| d <= 1) {
            break;
        }
        let dims = below.dims.map(|d| d.div_ceil(2));
        let plane = 2 * dims[1] as usize * dims[2] as usize;
        let mut cells = vec![0f32; plane * dims[0] as usize];
        if plane > 0 {
            cells
                .par_chunks_mut(plane)
                .enumerate()
                .for_each(|(x, out)| {
                    let x = x as i32;
                    for y in 0..dims[1] as i32 {
                        for z in 0..dims[2] as i32 {
                            let (mut lo, mut hi) = (f32::INFINITY, 0f32);
                            for k in 0..8 {
                                let c = [2 * x + (k >> 2), 2 * y + ((k >> 1) & 1), 2 * z + (k & 1)];
                                let (a, b) = below.get(c);
                                lo = lo.min(a);
                                hi = hi.max(b);
                            }
                            let i = 2 * (y as usize * dims[2] as usize + z as usize);
                            out[i] = lo;
                            out[i + 1] = hi;
                        }
                    }
                });
        }
        levels.push(BoundsLevel {
            dims,
            cells: cells.into(),
        });
    }
    levels
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coarse_cells_bound_their_children_and_count_outside_as_zero() {
        // 3 x 1 x 1 bricks: (1, 2), (0.5, 4), (3, 3).
        let level0 = BoundsLevel {
            dims: [3, 1, 1],
            cells: vec![1.0, 2.0, 0.5, 4.0, 3.0, 3.0].into(),
        };
        let levels = build_pyramid(level0);
        assert_eq!(levels.len(), 3);
        assert_eq!(levels[1].dims, [2, 1, 1]);
        // Cell 0 covers bricks 0,1 and four outside-y/z children: min 0.
        assert_eq!(levels[1].get([0, 0, 0]), (0.0, 4.0));
        assert_eq!(levels[1].get([1, 0, 0]), (0.0, 3.0));
        assert_eq!(levels[2].get([0, 0, 0]), (0.0, 4.0));
        assert_eq!(levels[2].get([1, 0, 0]), (0.0, 0.0));
    }
}
