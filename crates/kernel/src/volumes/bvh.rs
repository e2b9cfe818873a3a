//! The top-level BVH over volume instances (obvhs 0.4, PLOC build).
//!
//! obvhs's `Aabb::intersect_ray` returns only the entry distance, so each
//! candidate leaf is re-tested here with a full slab test that gives the
//! instance's `[t0, t1]` along the ray. A ray that misses every instance
//! costs one box test: obvhs tests the root before anything else.

use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::ploc::{PlocBuilder, PlocSearchDistance, SortPrecision};
use obvhs::ray::Ray as BvhRay;
use smallvec::SmallVec;

use crate::medium::Bounds3;

/// One instance a ray meets, over `[t0, t1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub instance: u32,
    pub t0: f32,
    pub t1: f32,
}

/// Hits of one ray, inline up to eight.
pub type Hits = SmallVec<[Hit; 8]>;

/// Render-space boxes of the instances and the BVH over them.
pub struct TopLevel {
    bounds: Vec<Bounds3>,
    bvh: Bvh2,
}

impl TopLevel {
    pub fn new(bounds: Vec<Bounds3>) -> Self {
        let aabbs: Vec<Aabb> = bounds
            .iter()
            .map(|b| Aabb::new(Vec3A::from(b.min), Vec3A::from(b.max)))
            .collect();
        let indices = (0..aabbs.len() as u32).collect();
        let bvh = if aabbs.is_empty() {
            Bvh2::default()
        } else {
            PlocBuilder::new().build(
                PlocSearchDistance::Minimum,
                &aabbs,
                indices,
                SortPrecision::U64,
                0,
            )
        };
        Self { bounds, bvh }
    }

    pub fn bounds(&self, instance: usize) -> Bounds3 {
        self.bounds[instance]
    }

    /// The instances the ray `origin + t dir` meets within `[t_min, t_max]`,
    /// sorted by entry.
    pub fn hits(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Hits {
        let mut hits = Hits::new();
        if !(origin.is_finite() && dir.is_finite()) || dir == Vec3::ZERO {
            return hits;
        }
        let ray = BvhRay::new(Vec3A::from(origin), Vec3A::from(dir), t_min, t_max);
        self.bvh.ray_traverse_anyhit(ray, |_, id| {
            let instance = self.bvh.primitive_indices[id];
            let b = self.bounds[instance as usize];
            if let Some((t0, t1)) = b.clip_ray(origin, dir, t_min, t_max) {
                if t1 > t0 {
                    hits.push(Hit { instance, t0, t1 });
                }
            }
        });
        hits.sort_unstable_by(|a, b| a.t0.total_cmp(&b.t0));
        hits
    }

    /// Calls `f(instance)` for every instance whose box contains `p`.
    #[inline]
    pub fn containing(&self, p: Vec3, mut f: impl FnMut(usize)) {
        // A linear scan beats the tree for the few instances of a usual
        // scene; the tree takes over for crowds.
        if self.bounds.len() <= 8 {
            for (i, b) in self.bounds.iter().enumerate() {
                if b.contains(p) {
                    f(i);
                }
            }
            return;
        }
        self.bvh.point_traverse(Vec3A::from(p), |bvh, node| {
            let n = &bvh.nodes[node as usize];
            for k in n.first_index..n.first_index + n.prim_count {
                let i = bvh.primitive_indices[k as usize] as usize;
                if self.bounds[i].contains(p) {
                    f(i);
                }
            }
            true
        });
    }
}
