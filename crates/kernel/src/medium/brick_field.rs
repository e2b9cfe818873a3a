//! The brick volumes of `cirrus-bricks` as a [`DensityField`].
//!
//! Render space is world space minus an offset (see the crate doc); this
//! adapter folds that offset and the grid's index-to-world transform into
//! one render-to-local matrix, computed in f64 and rounded once, so a volume
//! 10,000 or 1,000,000 units from the origin is addressed with local index
//! coordinates of ordinary size. An affine map keeps the ray parameter, so
//! the bricks' segments come back in the caller's `t`.
//!
//! With motion ([`BrickField::with_motion`]) lookups at a time other than
//! 0 follow the velocity (`motion.rs`) and the segments come from the
//! volume's dilated motion shell; at time 0, and without motion, nothing
//! changes.

use super::field::{march_segments, Bounds3, DensityField, Lattice};
use super::motion::{Motion, Velocity};
use crate::shutter::Shutter;
use cirrus_bricks::{BrickError, BrickVolume, CellPartition, DBounds3, SegmentIter};
use glam::{DMat4, DVec3, Mat4, Vec3};

/// The level whose cells a march's walk keeps: level 1, 8^3 voxels, one
/// brick (see [`BrickField::for_marching`]).
const OCCUPANCY_LEVEL: usize = 1;

/// Which cells the walk visits.
#[derive(Clone, Copy, Debug)]
enum CellRule {
    /// Majorant cells refined where their slack exceeds `split` density x
    /// voxels, voxel by voxel past `voxel_split` (for trackers).
    Refined { split: f32, voxel_split: f32 },
    /// Cells with density at [`OCCUPANCY_LEVEL`], unrefined (for marchers).
    Occupancy,
}

/// A [`BrickVolume`] placed in render space.
pub struct BrickField<'v> {
    volume: &'v BrickVolume,
    /// The cells the hierarchy walk visits, made for `cells`; `None`: the
    /// finest cells.
    partition: Option<CellPartition>,
    /// The rule the partition was made for.
    cells: Option<CellRule>,
    motion: Option<Motion>,
    render_from_local: DMat4,
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
            cells: None,
            motion: None,
            render_from_local,
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
    pub fn with_refinement(self, density_scale: f32, extra_optical_depth: f32) -> Self {
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
        self.with_cells(CellRule::Refined { split, voxel_split })
    }

    /// Walks the cells a ray march needs instead of refined majorant cells:
    /// every 8^3 cell holding density whole, empty space skipped as ever
    /// ([`BrickVolume::occupancy_partition`]). A march visits every lattice
    /// point where the majorant is positive and never uses the bound
    /// itself, so tight bounds would only cost it steps: on the corpus
    /// cloud at 1.6 per voxel the refined walk takes one step per lookup.
    pub fn for_marching(self) -> Self {
        self.with_cells(CellRule::Occupancy)
    }

    fn with_cells(mut self, rule: CellRule) -> Self {
        self.cells = Some(rule);
        self.partition = Some(self.partition_for(rule));
        self
    }

    fn partition_for(&self, rule: CellRule) -> CellPartition {
        match rule {
            CellRule::Refined { split, voxel_split } => self
                .walked()
                .partition(split, self.voxel_split(voxel_split)),
            CellRule::Occupancy => self.walked().occupancy_partition(OCCUPANCY_LEVEL),
        }
    }

    /// The cells the hierarchy walk visits (`None`: the finest cells,
    /// [`BrickVolume::segments`]).
    pub fn partition(&self) -> Option<&CellPartition> {
        self.partition.as_ref()
    }

    /// Makes the field move with `velocity` over `shutter`: lookups at time
    /// `t` read the density at `x - v(x) t`, and the majorants come from
    /// the volume's bounds dilated by the largest displacement over the
    /// shutter, so they bound the density at every time of it. Render
    /// bounds grow by the same padding. A shutter with no time away from 0
    /// leaves the field as it was.
    pub fn with_motion(
        mut self,
        velocity: &Velocity,
        shutter: Shutter,
    ) -> Result<Self, BrickError> {
        if shutter.max_abs_time() == 0.0 {
            return Ok(self);
        }
        let motion = Motion::new(self.volume, velocity, shutter)?;
        let o = -motion.shell_offset.as_dvec3();
        let local = DBounds3::new(o, o + motion.shell.local_extent().as_dvec3());
        self.bounds = local
            .transformed(self.render_from_local)
            .relative_to(DVec3::ZERO);
        self.motion = Some(motion);
        if let Some(rule) = self.cells {
            self.partition = Some(self.partition_for(rule));
        }
        Ok(self)
    }

    /// Whether lookups depend on time.
    pub fn moves(&self) -> bool {
        self.motion.is_some()
    }

    /// The volume whose bounds pyramid the walk uses: the motion shell, or
    /// the volume itself.
    fn walked(&self) -> &BrickVolume {
        self.motion.as_ref().map_or(self.volume, |m| &m.shell)
    }

    /// The shell has no voxels to bound single voxel cells by, so a moving
    /// field never goes below the finest 4^3 cells.
    fn voxel_split(&self, voxel_split: f32) -> f32 {
        if self.motion.is_some() {
            f32::INFINITY
        } else {
            voxel_split
        }
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

    #[inline]
    fn density_at(&self, p: Vec3, time: f32) -> f32 {
        let q = self.local_from_render.transform_point3(p);
        match &self.motion {
            Some(m) if time != 0.0 => self.volume.trilinear(m.source(q, time)),
            _ => self.volume.trilinear(q),
        }
    }

    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Segments<'_> {
        let (mut o, d) = self.local_ray(origin, dir);
        if let Some(m) = &self.motion {
            o += m.shell_offset;
        }
        let walked = self.walked();
        match &self.partition {
            Some(cells) => walked.segments_in(cells, o, d, t_min, t_max),
            None => walked.segments(o, d, t_min, t_max),
        }
    }

    /// A still field walked by occupancy looks its lattice points up cell
    /// by cell ([`BrickVolume::march_occupied`]); any other walks its
    /// segments.
    fn march_lattice(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        match (&self.partition, self.cells, &self.motion) {
            (Some(cells), Some(CellRule::Occupancy), None) => {
                let (o, d) = self.local_ray(origin, dir);
                self.volume
                    .march_occupied(cells, o, d, t_max, lattice, visit)
            }
            _ => march_segments(self, origin, dir, t_max, lattice, visit),
        }
    }

    fn global_majorant(&self) -> f32 {
        self.global_majorant
    }

    fn voxel_size(&self) -> f32 {
        self.voxel_size
    }
}
