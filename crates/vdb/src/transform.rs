//! Index-to-world transforms: every linear map OpenVDB writes, as one affine matrix.

use glam::{DMat3, DMat4, DVec3};

/// The map type a file named. All are linear; OpenVDB's
/// `NonlinearFrustumMap` is refused by the readers with a clear error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapKind {
    UniformScale,
    UniformScaleTranslate,
    Scale,
    ScaleTranslate,
    Translation,
    Affine,
    Unitary,
}

impl MapKind {
    /// The name OpenVDB gives the map (`MapBase::type()`).
    pub fn name(self) -> &'static str {
        match self {
            MapKind::UniformScale => "UniformScaleMap",
            MapKind::UniformScaleTranslate => "UniformScaleTranslateMap",
            MapKind::Scale => "ScaleMap",
            MapKind::ScaleTranslate => "ScaleTranslateMap",
            MapKind::Translation => "TranslationMap",
            MapKind::Affine => "AffineMap",
            MapKind::Unitary => "UnitaryMap",
        }
    }

    pub fn from_name(name: &str) -> Option<MapKind> {
        Some(match name {
            "UniformScaleMap" => MapKind::UniformScale,
            "UniformScaleTranslateMap" => MapKind::UniformScaleTranslate,
            "ScaleMap" => MapKind::Scale,
            "ScaleTranslateMap" => MapKind::ScaleTranslate,
            "TranslationMap" => MapKind::Translation,
            "AffineMap" => MapKind::Affine,
            "UnitaryMap" => MapKind::Unitary,
            _ => return None,
        })
    }
}

/// A grid's transform: `world = M * (i, j, k, 1)`, voxel centres at integer
/// index coordinates (OpenVDB's convention, shared by NanoVDB).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub kind: MapKind,
    index_to_world: DMat4,
    world_to_index: DMat4,
}

impl Transform {
    /// A transform from its index-to-world matrix. `None` when the matrix is
    /// not finite, not invertible, or not affine (last row other than 0 0 0 1).
    pub fn from_matrix(kind: MapKind, m: DMat4) -> Option<Transform> {
        let finite = m.to_cols_array().iter().all(|v| v.is_finite());
        let affine = m.row(3) == glam::DVec4::new(0.0, 0.0, 0.0, 1.0);
        let det = DMat3::from_mat4(m).determinant();
        if !finite || !affine || !det.is_normal() {
            return None;
        }
        let inv = m.inverse();
        if !inv.to_cols_array().iter().all(|v| v.is_finite()) {
            return None;
        }
        Some(Transform {
            kind,
            index_to_world: m,
            world_to_index: inv,
        })
    }

    /// `world = scale * index + translation`.
    pub fn scale_translate(kind: MapKind, scale: DVec3, translation: DVec3) -> Option<Transform> {
        let m = DMat4::from_cols(
            glam::DVec4::new(scale.x, 0.0, 0.0, 0.0),
            glam::DVec4::new(0.0, scale.y, 0.0, 0.0),
            glam::DVec4::new(0.0, 0.0, scale.z, 0.0),
            translation.extend(1.0),
        );
        Self::from_matrix(kind, m)
    }

    /// The identity: index space is world space.
    pub fn identity() -> Transform {
        Transform {
            kind: MapKind::UniformScale,
            index_to_world: DMat4::IDENTITY,
            world_to_index: DMat4::IDENTITY,
        }
    }

    pub fn index_to_world_matrix(&self) -> DMat4 {
        self.index_to_world
    }
    pub fn world_to_index_matrix(&self) -> DMat4 {
        self.world_to_index
    }

    pub fn index_to_world(&self, p: DVec3) -> DVec3 {
        self.index_to_world.transform_point3(p)
    }
    pub fn world_to_index(&self, p: DVec3) -> DVec3 {
        self.world_to_index.transform_point3(p)
    }
    /// Maps a direction (no translation) from world to index space.
    pub fn world_to_index_dir(&self, d: DVec3) -> DVec3 {
        self.world_to_index.transform_vector3(d)
    }
    pub fn index_to_world_dir(&self, d: DVec3) -> DVec3 {
        self.index_to_world.transform_vector3(d)
    }

    /// World-space length of one voxel step along each index axis, as
    /// OpenVDB's `voxelSize()`.
    pub fn voxel_size(&self) -> DVec3 {
        let m = DMat3::from_mat4(self.index_to_world);
        DVec3::new(m.x_axis.length(), m.y_axis.length(), m.z_axis.length())
    }

    /// True when the map has no rotation or shear.
    pub fn is_axis_aligned(&self) -> bool {
        let m = DMat3::from_mat4(self.index_to_world);
        m.x_axis.y == 0.0
            && m.x_axis.z == 0.0
            && m.y_axis.x == 0.0
            && m.y_axis.z == 0.0
            && m.z_axis.x == 0.0
            && m.z_axis.y == 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_translate_round_trips_far_from_origin() {
        let t = Transform::scale_translate(
            MapKind::ScaleTranslate,
            DVec3::splat(0.05),
            DVec3::new(1e4, -2e4, 3.5),
        )
        .unwrap();
        let p = DVec3::new(12.0, -7.0, 400.0);
        let w = t.index_to_world(p);
        assert!(
            (w - DVec3::new(1e4 + 0.6, -2e4 - 0.35, 23.5))
                .abs()
                .max_element()
                < 1e-9
        );
        assert!((t.world_to_index(w) - p).abs().max_element() < 1e-6);
        assert_eq!(t.voxel_size(), DVec3::splat(0.05));
    }

    #[test]
    fn singular_matrices_are_refused() {
        assert!(
            Transform::scale_translate(MapKind::Scale, DVec3::new(1.0, 0.0, 1.0), DVec3::ZERO)
                .is_none()
        );
        assert!(Transform::scale_translate(
            MapKind::Scale,
            DVec3::new(1.0, f64::NAN, 1.0),
            DVec3::ZERO
        )
        .is_none());
    }
}
