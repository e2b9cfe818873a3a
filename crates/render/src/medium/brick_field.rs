//! The brick volumes of `cirrus-bricks` as a [`DensityField`].
//!
//! Render space is world space minus an offset (see the crate doc); this
//! adapter folds that offset and the grid's index-to-world transform into
//! one render-to-local matrix, computed in f64 and rounded once, so a volume
//! 10,000 or 1,000,000 units from the origin is addressed with local index
//! coordinates of ordinary size. An affine map keeps the ray parameter, so
//! the bricks' segments come back in the caller's `t`.

use super::field::{Bounds3, DensityField};
use cirrus_bricks::{BrickVolume, CellPartition, DBounds3, SegmentIter};
use glam::{DMat4, DVec3, Mat4, Vec3};

/// A [`BrickVolume`] placed in render space.
pub struct BrickField<'v> {
    volume: &'v BrickVolume,
    /// The cells the hierarchy walk visits, made for the refinement rule of
    /// [`BrickField::with_refinement`]; `None`: the finest cells.
    partition: Option<CellPartition>,
    local_from_render: Mat4,
    bounds: Bounds3,
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
        // Bounds: the brick grid's box in render space, rounded once.
        let local = DBounds3::new(DVec3::ZERO, volume.local_extent().as_dvec3());
        let bounds = local
            .transformed(render_from_local)
            .relative_to(DVec3::ZERO);
        let axes = render_from_local.to_cols_array_2d();
        let voxel_size = (0..3)
            .map(|i| DVec3::new(axes[i][0], axes[i][1], axes[i][2]).length())
            .fold(f64::INFINITY, f64::min) as f32;
        BrickField {
            volume,
            partition: None,
            local_from_render: local_from_render.as_mat4(),
            bounds,
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

    /// A render-space ray in the volume's local index space (an affine
    /// map, so the parameter `t` is the same in both).
    pub fn local_ray(&self, origin: Vec3, dir: Vec3) -> (Vec3, Vec3) {
        (
            self.local_from_render.transform_point3(origin),
            self.local_from_render.transform_vector3(dir),
        )
    }
}

impl DensityField for BrickField<'_> {
    type Segments<'a>
        = SegmentIter<'a>
    where
        Self: 'a;

    fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    #[inline]
    fn density(&self, p: Vec3) -> f32 {
        self.volume
            .trilinear(self.local_from_render.transform_point3(p))
    }

    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Segments<'_> {
        let (o, d) = self.local_ray(origin, dir);
        match &self.partition {
            Some(cells) => self.volume.segments_in(cells, o, d, t_min, t_max),
            None => self.volume.segments(o, d, t_min, t_max),
        }
    }

    fn global_majorant(&self) -> f32 {
        self.global_majorant
    }

    fn voxel_size(&self) -> f32 {
        self.voxel_size
    }
}
