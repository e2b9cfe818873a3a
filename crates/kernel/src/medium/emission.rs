//! What a medium emits: blackbody radiation from a temperature grid and/or
//! a scalar emission grid times a colour.

use glam::Vec3;

use super::field::DensityField;
use crate::blackbody::Blackbody;
use crate::counters::Counters;

/// The emission of a [`Medium`](super::Medium). Each grid is its own field
/// with its own bounds, so lookups happen only where it lives.
pub struct Emission<F> {
    pub temperature: Option<(F, Blackbody)>,
    /// The grid and the colour its values multiply (scale included).
    pub grid: Option<(F, Vec3)>,
}

impl<F: DensityField> Emission<F> {
    /// Emitted radiance `Le` at `p` at shutter time `time`: the grids move
    /// with their own velocity (set on each field), as the density does.
    #[inline]
    pub fn radiance(&self, p: Vec3, time: f32, c: &mut Counters) -> Vec3 {
        let inside = |f: &F| f.bounds().contains(p);
        let mut le = Vec3::ZERO;
        if let Some((field, bb)) = &self.temperature {
            if inside(field) {
                c.emission_lookups += 1;
                le += bb.radiance(field.density_at(p, time));
            }
        }
        if let Some((field, colour)) = &self.grid {
            if inside(field) {
                c.emission_lookups += 1;
                le += *colour * field.density_at(p, time).max(0.0);
            }
        }
        le
    }
}
