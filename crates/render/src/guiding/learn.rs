//! What a camera path teaches the cache: at each scattering vertex, the
//! light that came back along the direction it left by.
//!
//! The path tracer calls a [`Learner`] at each scattered direction and
//! each contribution it adds; [`PathRecorder`] turns them into
//! [`Record`]s when the path ends, and [`Ignore`] (every render pass after
//! training) compiles to nothing. The radiance arriving at vertex `i`
//! along its sampled direction is everything the path added after it,
//! over the throughput it carried out of `i` (Müller et al. 2017, section
//! 3.2): a one-sample estimate of `L_i(x_i, w_i)`.

use glam::Vec3;
use smallvec::SmallVec;

use super::regions::Record;
use super::sphere::bin_of;
use super::Site;

/// Luminance (Rec. 709): how a colour is weighed for learning.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// What a path reports as it goes.
pub trait Learner {
    /// Whether it learns: a path that teaches the cache is never split
    /// (its records follow one chain of vertices).
    const LEARNS: bool;
    /// A scattering vertex at `site` left along `dir`, its throughput
    /// multiplied by `weight` there (the phase function over the density
    /// the direction was sampled with); `beta` is the throughput after it,
    /// `direct` the light next-event estimation found there (not weighted
    /// by the throughput).
    fn scatter(&mut self, site: Site, dir: Vec3, weight: f32, beta: Vec3, direct: Vec3);
    /// The path added `c` (throughput included) to its pixel.
    fn contribute(&mut self, c: Vec3);
    /// The path ended.
    fn finish(&mut self);
}

/// Learns nothing (the render passes).
pub struct Ignore;

impl Learner for Ignore {
    const LEARNS: bool = false;
    #[inline(always)]
    fn scatter(&mut self, _: Site, _: Vec3, _: f32, _: Vec3, _: Vec3) {}
    #[inline(always)]
    fn contribute(&mut self, _: Vec3) {}
    #[inline(always)]
    fn finish(&mut self) {}
}

/// Vertices recorded per path, at most (the first ones, where a path
/// learns most; a longer path's later vertices teach nothing more).
const MAX_VERTICES: usize = 64;

#[derive(Clone, Copy)]
struct Vertex {
    site: Site,
    bin: u16,
    weight: f32,
    beta: f32,
    /// The path's total contribution when it left this vertex.
    total_at: f32,
    direct: f32,
}

/// Records the vertices of the paths of one tile (in order).
pub struct PathRecorder<'a> {
    out: &'a mut Vec<Record>,
    vertices: SmallVec<[Vertex; 16]>,
    total: f32,
}

impl<'a> PathRecorder<'a> {
    pub fn new(out: &'a mut Vec<Record>) -> Self {
        Self {
            out,
            vertices: SmallVec::new(),
            total: 0.0,
        }
    }
}

impl Learner for PathRecorder<'_> {
    const LEARNS: bool = true;
    fn scatter(&mut self, site: Site, dir: Vec3, weight: f32, beta: Vec3, direct: Vec3) {
        if self.vertices.len() < MAX_VERTICES {
            self.vertices.push(Vertex {
                site,
                bin: bin_of(dir) as u16,
                weight,
                beta: luminance(beta),
                total_at: self.total,
                direct: luminance(direct),
            });
        }
    }

    fn contribute(&mut self, c: Vec3) {
        self.total += luminance(c);
    }

    fn finish(&mut self) {
        for v in self.vertices.drain(..) {
            if v.beta.is_nan() || v.beta <= 0.0 {
                continue;
            }
            let incident = ((self.total - v.total_at) / v.beta).max(0.0);
            self.out.push(Record {
                region: v.site.region,
                cell: v.site.cell,
                bin: v.bin,
                incident,
                inscattered: v.weight * incident + v.direct,
            });
        }
        self.total = 0.0;
    }
}
