//! The Mitsuba 3 baseline: one majorant for the whole field.

use glam::Vec3;

use super::field::{DensityField, MajorantSegment};
use crate::ray::clip_to_box;

/// Wraps a field so that its segments collapse into one segment spanning the
/// ray's overlap with the field's bounds, bounded by the global majorant
/// (minorant 0, so residual ratio tracking degenerates to ratio tracking).
/// This is what Mitsuba 3's `heterogeneous` medium does; benchmarks compare
/// it with the field's own local majorants.
#[derive(Clone, Copy, Debug)]
pub struct GlobalMajorant<F> {
    inner: F,
    majorant: f32,
}

impl<F: DensityField> GlobalMajorant<F> {
    pub fn new(inner: F) -> Self {
        let majorant = inner.global_majorant();
        Self { inner, majorant }
    }

    pub fn inner(&self) -> &F {
        &self.inner
    }
}

impl<F: DensityField> DensityField for GlobalMajorant<F> {
    type Segments<'a>
        = std::option::IntoIter<MajorantSegment>
    where
        Self: 'a;

    fn bounds(&self) -> (Vec3, Vec3) {
        self.inner.bounds()
    }

    fn density(&self, p: Vec3) -> f32 {
        self.inner.density(p)
    }

    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Segments<'_> {
        global_segment(
            self.inner.bounds(),
            self.majorant,
            origin,
            dir,
            t_min,
            t_max,
        )
        .into_iter()
    }

    fn global_majorant(&self) -> f32 {
        self.majorant
    }

    fn voxel_size(&self) -> f32 {
        self.inner.voxel_size()
    }
}

/// The one segment of a global majorant: the ray's overlap with `bounds`,
/// or nothing when it misses or the majorant is zero.
pub(crate) fn global_segment(
    (lo, hi): (Vec3, Vec3),
    majorant: f32,
    origin: Vec3,
    dir: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<MajorantSegment> {
    clip_to_box(origin, dir, lo, hi, t_min, t_max)
        .filter(|(t0, t1)| t1 > t0 && majorant > 0.0)
        .map(|(t0, t1)| MajorantSegment {
            t0,
            t1,
            minorant: 0.0,
            majorant,
        })
}
