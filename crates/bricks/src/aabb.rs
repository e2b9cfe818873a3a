//! Axis-aligned boxes: [`Bounds3`] in `f32` (a volume's local index space,
//! render space) and [`DBounds3`] in `f64` (world space, where volumes far
//! from the origin keep their precision). Plain `Copy` values, glam style.
//!
//! One ray test, [`Bounds3::clip_ray`]: it handles direction components
//! of zero explicitly (a ray in a slab's plane is inside or outside by its
//! origin, never `0 * inf = NaN`) and clips to a parameter range. There is
//! deliberately no bare slab test with a precomputed `1 / dir`: glam's
//! `min`/`max` are ordered compares that keep a NaN in one operand, so
//! such a test can return an infinite or NaN end for a ray along a face.

use glam::{DMat4, DVec3, Vec3};

/// The box `[min, max]`; empty when any `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3 {
    pub min: Vec3,
    pub max: Vec3,
}

/// The box `[min, max]` in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DBounds3 {
    pub min: DVec3,
    pub max: DVec3,
}

/// Corner `k` (bit 0: x, bit 1: y, bit 2: z pick `max` over `min`).
macro_rules! corners {
    ($b:expr, $v:ident) => {
        std::array::from_fn(|k| {
            $v::new(
                if k & 1 == 0 { $b.min.x } else { $b.max.x },
                if k & 2 == 0 { $b.min.y } else { $b.max.y },
                if k & 4 == 0 { $b.min.z } else { $b.max.z },
            )
        })
    };
}

impl Bounds3 {
    /// The identity of [`union`](Self::union).
    pub const EMPTY: Self = Self {
        min: Vec3::INFINITY,
        max: Vec3::NEG_INFINITY,
    };

    pub const fn new(min: Vec3, max: Vec3) -> Self {
        Self { min, max }
    }

    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    pub fn centre(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    pub fn union(self, o: Self) -> Self {
        Self::new(self.min.min(o.min), self.max.max(o.max))
    }

    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    pub fn corners(&self) -> [Vec3; 8] {
        corners!(self, Vec3)
    }

    /// The box in `f64`.
    pub fn as_dbounds(&self) -> DBounds3 {
        DBounds3::new(self.min.as_dvec3(), self.max.as_dvec3())
    }

    /// The parametric overlap `[t0, t1]` of the ray `origin + t dir` with
    /// the box, restricted to `[t_min, t_max]`, or `None` if empty.
    #[inline]
    pub fn clip_ray(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Option<(f32, f32)> {
        let mut t0 = t_min;
        let mut t1 = t_max;
        for axis in 0..3 {
            let (o, d) = (origin[axis], dir[axis]);
            if d == 0.0 {
                if o < self.min[axis] || o > self.max[axis] {
                    return None;
                }
                continue;
            }
            let inv = 1.0 / d;
            let (mut a, mut b) = ((self.min[axis] - o) * inv, (self.max[axis] - o) * inv);
            if a > b {
                std::mem::swap(&mut a, &mut b);
            }
            t0 = t0.max(a);
            t1 = t1.min(b);
        }
        (t0 <= t1).then_some((t0, t1))
    }
}

impl DBounds3 {
    /// The identity of [`union`](Self::union).
    pub const EMPTY: Self = Self {
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
    };

    pub const fn new(min: DVec3, max: DVec3) -> Self {
        Self { min, max }
    }

    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    pub fn centre(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    pub fn size(&self) -> DVec3 {
        self.max - self.min
    }

    pub fn union(self, o: Self) -> Self {
        Self::new(self.min.min(o.min), self.max.max(o.max))
    }

    pub fn corners(&self) -> [DVec3; 8] {
        corners!(self, DVec3)
    }

    /// The box around this box's corners mapped by `m` (an affine map).
    pub fn transformed(&self, m: DMat4) -> Self {
        self.corners()
            .into_iter()
            .map(|c| m.transform_point3(c))
            .fold(Self::EMPTY, |b, p| Self::new(b.min.min(p), b.max.max(p)))
    }

    /// The box moved by `-offset` and rounded to `f32` (world to render space).
    pub fn relative_to(&self, offset: DVec3) -> Bounds3 {
        Bounds3::new((self.min - offset).as_vec3(), (self.max - offset).as_vec3())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_union_and_transforms() {
        let b = Bounds3::new(Vec3::new(0.0, 1.0, 2.0), Vec3::new(3.0, 4.0, 5.0));
        let c = b.corners();
        assert_eq!(c[0], b.min);
        assert_eq!(c[7], b.max);
        assert_eq!(c[5], Vec3::new(3.0, 1.0, 5.0));
        assert_eq!(Bounds3::EMPTY.union(b), b);
        assert!(Bounds3::EMPTY.is_empty() && !b.is_empty());
        assert_eq!(b.centre(), Vec3::new(1.5, 2.5, 3.5));
        let d = b.as_dbounds();
        let m = DMat4::from_translation(DVec3::new(10.0, 0.0, 0.0))
            * DMat4::from_rotation_z(std::f64::consts::FRAC_PI_2);
        let t = d.transformed(m);
        // (x, y) -> (-y, x), then +10 in x.
        assert!(
            (t.min - DVec3::new(6.0, 0.0, 2.0)).abs().max_element() < 1e-12,
            "{t:?}"
        );
        assert!(
            (t.max - DVec3::new(9.0, 3.0, 5.0)).abs().max_element() < 1e-12,
            "{t:?}"
        );
        assert_eq!(
            d.relative_to(DVec3::ONE),
            Bounds3::new(Vec3::new(-1.0, 0.0, 1.0), Vec3::new(2.0, 3.0, 4.0))
        );
    }

    #[test]
    fn clip_agrees_with_an_f64_slab_test_off_the_faces_and_handles_them() {
        let b = Bounds3::new(Vec3::ZERO, Vec3::splat(2.0));
        let mut s = 1u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 40) as f32 / (1u64 << 24) as f32) * 6.0 - 3.0
        };
        for _ in 0..2000 {
            let o = Vec3::new(rnd(), rnd(), rnd());
            let d = Vec3::new(rnd(), rnd(), rnd());
            // The slab test in f64, whose direction has no zero here.
            let (lo, hi) = (
                (b.min.as_dvec3() - o.as_dvec3()) / d.as_dvec3(),
                (b.max.as_dvec3() - o.as_dvec3()) / d.as_dvec3(),
            );
            let (a0, a1) = (
                lo.min(hi).max_element() as f32,
                lo.max(hi).min_element() as f32,
            );
            let clipped = b.clip_ray(o, d, f32::NEG_INFINITY, f32::INFINITY);
            match clipped {
                Some((c0, c1)) => assert!((c0 - a0).abs() < 1e-5 && (c1 - a1).abs() < 1e-5),
                None => assert!(a0 > a1),
            }
        }
        // A ray lying in the plane x = 0 (a face): inside by its origin.
        let along = b.clip_ray(Vec3::new(0.0, 1.0, -1.0), Vec3::Z, 0.0, 10.0);
        assert_eq!(along, Some((1.0, 3.0)));
        assert_eq!(
            b.clip_ray(Vec3::new(-0.5, 1.0, -1.0), Vec3::Z, 0.0, 10.0),
            None
        );
        // On a face, with a zero (or negative zero) component: inside,
        // with a finite end whatever the face.
        for o in [Vec3::new(0.0, 1.0, 1.0), Vec3::new(2.0, 1.0, 1.0)] {
            for d in [
                Vec3::Y,
                Vec3::new(-0.0, 1.0, 0.0),
                Vec3::new(0.0, -1.0, -0.0),
            ] {
                let (t0, t1) = b.clip_ray(o, d, 0.0, f32::INFINITY).unwrap();
                assert_eq!((t0, t1), (0.0, 1.0), "{o} {d}");
            }
        }
        // Restricted to [t_min, t_max].
        assert_eq!(
            b.clip_ray(Vec3::new(1.0, 1.0, -1.0), Vec3::Z, 1.5, 2.0),
            Some((1.5, 2.0))
        );
        assert_eq!(
            b.clip_ray(Vec3::new(1.0, 1.0, -1.0), Vec3::Z, 0.0, 0.5),
            None
        );
    }
}
