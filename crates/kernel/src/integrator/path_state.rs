//! What a camera path is while it is traced, as plain data: the path
//! (its ray, throughput, depth and what it has found), a scattering vertex
//! before and during its light gathering, and how the path's current
//! direction was drawn, which the multiple-importance weights of the next
//! vertex read. The stages that read and write them are `PathTracer`'s
//! methods in `path.rs`, `path_light.rs` and `path_sunward.rs`.

use glam::Vec3;

use super::light_choice::LightChoice;
use super::mis::Strategies;
use super::{LightParts, Sample};
use crate::phase::Phase;
use crate::ray::Ray;

/// What the lights at infinity a ray escapes to add.
#[derive(Clone, Copy, Debug)]
pub(super) enum Escape {
    /// All their light: the camera ray, which no light strategy sampled.
    Full,
    /// Weighted against next-event estimation's samples (power
    /// heuristic): a phase-sampled ray, with the density it had and the
    /// lights' pick probabilities at its vertex.
    Mis(f32, LightChoice),
}

/// A scattering vertex, before its next-event estimation and direction.
#[derive(Clone, Copy)]
pub(super) struct At<'m> {
    pub p: Vec3,
    pub phase: &'m Phase,
    /// The vertex's index in the draw allocation.
    pub vertex: u32,
}

/// A camera path as it is traced: what it carries and what it has found.
#[derive(Clone)]
pub(super) struct Path {
    pub(super) ray: Ray,
    pub(super) beta: Vec3,
    /// Scattering events so far.
    pub(super) depth: u32,
    /// How the lights at infinity the current ray escapes to count.
    pub(super) escape: Escape,
    /// Set after the last allowed scattering event when the media emit:
    /// the path goes on only to find emitted light, lights at infinity
    /// having had their full weight from next-event estimation.
    pub(super) emission_only: bool,
    /// How the current ray's direction was drawn.
    pub(super) arrival: Arrival,
    pub(super) out: Sample,
}

impl Path {
    /// Adds light `parts` reaching the path (throughput included in
    /// `total`), to the pixel and, where `groups`, its light groups.
    #[inline]
    pub(super) fn add(&mut self, total: Vec3, parts: &LightParts, groups: bool) {
        self.out.radiance += total;
        if groups {
            parts.tag_scaled(self.beta, &mut self.out.groups);
        }
    }

    /// Adds light `e` (throughput included) of light group `group`,
    /// gathered beside the path's own vertices or emitted.
    #[inline]
    pub(super) fn add_to_group(&mut self, e: Vec3, group: usize, groups: bool) {
        self.out.radiance += e;
        if groups {
            self.out.groups[group] += e;
        }
    }
}

/// Where and how the light is gathered at a vertex.
pub(super) struct Vertex<'a> {
    pub p: Vec3,
    /// The ray that arrived (its direction and time).
    pub ray_in: &'a Ray,
    pub phase: &'a Phase,
    /// Weight against the scattered direction (false at the last allowed
    /// vertex, whose continuation is not traced).
    pub mis: bool,
    /// The vertex's index in the draw allocation.
    pub index: u32,
    /// The probability that each light is sampled here.
    pub choice: LightChoice,
    /// How the path arrived here, for the sun's weight against sunward
    /// scattering at the previous vertex.
    pub arrival: Arrival,
}

/// How the direction a path travels along was drawn: what the sunward
/// light's next-event estimate at its next vertex weighs itself by.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Arrival {
    /// The continuation's scattering density of the direction.
    pub scatter_pdf: f32,
    /// The sunward strategy's density for it (kept fraction included); 0
    /// where that strategy did not run (the camera ray included), leaving
    /// the next-event estimate its whole weight.
    pub sunward_pdf: f32,
}

impl Arrival {
    /// The weight of the sunward light's next-event estimate at the vertex
    /// this arrival reaches, where it is picked with probability `pick`.
    #[inline]
    pub fn sun_weight(self, pick: f32) -> f32 {
        if self.sunward_pdf > 0.0 {
            Strategies::drawn_with(self.scatter_pdf * pick)
                .or(self.sunward_pdf)
                .weight()
        } else {
            1.0
        }
    }
}
