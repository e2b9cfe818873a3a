//! The in-scattered radiance learned on a regular grid over the media,
//! finer than the regions' tree: what adjoint-driven roulette and
//! splitting (`integrator/path_split.rs`) compare a path's expected
//! contribution by.
//!
//! Layout: cubic cells, [`CELLS_LONGEST`] along the bounds' longest axis
//! at the finest of four levels, x fastest, each level above with half
//! the cells along each axis. A thick cloud's in-scattered light falls by orders of
//! magnitude from its lit rim into its core over a few mean free paths,
//! so the estimate must resolve the rim; the regions (tens after a short
//! training) average rim and core together. A cell holds a sum and a
//! count (12 bytes), so 48^3 cells and their levels above stay under 1.5 MB.

use glam::{UVec3, Vec3};

use crate::medium::Bounds3;

/// Cells along the longest axis of the bounds, at the finest level.
pub const CELLS_LONGEST: u32 = 48;
/// Levels, each with half the cells of the one below along each axis
/// (48, 24, 12, 6 along the longest).
const LEVELS: usize = 4;
/// A cell's own mean counts once it has this many samples.
pub const MIN_CELL_RECORDS: u32 = 16;

/// One level's sums and counts, x fastest.
#[derive(Clone, Debug)]
struct Level {
    dims: UVec3,
    sums: Vec<f64>,
    counts: Vec<u32>,
}

impl Level {
    fn new(dims: UVec3) -> Level {
        let n = (dims.x * dims.y * dims.z) as usize;
        Level {
            dims,
            sums: vec![0.0; n],
            counts: vec![0; n],
        }
    }

    #[inline]
    fn index(&self, c: UVec3) -> usize {
        (c.x + self.dims.x * (c.y + self.dims.y * c.z)) as usize
    }
}

/// Mean in-scattered radiance (luminance) per cell, on a pyramid of
/// grids: a lookup takes the finest cell that has learned enough, so the
/// rim is resolved where samples are many and a coarser mean stands in
/// where they are few.
#[derive(Clone, Debug)]
pub struct InscatteredGrid {
    origin: Vec3,
    /// Finest cells per unit length.
    scale: f32,
    levels: Vec<Level>,
}

impl InscatteredGrid {
    /// An empty grid over `bounds`.
    pub fn new(bounds: Bounds3) -> InscatteredGrid {
        let size = bounds.size().max(Vec3::splat(1e-6));
        let scale = CELLS_LONGEST as f32 / size.max_element();
        let dims = (size * scale)
            .ceil()
            .as_uvec3()
            .clamp(UVec3::ONE, UVec3::splat(CELLS_LONGEST));
        let levels = (0..LEVELS)
            .map(|k| Level::new(((dims - UVec3::ONE) >> k as u32) + UVec3::ONE))
            .collect();
        InscatteredGrid {
            origin: bounds.min,
            scale,
            levels,
        }
    }

    /// The finest cell holding `p`, points outside taking the nearest.
    #[inline]
    pub fn cell_of(&self, p: Vec3) -> u32 {
        let fine = &self.levels[0];
        let c = ((p - self.origin) * self.scale).max(Vec3::ZERO).as_uvec3();
        fine.index(c.min(fine.dims - UVec3::ONE)) as u32
    }

    /// The coordinates of finest cell `cell`, if it is one.
    #[inline]
    fn coords(&self, cell: u32) -> Option<UVec3> {
        let d = self.levels[0].dims;
        (cell < d.x * d.y * d.z)
            .then(|| UVec3::new(cell % d.x, (cell / d.x) % d.y, cell / (d.x * d.y)))
    }

    /// Learns one sample of the in-scattered radiance in finest cell
    /// `cell` (and in the cells above it).
    pub fn add(&mut self, cell: u32, inscattered: f32) {
        let Some(c) = self.coords(cell).filter(|_| inscattered.is_finite()) else {
            return;
        };
        for (k, level) in self.levels.iter_mut().enumerate() {
            let i = level.index(c >> k as u32);
            level.sums[i] += f64::from(inscattered.max(0.0));
            level.counts[i] += 1;
        }
    }

    /// The mean in-scattered radiance of the finest cell above finest cell
    /// `cell` that has learned enough, if any has.
    #[inline]
    pub fn mean(&self, cell: u32) -> Option<f32> {
        let c = self.coords(cell)?;
        self.levels.iter().enumerate().find_map(|(k, level)| {
            let i = level.index(c >> k as u32);
            let n = level.counts[i];
            (n >= MIN_CELL_RECORDS).then(|| (level.sums[i] / f64::from(n)) as f32)
        })
    }

    /// Cells at the finest level.
    pub fn cells(&self) -> usize {
        self.levels[0].sums.len()
    }

    pub fn memory_bytes(&self) -> usize {
        self.levels
            .iter()
            .map(|l| l.sums.capacity() * 8 + l.counts.capacity() * 4)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cells are cubic with 48 along the longest axis; points find the cell
    /// whose box holds them, points outside the nearest one; a cell's own
    /// mean shows once it has 16 samples, before that its parent's (two
    /// cells along each axis) once that has 16.
    #[test]
    fn points_find_their_cell_and_cells_learn_means() {
        let mut g = InscatteredGrid::new(Bounds3::new(Vec3::ZERO, Vec3::new(4.0, 2.0, 1.0)));
        assert_eq!(g.levels[0].dims, UVec3::new(48, 24, 12));
        assert_eq!(g.levels[3].dims, UVec3::new(6, 3, 2));
        assert_eq!(g.cells(), 48 * 24 * 12);
        let p = Vec3::new(1.0 + 0.5 / 12.0, 0.5 + 0.5 / 12.0, 0.99);
        assert_eq!(g.cell_of(p), 12 + 48 * (6 + 24 * 11));
        assert_eq!(g.cell_of(Vec3::splat(-5.0)), 0);
        assert_eq!(g.cell_of(Vec3::splat(50.0)), (g.cells() - 1) as u32);
        let c = g.cell_of(p);
        // A sibling under the same parent (x 13 against 12).
        let sibling = g.cell_of(p + Vec3::new(1.0 / 12.0, 0.0, 0.0));
        for k in 0..15 {
            g.add(c, k as f32);
        }
        assert_eq!(g.mean(c), None);
        g.add(sibling, 105.0);
        assert_eq!(
            g.mean(c),
            Some(13.125),
            "the parent's mean, (105 + 105) / 16"
        );
        g.add(c, 15.0);
        g.add(c, f32::NAN);
        assert_eq!(g.mean(c), Some(7.5));
        assert_eq!(g.mean(sibling), Some((120.0 + 105.0) / 17.0));
        assert_eq!(g.mean(0), None);
        assert_eq!(g.mean(u32::MAX), None);
        g.add(u32::MAX, 1.0);
    }
}
