//! A fixed grid of per-cell density bounds walked with a 3D DDA: pbrt-v4's
//! `MajorantGrid` + `DDAMajorantIterator` (media.h), extended with a
//! minorant per cell for residual ratio tracking.

use glam::Vec3;

use super::field::{Bounds3, MajorantSegment};

/// Per-cell `[min, max]` of the density over a box split into equal cubes.
#[derive(Clone, Debug)]
pub struct MajorantGrid {
    lo: Vec3,
    cell: f32,
    dims: [u32; 3],
    /// `(minorant, majorant)` per cell, x fastest.
    bounds: Vec<(f32, f32)>,
}

impl MajorantGrid {
    /// A grid with corner `lo`, cubic cells of render-space size `cell`, and
    /// `dims` cells per axis; `bounds(i, j, k)` gives each cell's
    /// `(minorant, majorant)`.
    pub fn new(
        lo: Vec3,
        cell: f32,
        dims: [u32; 3],
        mut bounds: impl FnMut(u32, u32, u32) -> (f32, f32),
    ) -> Self {
        let mut out = Vec::with_capacity(dims.iter().map(|&d| d as usize).product());
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    out.push(bounds(i, j, k));
                }
            }
        }
        Self {
            lo,
            cell,
            dims,
            bounds: out,
        }
    }

    pub fn hi(&self) -> Vec3 {
        self.lo
            + self.cell
                * Vec3::new(
                    self.dims[0] as f32,
                    self.dims[1] as f32,
                    self.dims[2] as f32,
                )
    }

    /// Largest majorant of any cell.
    pub fn max_majorant(&self) -> f32 {
        self.bounds.iter().fold(0.0, |m, b| m.max(b.1))
    }

    #[inline]
    fn cell_bounds(&self, c: [i32; 3]) -> (f32, f32) {
        let (nx, ny) = (self.dims[0] as usize, self.dims[1] as usize);
        self.bounds[c[0] as usize + nx * (c[1] as usize + ny * c[2] as usize)]
    }

    /// Amanatides and Woo (1987) traversal of the cells the ray crosses
    /// within `[t_min, t_max]`, one segment per cell, front to back.
    pub fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> DdaSegments<'_> {
        let mut it = DdaSegments {
            grid: self,
            origin,
            dir,
            cell: [0; 3],
            step: [0; 3],
            t_next: [f32::INFINITY; 3],
            t: 0.0,
            t_end: 0.0,
            done: true,
        };
        let bounds = Bounds3::new(self.lo, self.hi());
        let Some((t0, t1)) = bounds.clip_ray(origin, dir, t_min, t_max) else {
            return it;
        };
        if t1 <= t0 {
            return it;
        }
        let rel = (origin + t0 * dir - self.lo) / self.cell;
        for axis in 0..3 {
            // Clamp: the entry point can round to just outside the box.
            let c = (rel[axis].floor() as i32).clamp(0, self.dims[axis] as i32 - 1);
            it.cell[axis] = c;
            let d = dir[axis];
            if d > 0.0 {
                it.step[axis] = 1;
            } else if d < 0.0 {
                it.step[axis] = -1;
            }
            it.t_next[axis] = it.boundary_t(axis, c);
        }
        it.t = t0;
        it.t_end = t1;
        it.done = false;
        it
    }
}

/// Iterator over the cells a ray crosses; see [`MajorantGrid::segments`].
pub struct DdaSegments<'a> {
    grid: &'a MajorantGrid,
    origin: Vec3,
    dir: Vec3,
    cell: [i32; 3],
    step: [i32; 3],
    t_next: [f32; 3],
    t: f32,
    t_end: f32,
    done: bool,
}

impl DdaSegments<'_> {
    /// Ray parameter of the face through which the ray leaves cell `c` along
    /// `axis`. Computed from the plane rather than by adding `t_delta`
    /// repeatedly, so rounding errors do not accumulate along long rays.
    fn boundary_t(&self, axis: usize, c: i32) -> f32 {
        let d = self.dir[axis];
        if d == 0.0 {
            return f32::INFINITY;
        }
        let face = if d > 0.0 { c + 1 } else { c };
        (self.grid.lo[axis] + face as f32 * self.grid.cell - self.origin[axis]) / d
    }
}

impl Iterator for DdaSegments<'_> {
    type Item = MajorantSegment;

    fn next(&mut self) -> Option<MajorantSegment> {
        while !self.done {
            let axis = if self.t_next[0] < self.t_next[1] {
                if self.t_next[0] < self.t_next[2] {
                    0
                } else {
                    2
                }
            } else if self.t_next[1] < self.t_next[2] {
                1
            } else {
                2
            };
            let t0 = self.t;
            let t1 = self.t_next[axis].clamp(t0, self.t_end);
            let (minorant, majorant) = self.grid.cell_bounds(self.cell);
            self.t = t1;
            if t1 >= self.t_end {
                self.done = true;
            } else {
                self.cell[axis] += self.step[axis];
                if self.cell[axis] < 0 || self.cell[axis] >= self.grid.dims[axis] as i32 {
                    self.done = true;
                } else {
                    self.t_next[axis] = self.boundary_t(axis, self.cell[axis]);
                }
            }
            if t1 > t0 {
                return Some(MajorantSegment {
                    t0,
                    t1,
                    minorant,
                    majorant,
                });
            }
        }
        None
    }
}
