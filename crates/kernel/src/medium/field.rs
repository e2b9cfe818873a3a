//! The abstraction every renderer here is written against: a scalar density
//! field that can bound itself along a ray.

use glam::Vec3;

pub use cirrus_bricks::{Bounds3, Lattice, MajorantSegment};

/// A density field in render space (world space minus an offset chosen by the
/// caller so coordinates stay small in `f32`).
///
/// The trackers only ever need two things from a field: point lookups and,
/// along a ray, piecewise-constant bounds of the density. How tight those
/// bounds are is what decides the cost of null-collision tracking. A ray
/// march needs no bounds, only where the density may be non-zero:
/// [`march_lattice`](Self::march_lattice) lets a field find its lattice
/// points without walking its segments.
pub trait DensityField: Send + Sync {
    type Segments<'a>: Iterator<Item = MajorantSegment>
    where
        Self: 'a;

    /// Render-space bounds of where density may be non-zero.
    fn bounds(&self) -> Bounds3;

    /// Trilinearly interpolated density at a render-space point (0 outside).
    fn density(&self, p: Vec3) -> f32;

    /// Density at `p` at shutter time `time` (frames from the frame's own
    /// instant). A moving field looks it up where its velocity brings
    /// matter from; a still one ignores `time`, so rays at any time see
    /// exactly [`density`](Self::density).
    #[inline]
    fn density_at(&self, p: Vec3, _time: f32) -> f32 {
        self.density(p)
    }

    /// Front-to-back, disjoint majorant segments covering the ray's overlap
    /// with the field inside `[t_min, t_max]` (gaps mean zero density).
    /// `dir` need not be normalised; t is in units of `dir`.
    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Segments<'_>;

    /// Calls `visit(t, density)` at the points of `lattice` along the ray
    /// within `[0, t_max]` where the density may be non-zero (its origin:
    /// where the ray enters the first segment with a positive majorant),
    /// until `visit` returns false; returns the walk's steps. What a ray
    /// march needs: a field may find those points faster than by walking
    /// its segments, which is the default.
    fn march_lattice(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        march_segments(self, origin, dir, t_max, lattice, visit)
    }

    /// One majorant for the whole field (for the global-majorant mode).
    fn global_majorant(&self) -> f32;

    /// Smallest world-space voxel size (ray-march steps are given in voxels).
    fn voxel_size(&self) -> f32;
}

/// A borrowed field is a field, so media can borrow a field instead of own it.
impl<T: DensityField + ?Sized> DensityField for &T {
    type Segments<'a>
        = T::Segments<'a>
    where
        Self: 'a;

    fn bounds(&self) -> Bounds3 {
        (**self).bounds()
    }
    fn density(&self, p: Vec3) -> f32 {
        (**self).density(p)
    }
    fn density_at(&self, p: Vec3, time: f32) -> f32 {
        (**self).density_at(p, time)
    }
    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Segments<'_> {
        (**self).segments(origin, dir, t_min, t_max)
    }
    fn march_lattice(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        (**self).march_lattice(origin, dir, t_max, lattice, visit)
    }
    fn global_majorant(&self) -> f32 {
        (**self).global_majorant()
    }
    fn voxel_size(&self) -> f32 {
        (**self).voxel_size()
    }
}

/// The march of [`DensityField::march_lattice`] over `field`'s segments:
/// the default, and what a field that can do better falls back to.
pub fn march_segments<F: DensityField + ?Sized>(
    field: &F,
    origin: Vec3,
    dir: Vec3,
    t_max: f32,
    lattice: Lattice,
    mut visit: impl FnMut(f32, f32) -> bool,
) -> u64 {
    lattice.visit_segments(field.segments(origin, dir, 0.0, t_max), |t| {
        visit(t, field.density(origin + dir * t))
    })
}
