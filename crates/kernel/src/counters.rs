//! What the integrators and trackers did: plain counters.
//!
//! Counters are plain integers in a struct each rayon task owns; tasks sum
//! theirs at the end of a pass, so the hot loops never touch an atomic.

use std::ops::AddAssign;

use serde::Serialize;

/// What the integrators and trackers did; summed over tasks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Counters {
    /// Camera samples (one path, or one marched camera ray, each).
    pub paths: u64,
    pub density_lookups: u64,
    /// Delta-tracking collisions accepted as real.
    pub real_collisions: u64,
    /// Delta-tracking collisions rejected as null.
    pub null_collisions: u64,
    /// Tentative collisions of ratio and residual tracking (shadow rays),
    /// each a density lookup and a weight.
    pub shadow_collisions: u64,
    /// Majorant segments visited by the trackers; for the ray marchers,
    /// the walk's steps (segments, or over occupied cells: one to enter
    /// the first, one per empty cube skipped).
    pub dda_segments: u64,
    pub shadow_rays: u64,
    /// Tracker calls stopped by the per-call collision cap.
    pub collision_cap_hits: u64,
    /// Density lookups that exceeded their segment's majorant (a field bug
    /// that would bias delta tracking; ratio weights are clamped to 0).
    pub majorant_violations: u64,
    /// Samples that came out NaN or infinite and were replaced by 0.
    pub nonfinite_samples: u64,
    /// Emission grid lookups (temperature or emission) at collisions.
    pub emission_lookups: u64,
    /// Next-event shadow rays toward distant lights (sunward scattering's
    /// included)...
    pub nee_rays_distant: u64,
    /// ...toward domes...
    pub nee_rays_dome: u64,
    /// ...toward sphere, point and spot lights...
    pub nee_rays_sphere: u64,
    /// ...and toward area lights.
    pub nee_rays_area: u64,
    /// Times a dome was consulted: directions sampled from it for
    /// next-event estimation, and escaped rays looking it up.
    pub dome_samples: u64,
    /// Distances drawn by equi-angular sampling toward sphere lights
    /// (`integrator/path_equiangular.rs`), each a transmittance walk and a
    /// shadow ray.
    pub equiangular_samples: u64,
    /// Directions drawn toward a distant light by sunward scattering
    /// (`integrator/path_sunward.rs`), each a free flight and, where it
    /// collides, a shadow ray.
    pub sunward_rays: u64,
}

impl AddAssign for Counters {
    fn add_assign(&mut self, o: Self) {
        self.paths += o.paths;
        self.density_lookups += o.density_lookups;
        self.real_collisions += o.real_collisions;
        self.null_collisions += o.null_collisions;
        self.shadow_collisions += o.shadow_collisions;
        self.dda_segments += o.dda_segments;
        self.shadow_rays += o.shadow_rays;
        self.collision_cap_hits += o.collision_cap_hits;
        self.majorant_violations += o.majorant_violations;
        self.nonfinite_samples += o.nonfinite_samples;
        self.emission_lookups += o.emission_lookups;
        self.nee_rays_distant += o.nee_rays_distant;
        self.nee_rays_dome += o.nee_rays_dome;
        self.nee_rays_sphere += o.nee_rays_sphere;
        self.nee_rays_area += o.nee_rays_area;
        self.dome_samples += o.dome_samples;
        self.sunward_rays += o.sunward_rays;
        self.equiangular_samples += o.equiangular_samples;
    }
}

impl std::ops::Add for Counters {
    type Output = Self;
    fn add(mut self, o: Self) -> Self {
        self += o;
        self
    }
}
