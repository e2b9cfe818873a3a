//! A small dense voxel grid with trilinear interpolation and a coarse
//! majorant grid: the test field with real structure, and the pbrt-style
//! "fixed majorant grid" baseline.

use glam::Vec3;

use super::field::{Bounds3, DensityField};
use super::majorant_grid::{DdaSegments, MajorantGrid};

/// Dense voxels, OpenVDB conventions: voxel `(i, j, k)` is a sample at
/// `origin + (i, j, k) * voxel_size`, values outside the array are 0, and
/// the density between samples is trilinear.
#[derive(Clone, Debug)]
pub struct GridField {
    dims: [usize; 3],
    /// `dims` as i64, for index arithmetic in the lookup.
    n: [i64; 3],
    data: Vec<f32>,
    origin: Vec3,
    voxel_size: f32,
    majorants: MajorantGrid,
}

impl GridField {
    /// `data` holds `dims[0] * dims[1] * dims[2]` values, x fastest.
    /// Majorant cells are `cell_voxels` voxels wide (pbrt-v4 uses 16^3 cells
    /// over a grid medium; smaller cells are tighter but cost more DDA steps).
    pub fn new(
        dims: [usize; 3],
        data: Vec<f32>,
        origin: Vec3,
        voxel_size: f32,
        cell_voxels: usize,
    ) -> Self {
        assert_eq!(data.len(), dims.iter().product::<usize>(), "data length");
        assert!(dims.iter().all(|&d| d > 0) && cell_voxels > 0 && voxel_size > 0.0);
        // Density can be non-zero on index coordinates (-1, n): voxel 0
        // still weighs in one voxel to its left. The majorant grid covers
        // [-1, n] in cells of `cell_voxels`.
        let cells = dims.map(|n| (n + 1).div_ceil(cell_voxels) as u32);
        let lo = origin - Vec3::splat(voxel_size);
        let mut field = Self {
            dims,
            n: [dims[0] as i64, dims[1] as i64, dims[2] as i64],
            data,
            origin,
            voxel_size,
            majorants: MajorantGrid::new(lo, 1.0, [1, 1, 1], |_, _, _| (0.0, 0.0)),
        };
        let cv = cell_voxels as i64;
        let majorants = MajorantGrid::new(lo, cell_voxels as f32 * voxel_size, cells, |i, j, k| {
            // Index interval of the cell is [c*cv - 1, (c+1)*cv - 1]; the
            // trilinear density there is a convex combination of voxels
            // floor(a) ..= floor(b) + 1, so their min and max bound it.
            let range = |c: u32| {
                let a = c as i64 * cv - 1;
                a..=a + cv + 1
            };
            field.voxel_range_bounds(range(i), range(j), range(k))
        });
        field.majorants = majorants;
        field
    }

    /// Build from a function of the voxel index.
    pub fn from_fn(
        dims: [usize; 3],
        origin: Vec3,
        voxel_size: f32,
        cell_voxels: usize,
        f: impl Fn(usize, usize, usize) -> f32,
    ) -> Self {
        let mut data = Vec::with_capacity(dims.iter().product());
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    data.push(f(i, j, k));
                }
            }
        }
        Self::new(dims, data, origin, voxel_size, cell_voxels)
    }

    pub fn majorant_grid(&self) -> &MajorantGrid {
        &self.majorants
    }

    /// Voxel value, 0 outside the array.
    #[inline]
    fn voxel(&self, i: i64, j: i64, k: i64) -> f32 {
        let [nx, ny, nz] = self.n;
        if i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz {
            return 0.0;
        }
        self.data[(i + nx * (j + ny * k)) as usize]
    }

    /// The 2x2x2 voxels from `(i, j, k)` up, x fastest; a direct gather
    /// when all lie inside the array (the common case), else checked.
    #[inline]
    fn corners(&self, i: i64, j: i64, k: i64) -> [f32; 8] {
        let [nx, ny, nz] = self.n;
        if i >= 0 && j >= 0 && k >= 0 && i + 1 < nx && j + 1 < ny && k + 1 < nz {
            let (sy, sz) = (nx as usize, (nx * ny) as usize);
            let o = (i + nx * (j + ny * k)) as usize;
            let d = &self.data;
            [
                d[o],
                d[o + 1],
                d[o + sy],
                d[o + sy + 1],
                d[o + sz],
                d[o + sz + 1],
                d[o + sz + sy],
                d[o + sz + sy + 1],
            ]
        } else {
            [
                self.voxel(i, j, k),
                self.voxel(i + 1, j, k),
                self.voxel(i, j + 1, k),
                self.voxel(i + 1, j + 1, k),
                self.voxel(i, j, k + 1),
                self.voxel(i + 1, j, k + 1),
                self.voxel(i, j + 1, k + 1),
                self.voxel(i + 1, j + 1, k + 1),
            ]
        }
    }

    fn voxel_range_bounds(
        &self,
        ri: std::ops::RangeInclusive<i64>,
        rj: std::ops::RangeInclusive<i64>,
        rk: std::ops::RangeInclusive<i64>,
    ) -> (f32, f32) {
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for k in rk {
            for j in rj.clone() {
                for i in ri.clone() {
                    let v = self.voxel(i, j, k);
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
        }
        (lo, hi)
    }

    /// A 16^3 cloud-like blob over roughly `[0, 1]^3 + offset`: a smooth
    /// falloff times a lumpy modulation, zero near the array's faces, so
    /// the field has empty cells, interior cells and structure for the
    /// majorant grid to bound (the tests' cloud).
    pub fn cloud(cell_voxels: usize, offset: Vec3) -> Self {
        let n = 16;
        let vs = 1.0 / n as f32;
        Self::from_fn(
            [n, n, n],
            Vec3::splat(0.5 * vs) + offset,
            vs,
            cell_voxels,
            |i, j, k| {
                let p = (Vec3::new(i as f32, j as f32, k as f32) + 0.5) / n as f32 - 0.5;
                let r2 = (p * Vec3::new(1.0, 1.4, 1.0)).length_squared() / 0.2;
                let lumps =
                    0.65 + 0.35 * (9.0 * p.x).sin() * (7.0 * p.y + 1.0).cos() * (8.0 * p.z).sin();
                ((1.0 - r2).max(0.0) * lumps).max(0.0)
            },
        )
    }
}

impl DensityField for GridField {
    type Segments<'a> = DdaSegments<'a>;

    fn bounds(&self) -> Bounds3 {
        let n = Vec3::new(
            self.dims[0] as f32,
            self.dims[1] as f32,
            self.dims[2] as f32,
        );
        Bounds3::new(
            self.origin - Vec3::splat(self.voxel_size),
            self.origin + n * self.voxel_size,
        )
    }

    fn density(&self, p: Vec3) -> f32 {
        let x = (p - self.origin) / self.voxel_size;
        let n = Vec3::new(
            self.dims[0] as f32,
            self.dims[1] as f32,
            self.dims[2] as f32,
        );
        if !(x.cmpgt(Vec3::splat(-1.0)).all() && x.cmplt(n).all()) {
            return 0.0; // also rejects NaN
        }
        // x > -1, so x + 1 > 0 and truncation is floor (no libm floorf).
        let shifted = x + 1.0;
        let (i, j, k) = (shifted.x as i64, shifted.y as i64, shifted.z as i64);
        let f = shifted - Vec3::new(i as f32, j as f32, k as f32);
        let c = self.corners(i - 1, j - 1, k - 1);
        let lerp = |a: f32, b: f32, t: f32| a + t * (b - a);
        let c00 = lerp(c[0], c[1], f.x);
        let c10 = lerp(c[2], c[3], f.x);
        let c01 = lerp(c[4], c[5], f.x);
        let c11 = lerp(c[6], c[7], f.x);
        lerp(lerp(c00, c10, f.y), lerp(c01, c11, f.y), f.z)
    }

    /// The DDA over the majorant grid, clipped to the field's bounds (the
    /// grid's last cells may reach past them).
    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> DdaSegments<'_> {
        let (t0, t1) = self
            .bounds()
            .clip_ray(origin, dir, t_min, t_max)
            .unwrap_or((1.0, 0.0));
        self.majorants.segments(origin, dir, t0, t1)
    }

    fn global_majorant(&self) -> f32 {
        self.majorants.max_majorant()
    }

    fn voxel_size(&self) -> f32 {
        self.voxel_size
    }
}
