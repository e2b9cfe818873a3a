//! [`Media`]: what the trackers and integrators need from whatever fills
//! the scene, one [`Medium`](super::Medium) or several overlapping ones
//! ([`Volumes`](crate::volumes::Volumes)).
//!
//! Extinction is the sum over the media present at a point, so the
//! trackers only ever see one scalar field and its majorant segments, in
//! extinction units (1 / render-space length). For chromatic media that
//! scalar is each instance's largest channel, summed: it bounds every
//! channel's extinction, so the same majorants serve all three, and
//! [`Media::extinction`] gives the channels themselves as a `Vec3`. What differs between
//! instances, albedo, phase function and emission, is asked for only at a
//! real collision: [`Media::interaction`] picks the instance that scattered
//! with probability `sigma_t,i / sigma_t`, which makes the mixture's
//! scattering and emission terms unbiased (the collision-type selection of
//! Novak et al. 2018, "Monte Carlo methods for volumetric light transport
//! simulation", section 5.1, over instances instead of event types).

use glam::Vec3;

use super::field::{Bounds3, Lattice, MajorantSegment};
use crate::counters::Counters;
use crate::phase::Phase;
use crate::sampling::Rng;
use crate::spectrum::Spectrum;

/// What scatters (or emits) at a real collision.
///
/// The phase function is borrowed from the medium: a tabulated one lives
/// behind an `Arc`, and cloning that per collision would put an atomic
/// counter shared by every thread on the hot path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interaction<'a> {
    /// `sigma_s / sigma_t` of the chosen instance, per RGB channel.
    pub albedo: Vec3,
    pub phase: &'a Phase,
    /// Index of the chosen instance (0 for a lone medium).
    pub instance: u32,
    /// Per channel, `sigma_t,i / (sigma_t q_i)`: the chosen instance's
    /// share of the channel's extinction over the probability `q_i` it was
    /// chosen with. 1 for grey media, where `q_i` is that share exactly;
    /// chromatic estimators multiply by it.
    pub weight: Vec3,
    /// The instance is a holdout: it shadows and lights the others as
    /// before, but a camera path that meets it first shows nothing.
    pub holdout: bool,
}

/// The participating media of a scene, in render space: what the trackers
/// and integrators need, and nothing else. Every method is required, so a
/// wrapper ([`GlobalMedia`]) cannot silently miss one.
pub trait Media: Send + Sync {
    type Majorants<'a>: Iterator<Item = MajorantSegment>
    where
        Self: 'a;

    /// Front-to-back, disjoint majorant segments of the total extinction
    /// along the ray within `[t_min, t_max]` (gaps: zero extinction), in
    /// extinction units.
    fn majorants(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Majorants<'_>;

    /// Total extinction at `p` at shutter time `time` (the trackers look it
    /// up at a ray's time; media without motion are the same at every
    /// time): per channel for `Vec3`, and for `f32` the sum of each
    /// instance's largest channel, a bound of every channel
    /// ([`Spectrum::tinted`]).
    fn extinction<S: Spectrum>(&self, p: Vec3, time: f32) -> S;

    /// Whether extinction differs between colour channels anywhere; when
    /// false every channel's extinction is the scalar one and the
    /// integrators track `f32`.
    fn chromatic(&self) -> bool;

    /// `Some(tint)` when every channel's extinction is `tint` times the
    /// scalar extinction everywhere (grey media: 1), so a march can look
    /// up one scalar; `None` for mixtures of differently tinted media.
    fn uniform_tint(&self) -> Option<Vec3>;

    /// Calls `visit(t, sigma_t)` at the points of `lattice` along the ray
    /// within `[0, t_max]` where the scalar extinction may be non-zero (see
    /// [`DensityField::march_lattice`]), until `visit` returns false;
    /// returns the walk's steps.
    fn march_lattice(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        visit: impl FnMut(f32, f32) -> bool,
    ) -> u64;

    /// Render-space bounds of where extinction may be non-zero.
    fn bounds(&self) -> Bounds3;

    /// Smallest voxel size (ray-march steps are given in voxels).
    fn voxel_size(&self) -> f32;

    /// An upper bound of the scalar extinction everywhere (the
    /// global-majorant mode).
    fn max_sigma_t(&self) -> f32;

    /// The instance that a real collision at `p` at shutter time `time`
    /// belongs to, chosen with probability `sigma_t,i(p) / sigma_t(p)`.
    /// Draws from `rng` only when several instances overlap at `p`, so a
    /// lone medium's random streams are those of a single-medium renderer.
    fn interaction(&self, p: Vec3, time: f32, rng: &mut Rng) -> Interaction<'_>;

    /// Whether any instance emits; when false the integrators do no
    /// emission work at all.
    fn emits(&self) -> bool;

    /// Emitted radiance `Le` of `instance` at `p` at shutter time `time`
    /// (the source term of the radiative transfer equation is
    /// `sigma_a * Le`; emission grids move with the density); counts its
    /// lookups.
    fn emission(&self, p: Vec3, time: f32, instance: u32, c: &mut Counters) -> Vec3;
}

/// A field's segments multiplied by a density scale.
pub struct Scaled<I> {
    inner: I,
    scale: f32,
}

impl<I: Iterator<Item = MajorantSegment>> Iterator for Scaled<I> {
    type Item = MajorantSegment;

    #[inline]
    fn next(&mut self) -> Option<MajorantSegment> {
        let s = self.inner.next()?;
        Some(MajorantSegment {
            minorant: self.scale * s.minorant,
            majorant: self.scale * s.majorant,
            ..s
        })
    }
}

impl<I> Scaled<I> {
    pub fn new(inner: I, scale: f32) -> Self {
        Self { inner, scale }
    }
}

/// Any media seen through one global majorant over their bounds (Mitsuba
/// 3's `heterogeneous` medium; minorant 0, so residual ratio tracking
/// degenerates to ratio tracking). The benchmarks' baseline.
pub struct GlobalMedia<'m, M> {
    inner: &'m M,
    majorant: f32,
}

impl<'m, M: Media> GlobalMedia<'m, M> {
    pub fn new(inner: &'m M) -> Self {
        Self {
            majorant: inner.max_sigma_t(),
            inner,
        }
    }
}

impl<M: Media> Media for GlobalMedia<'_, M> {
    type Majorants<'a>
        = std::option::IntoIter<MajorantSegment>
    where
        Self: 'a;

    fn majorants(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Majorants<'_> {
        super::global::global_segment(
            self.inner.bounds(),
            self.majorant,
            origin,
            dir,
            t_min,
            t_max,
        )
        .into_iter()
    }

    fn extinction<S: Spectrum>(&self, p: Vec3, time: f32) -> S {
        self.inner.extinction(p, time)
    }
    fn chromatic(&self) -> bool {
        self.inner.chromatic()
    }
    fn uniform_tint(&self) -> Option<Vec3> {
        self.inner.uniform_tint()
    }
    /// The global bound's one segment, walked: there are no occupied cells
    /// to skip by.
    fn march_lattice(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        mut visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        lattice.visit_segments(self.majorants(origin, dir, 0.0, t_max), |t| {
            visit(t, self.extinction(origin + dir * t, 0.0))
        })
    }
    fn bounds(&self) -> Bounds3 {
        self.inner.bounds()
    }
    fn voxel_size(&self) -> f32 {
        self.inner.voxel_size()
    }
    fn max_sigma_t(&self) -> f32 {
        self.majorant
    }
    fn interaction(&self, p: Vec3, time: f32, rng: &mut Rng) -> Interaction<'_> {
        self.inner.interaction(p, time, rng)
    }
    fn emits(&self) -> bool {
        self.inner.emits()
    }
    fn emission(&self, p: Vec3, time: f32, instance: u32, c: &mut Counters) -> Vec3 {
        self.inner.emission(p, time, instance, c)
    }
}

/// Borrowed media are media, so a [`Scene`](crate::Scene) can borrow them.
impl<M: Media> Media for &M {
    type Majorants<'a>
        = M::Majorants<'a>
    where
        Self: 'a;

    fn majorants(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Majorants<'_> {
        (**self).majorants(origin, dir, t_min, t_max)
    }
    fn extinction<S: Spectrum>(&self, p: Vec3, time: f32) -> S {
        (**self).extinction(p, time)
    }
    fn chromatic(&self) -> bool {
        (**self).chromatic()
    }
    fn uniform_tint(&self) -> Option<Vec3> {
        (**self).uniform_tint()
    }
    fn march_lattice(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        (**self).march_lattice(origin, dir, t_max, lattice, visit)
    }
    fn bounds(&self) -> Bounds3 {
        (**self).bounds()
    }
    fn voxel_size(&self) -> f32 {
        (**self).voxel_size()
    }
    fn max_sigma_t(&self) -> f32 {
        (**self).max_sigma_t()
    }
    fn interaction(&self, p: Vec3, time: f32, rng: &mut Rng) -> Interaction<'_> {
        (**self).interaction(p, time, rng)
    }
    fn emits(&self) -> bool {
        (**self).emits()
    }
    fn emission(&self, p: Vec3, time: f32, instance: u32, c: &mut Counters) -> Vec3 {
        (**self).emission(p, time, instance, c)
    }
}
