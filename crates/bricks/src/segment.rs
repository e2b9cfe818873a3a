//! The one majorant segment type of the workspace.

/// Over the ray parameter interval `[t0, t1]` the field lies within
/// `[minorant, majorant]`.
///
/// Units: a density field's segments bound the unscaled density (what
/// [`BrickVolume`](crate::BrickVolume) stores); a medium's bound the
/// extinction `sigma_t` in 1 / render-space units (density times the
/// medium's density scale, summed over overlapping instances). The
/// renderer's trackers take the latter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MajorantSegment {
    pub t0: f32,
    pub t1: f32,
    pub minorant: f32,
    pub majorant: f32,
}

impl MajorantSegment {
    /// The same interval with both bounds multiplied by `scale`.
    #[inline]
    pub fn scaled(self, scale: f32) -> Self {
        Self {
            minorant: self.minorant * scale,
            majorant: self.majorant * scale,
            ..self
        }
    }
}
