//! A brick volume walked through a fixed majorant grid instead of its
//! hierarchy: pbrt-v4's `MajorantGrid` (64^3 cells in its NanoVDB medium),
//! the structure `bench error` and `bench traverse` compare cirrus with.

use cirrus_bricks::Bounds3;
use cirrus_render::{BrickField, DensityField};
use glam::Vec3;

use crate::baseline::{FixedGridIter, FixedMajorantGrid};

/// The same density, lookups and bounds as the [`BrickField`] it wraps;
/// only the majorant segments come from a `res^3` grid.
pub struct FixedGridField<'v> {
    field: BrickField<'v>,
    grid: FixedMajorantGrid,
}

impl<'v> FixedGridField<'v> {
    pub fn new(field: BrickField<'v>, res: i32) -> Self {
        let grid = FixedMajorantGrid::build(field.volume(), res);
        Self { field, grid }
    }
}

impl DensityField for FixedGridField<'_> {
    type Segments<'a>
        = FixedGridIter<'a>
    where
        Self: 'a;

    fn bounds(&self) -> Bounds3 {
        self.field.bounds()
    }

    #[inline]
    fn density(&self, p: Vec3) -> f32 {
        self.field.density(p)
    }

    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Segments<'_> {
        let (o, d) = self.field.local_ray(origin, dir);
        self.grid.segments(o, d, t_min, t_max)
    }

    fn global_majorant(&self) -> f32 {
        self.field.global_majorant()
    }

    fn voxel_size(&self) -> f32 {
        self.field.voxel_size()
    }
}
