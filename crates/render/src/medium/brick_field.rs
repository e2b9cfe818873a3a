//! The brick volumes of `cirrus-bricks` as a [`DensityField`].
//!
//! Render space is world space minus an offset (see the crate doc); this
//! adapter folds that offset and the grid's index-to-world transform into
//! one render-to-local matrix, computed in f64 and rounded once, so a volume
//! 10,000 or 1,000,000 units from the origin is addressed with local index
//! coordinates of ordinary size. An affine map keeps the ray parameter, so
//! the bricks' segments come back in the caller's `t`.

use super::field::{DensityField, MajorantSegment};
use cirrus_bricks::{
    BrickVolume, CellPartition, FixedGridIter, FixedMajorantGrid, RaySegment, SegmentIter,
};
use glam::{DMat4, DVec3, Mat4, Vec3};

/// A [`BrickVolume`] placed in render space.
pub struct BrickField<'v> {
    volume: &'v BrickVolume,
    /// A pbrt-v4-style fixed majorant grid used instead of the hierarchy,
    /// for the benchmarks that compare the two.
    fixed: Option<FixedMajorantGrid>,
    /// The cells the hierarchy walk visits, made for the refinement rule of
    /// [`BrickField::with_refinement`]; `None`: the finest cells.
    partition: Option<CellPartition>,
    local_from_render: Mat4,
    bounds: (Vec3, Vec3),
    voxel_size: f32,
    global_majorant: f32,
}

impl<'v> BrickField<'v> {
    /// `object_to_world` places the grid's world space in the scene (the
    /// identity for a lone volume); `render_offset` is subtracted from world
    /// coordinates to make render space.
    pub fn new(volume: &'v BrickVolume, object_to_world: DMat4, render_offset: DVec3) -> Self {
        let world_from_local = object_to_world * volume.local_from_world().inverse();
        let render_from_local = DMat4::from_translation(-render_offset) * world_from_local;
        let local_from_render = render_from_local.inverse();
        // Bounds: the eight corners of the brick grid, in render space.
        let e = volume.local_extent().as_dvec3();
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for k in 0..8 {
            let c = DVec3::new(
                if k & 4 != 0 { e.x } else { 0.0 },
                if k & 2 != 0 { e.y } else { 0.0 },
                if k & 1 != 0 { e.z } else { 0.0 },
            );
            let p = render_from_local.transform_point3(c).as_vec3();
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let axes = render_from_local.to_cols_array_2d();
        let voxel_size = (0..3)
            .map(|i| DVec3::new(axes[i][0], axes[i][1], axes[i][2]).length())
            .fold(f64::INFINITY, f64::min) as f32;
        BrickField {
            volume,
            fixed: None,
            partition: None,
            local_from_render: local_from_render.as_mat4(),
            bounds: (lo, hi),
            voxel_size,
            global_majorant: volume.max_density(),
        }
    }

    pub fn volume(&self) -> &BrickVolume {
        self.volume
    }

    /// Stops refining majorant cells where crossing one costs at most
    /// `extra_optical_depth` more null collisions than its finest cells
    /// would (Blender Cycles splits its octree at 1.442), given the scale
    /// from density to extinction per world unit.
    pub fn with_refinement(mut self, density_scale: f32, extra_optical_depth: f32) -> Self {
        let per_voxel = density_scale * self.voxel_size;
        // `split`: density x voxels a cell's bounds may differ by before the
        // walk refines it. Finest cells that would cost more than 16 extra
        // null collisions (only ever at extreme density scales) are walked
        // voxel by voxel.
        let (split, voxel_split) = if per_voxel > 0.0 {
            (extra_optical_depth / per_voxel, 16.0 / per_voxel)
        } else {
            (0.0, f32::INFINITY)
        };
        self.partition = Some(self.volume.partition(split, voxel_split));
        self
    }

    /// Walks a fixed `res^3` majorant grid over the volume (pbrt-v4's
    /// `MajorantGrid`, 64^3 in its NanoVDB medium) instead of the hierarchy.
    pub fn with_fixed_grid(mut self, res: i32) -> Self {
        self.fixed = Some(FixedMajorantGrid::build(self.volume, res));
        self
    }
}

/// Segments of either majorant structure.
pub enum BrickSegments<'a> {
    Hierarchy(SegmentIter<'a>),
    Fixed(FixedGridIter<'a>),
}

impl Iterator for BrickSegments<'_> {
    type Item = MajorantSegment;
    #[inline]
    fn next(&mut self) -> Option<MajorantSegment> {
        let s: RaySegment = match self {
            BrickSegments::Hierarchy(it) => it.next()?,
            BrickSegments::Fixed(it) => it.next()?,
        };
        Some(MajorantSegment {
            t0: s.t0,
            t1: s.t1,
            minorant: s.minorant,
            majorant: s.majorant,
        })
    }
}

impl DensityField for BrickField<'_> {
    type Segments<'a>
        = BrickSegments<'a>
    where
        Self: 'a;

    fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    #[inline]
    fn density(&self, p: Vec3) -> f32 {
        self.volume
            .trilinear(self.local_from_render.transform_point3(p))
    }

    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Segments<'_> {
        let o = self.local_from_render.transform_point3(origin);
        let d = self.local_from_render.transform_vector3(dir);
        match (&self.fixed, &self.partition) {
            (None, Some(cells)) => {
                BrickSegments::Hierarchy(self.volume.segments_in(cells, o, d, t_min, t_max))
            }
            (None, None) => BrickSegments::Hierarchy(self.volume.segments(o, d, t_min, t_max)),
            (Some(grid), _) => BrickSegments::Fixed(grid.segments(o, d, t_min, t_max)),
        }
    }

    fn global_majorant(&self) -> f32 {
        self.global_majorant
    }

    fn voxel_size(&self) -> f32 {
        self.voxel_size
    }
}
