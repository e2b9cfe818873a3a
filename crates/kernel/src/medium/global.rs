//! The Mitsuba 3 baseline's one segment: a single majorant over the
//! media's bounds ([`GlobalMedia`](super::GlobalMedia) uses it).

use glam::Vec3;

use super::field::{Bounds3, MajorantSegment};

/// The one segment of a global majorant: the ray's overlap with `bounds`,
/// or nothing when it misses or the majorant is zero (minorant 0, so
/// residual ratio tracking degenerates to ratio tracking).
pub(crate) fn global_segment(
    bounds: Bounds3,
    majorant: f32,
    origin: Vec3,
    dir: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<MajorantSegment> {
    bounds
        .clip_ray(origin, dir, t_min, t_max)
        .filter(|(t0, t1)| t1 > t0 && majorant > 0.0)
        .map(|(t0, t1)| MajorantSegment {
            t0,
            t1,
            minorant: 0.0,
            majorant,
        })
}
