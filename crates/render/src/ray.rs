//! Rays and the one piece of geometry a volume renderer needs: clipping a ray
//! to an axis-aligned box.

use glam::Vec3;

/// A ray `origin + t * dir`. The integrators keep `dir` normalised so t is a
/// distance in render-space units.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self { origin, dir }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}

/// The parametric overlap `[t0, t1]` of the ray with the box `[lo, hi]`,
/// restricted to `[t_min, t_max]`, or `None` if empty.
///
/// Slab test written per axis with explicit handling of zero direction
/// components, so a ray lying in a slab's plane gives no `0 * inf = NaN`.
#[inline]
pub fn clip_to_box(
    origin: Vec3,
    dir: Vec3,
    lo: Vec3,
    hi: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<(f32, f32)> {
    let mut t0 = t_min;
    let mut t1 = t_max;
    for axis in 0..3 {
        let (o, d) = (origin[axis], dir[axis]);
        if d == 0.0 {
            if o < lo[axis] || o > hi[axis] {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d;
        let (mut a, mut b) = ((lo[axis] - o) * inv, (hi[axis] - o) * inv);
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        t0 = t0.max(a);
        t1 = t1.min(b);
    }
    (t0 <= t1).then_some((t0, t1))
}
