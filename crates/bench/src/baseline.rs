//! The majorant structures cirrus is measured against, built from the same
//! bricks so that only the bounds differ:
//!
//! - [`GlobalMajorant`]: one majorant for the whole volume, as Mitsuba 3's
//!   heterogeneous medium uses (scale x max of the grid);
//! - [`FixedMajorantGrid`]: a fixed `res^3` grid of maxima over the volume's
//!   bounds walked by an Amanatides–Woo DDA, as pbrt-v4's `MajorantGrid`
//!   and `DDAMajorantIterator` (its NanoVDB medium uses 64^3 cells, each the
//!   max over the cell's box padded by one voxel for the trilinear filter).

use cirrus_bricks::{Bounds3, BrickVolume, MajorantSegment};
use glam::{IVec3, Vec3};
use rayon::prelude::*;

/// One segment from entry to exit with the volume's maximum.
pub struct GlobalMajorant {
    pub majorant: f32,
    extent: Vec3,
}

impl GlobalMajorant {
    pub fn new(volume: &BrickVolume) -> Self {
        GlobalMajorant {
            majorant: volume.max_density(),
            extent: volume.local_extent(),
        }
    }

    pub fn segments(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> impl Iterator<Item = MajorantSegment> {
        let (t0, t1) = Bounds3::new(Vec3::ZERO, self.extent)
            .clip_ray(origin, dir, t_min, t_max)
            .unwrap_or((0.0, 0.0));
        let majorant = self.majorant;
        (t0 < t1 && majorant > 0.0)
            .then_some(MajorantSegment {
                t0,
                t1,
                minorant: 0.0,
                majorant,
            })
            .into_iter()
    }
}

/// A dense `res^3` grid of majorants over the volume's local extent.
pub struct FixedMajorantGrid {
    pub res: i32,
    cell: Vec3,
    extent: Vec3,
    max: Vec<f32>,
}

impl FixedMajorantGrid {
    /// Each cell's majorant is the largest voxel over the cell's box padded
    /// by one voxel on every side.
    pub fn build(volume: &BrickVolume, res: i32) -> Self {
        let extent = volume.local_extent();
        let cell = extent / res as f32;
        let max: Vec<f32> = (0..res * res * res)
            .into_par_iter()
            .map(|i| {
                let c = IVec3::new(i / (res * res), (i / res) % res, i % res);
                let lo = (c.as_vec3() * cell).floor().as_ivec3() - 1;
                let hi = ((c + 1).as_vec3() * cell).ceil().as_ivec3() + 1;
                let mut m = 0f32;
                // Skip whole empty bricks.
                for bx in lo.x.div_euclid(8)..=hi.x.div_euclid(8) {
                    for by in lo.y.div_euclid(8)..=hi.y.div_euclid(8) {
                        for bz in lo.z.div_euclid(8)..=hi.z.div_euclid(8) {
                            if volume.brick_ref(IVec3::new(bx, by, bz))
                                == cirrus_bricks::BrickRef::Empty
                            {
                                continue;
                            }
                            for x in (bx * 8).max(lo.x)..=(bx * 8 + 7).min(hi.x) {
                                for y in (by * 8).max(lo.y)..=(by * 8 + 7).min(hi.y) {
                                    for z in (bz * 8).max(lo.z)..=(bz * 8 + 7).min(hi.z) {
                                        m = m.max(volume.voxel(IVec3::new(x, y, z)));
                                    }
                                }
                            }
                        }
                    }
                }
                m
            })
            .collect();
        FixedMajorantGrid {
            res,
            cell,
            extent,
            max,
        }
    }

    pub fn bytes(&self) -> usize {
        self.max.len() * 4
    }

    /// Segments cell by cell (Amanatides–Woo), empty cells left out.
    pub fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> FixedGridIter<'_> {
        let inv = dir.recip();
        let (t, t_end) = Bounds3::new(Vec3::ZERO, self.extent)
            .clip_ray(origin, dir, t_min, t_max)
            .unwrap_or((0.0, 0.0));
        let p = origin + dir * t;
        let cell = (p / self.cell)
            .floor()
            .as_ivec3()
            .clamp(IVec3::ZERO, IVec3::splat(self.res - 1));
        let step = IVec3::new(
            dir.x.signum() as i32,
            dir.y.signum() as i32,
            dir.z.signum() as i32,
        );
        let next_boundary = (cell + step.max(IVec3::ZERO)).as_vec3() * self.cell;
        let t_next = Vec3::select(
            dir.cmpeq(Vec3::ZERO),
            Vec3::INFINITY,
            (next_boundary - origin) * inv,
        );
        let t_delta = Vec3::select(
            dir.cmpeq(Vec3::ZERO),
            Vec3::INFINITY,
            (self.cell * inv).abs(),
        );
        FixedGridIter {
            grid: self,
            cell,
            step,
            t,
            t_end,
            t_next,
            t_delta,
        }
    }
}

pub struct FixedGridIter<'a> {
    grid: &'a FixedMajorantGrid,
    cell: IVec3,
    step: IVec3,
    t: f32,
    t_end: f32,
    t_next: Vec3,
    t_delta: Vec3,
}

impl Iterator for FixedGridIter<'_> {
    type Item = MajorantSegment;
    fn next(&mut self) -> Option<MajorantSegment> {
        let r = self.grid.res;
        while self.t < self.t_end
            && self.cell.cmpge(IVec3::ZERO).all()
            && self.cell.cmplt(IVec3::splat(r)).all()
        {
            let axis = if self.t_next.x < self.t_next.y && self.t_next.x < self.t_next.z {
                0
            } else if self.t_next.y < self.t_next.z {
                1
            } else {
                2
            };
            let t1 = self.t_next[axis].min(self.t_end);
            let m = self.grid.max[((self.cell.x * r + self.cell.y) * r + self.cell.z) as usize];
            let t0 = self.t;
            self.t = t1;
            self.cell[axis] += self.step[axis];
            self.t_next[axis] += self.t_delta[axis];
            if m > 0.0 && t1 > t0 {
                return Some(MajorantSegment {
                    t0,
                    t1,
                    minorant: 0.0,
                    majorant: m,
                });
            }
        }
        None
    }
}
