//! A homogeneous box: the field whose transmittance is known in closed form,
//! used by the tests to check estimators against `exp(-sigma_t * d)`.

use glam::Vec3;

use super::field::{Bounds3, DensityField, MajorantSegment};

/// Constant density inside the axis-aligned box `[lo, hi]`, zero outside.
#[derive(Clone, Copy, Debug)]
pub struct ConstantBox {
    pub lo: Vec3,
    pub hi: Vec3,
    pub density: f32,
    /// Nominal voxel size, only used to turn ray-march steps into lengths.
    pub voxel_size: f32,
}

impl ConstantBox {
    pub fn new(lo: Vec3, hi: Vec3, density: f32, voxel_size: f32) -> Self {
        Self {
            lo,
            hi,
            density,
            voxel_size,
        }
    }
}

impl DensityField for ConstantBox {
    type Segments<'a> = std::option::IntoIter<MajorantSegment>;

    fn bounds(&self) -> Bounds3 {
        Bounds3::new(self.lo, self.hi)
    }

    fn density(&self, p: Vec3) -> f32 {
        let inside = p.cmpge(self.lo).all() && p.cmple(self.hi).all();
        if inside {
            self.density
        } else {
            0.0
        }
    }

    /// One exact segment: the chord through the box.
    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Segments<'_> {
        self.bounds()
            .clip_ray(origin, dir, t_min, t_max)
            .filter(|(t0, t1)| t1 > t0)
            .map(|(t0, t1)| MajorantSegment {
                t0,
                t1,
                minorant: self.density,
                majorant: self.density,
            })
            .into_iter()
    }

    fn global_majorant(&self) -> f32 {
        self.density
    }

    fn voxel_size(&self) -> f32 {
        self.voxel_size
    }
}
