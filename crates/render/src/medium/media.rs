//! [`Media`]: what the trackers and integrators need from whatever fills
//! the scene, one [`Medium`] or several overlapping volume instances
//! ([`Volumes`](crate::volumes::Volumes)).
//!
//! Extinction is the sum over the media present at a point, so the
//! trackers only ever see one scalar field and its majorant segments, in
//! extinction units (1 / render-space length). For chromatic media that
//! scalar is each instance's largest channel, summed: it bounds every
//! channel's extinction, so the same majorants serve all three, and
//! [`Media::sigma_t_rgb`] gives the channels themselves. What differs between
//! instances, albedo, phase function and emission, is asked for only at a
//! real collision: [`Media::interaction`] picks the instance that scattered
//! with probability `sigma_t,i / sigma_t`, which makes the mixture's
//! scattering and emission terms unbiased (the collision-type selection of
//! Novak et al. 2018, "Monte Carlo methods for volumetric light transport
//! simulation", section 5.1, over instances instead of event types).

use glam::Vec3;

use super::field::{Bounds3, DensityField, Lattice, MajorantSegment};
use super::Medium;
use crate::phase::Phase;
use crate::sampling::Rng;
use crate::stats::Counters;

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
}

/// The participating media of a scene, in render space.
pub trait Media: Send + Sync {
    type Majorants<'a>: Iterator<Item = MajorantSegment>
    where
        Self: 'a;

    /// Front-to-back, disjoint majorant segments of the total extinction
    /// along the ray within `[t_min, t_max]` (gaps: zero extinction), in
    /// extinction units.
    fn majorants(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Majorants<'_>;

    /// Total extinction coefficient at `p` (of chromatic media: the sum of
    /// each instance's largest channel, a bound of every channel).
    fn sigma_t(&self, p: Vec3) -> f32;

    /// Calls `visit(t, sigma_t)` at the points of `lattice` along the ray
    /// within `[0, t_max]` where the extinction may be non-zero (see
    /// [`DensityField::march_lattice`]), until `visit` returns false;
    /// returns the walk's steps. The default walks the majorant segments.
    fn march_lattice(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        mut visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        lattice.visit_segments(self.majorants(origin, dir, 0.0, t_max), |t| {
            visit(t, self.sigma_t(origin + dir * t))
        })
    }

    /// `Some(tint)` when every channel's extinction is `tint` times
    /// [`sigma_t`](Self::sigma_t) everywhere (grey media: 1), so a march
    /// can look up one scalar; `None` for mixtures of differently tinted
    /// media.
    fn uniform_tint(&self) -> Option<Vec3> {
        (!self.chromatic()).then_some(Vec3::ONE)
    }

    /// Total extinction at `p` at shutter time `time` (what the trackers
    /// look up: a ray's time). Media without motion are the same at every
    /// time, which is the default.
    #[inline]
    fn sigma_t_at(&self, p: Vec3, _time: f32) -> f32 {
        self.sigma_t(p)
    }

    /// Whether extinction differs between colour channels anywhere; when
    /// false every channel's extinction is [`Media::sigma_t`] and the
    /// integrators take their scalar paths.
    fn chromatic(&self) -> bool {
        false
    }

    /// Extinction per RGB channel at `p` at shutter time `time`, each at
    /// most [`Media::sigma_t_at`].
    #[inline]
    fn sigma_t_rgb_at(&self, p: Vec3, time: f32) -> Vec3 {
        Vec3::splat(self.sigma_t_at(p, time))
    }

    /// Render-space bounds of where extinction may be non-zero.
    fn bounds(&self) -> Bounds3;

    /// Smallest voxel size (ray-march steps are given in voxels).
    fn voxel_size(&self) -> f32;

    /// An upper bound of `sigma_t` everywhere (the global-majorant mode).
    fn max_sigma_t(&self) -> f32;

    /// The instance that a real collision at `p` belongs to, chosen with
    /// probability `sigma_t,i(p) / sigma_t(p)`. Draws from `rng` only when
    /// several instances overlap at `p`, so a lone medium's random streams
    /// are those of the single-medium renderer.
    fn interaction(&self, p: Vec3, rng: &mut Rng) -> Interaction<'_>;

    /// [`interaction`](Self::interaction) with the instances' extinctions
    /// taken at shutter time `time`.
    #[inline]
    fn interaction_at(&self, p: Vec3, _time: f32, rng: &mut Rng) -> Interaction<'_> {
        self.interaction(p, rng)
    }

    /// Whether any instance emits; when false the integrators do no
    /// emission work at all.
    fn emits(&self) -> bool {
        false
    }

    /// Whether `instance` is a holdout: it shadows and lights the others
    /// as before, but a camera path that meets it first shows nothing.
    #[inline]
    fn holdout(&self, _instance: u32) -> bool {
        false
    }

    /// Emitted radiance `Le` of `instance` at `p` (the source term of the
    /// radiative transfer equation is `sigma_a * Le`); counts its lookups.
    fn emission(&self, _p: Vec3, _instance: u32, _c: &mut Counters) -> Vec3 {
        Vec3::ZERO
    }

    /// [`emission`](Self::emission) at shutter time `time` (emission
    /// grids move with the density).
    #[inline]
    fn emission_at(&self, p: Vec3, _time: f32, instance: u32, c: &mut Counters) -> Vec3 {
        self.emission(p, instance, c)
    }
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

/// A lone medium: one field, one material, no emission.
impl<F: DensityField> Media for Medium<F> {
    type Majorants<'a>
        = Scaled<F::Segments<'a>>
    where
        Self: 'a;

    #[inline]
    fn majorants(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Majorants<'_> {
        Scaled::new(
            self.field.segments(origin, dir, t_min, t_max),
            self.density_scale,
        )
    }

    #[inline]
    fn sigma_t(&self, p: Vec3) -> f32 {
        self.density_scale * self.field.density(p)
    }

    #[inline]
    fn sigma_t_at(&self, p: Vec3, time: f32) -> f32 {
        self.density_scale * self.field.density_at(p, time)
    }

    fn march_lattice(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        lattice: Lattice,
        mut visit: impl FnMut(f32, f32) -> bool,
    ) -> u64 {
        let scale = self.density_scale;
        self.field
            .march_lattice(origin, dir, t_max, lattice, |t, d| visit(t, scale * d))
    }

    fn uniform_tint(&self) -> Option<Vec3> {
        Some(self.extinction_tint)
    }

    fn chromatic(&self) -> bool {
        self.extinction_tint != Vec3::ONE
    }

    #[inline]
    fn sigma_t_rgb_at(&self, p: Vec3, time: f32) -> Vec3 {
        self.extinction_tint * self.sigma_t_at(p, time)
    }

    fn bounds(&self) -> Bounds3 {
        self.field.bounds()
    }

    fn voxel_size(&self) -> f32 {
        self.field.voxel_size()
    }

    fn max_sigma_t(&self) -> f32 {
        self.density_scale * self.field.global_majorant()
    }

    #[inline]
    fn interaction(&self, _p: Vec3, _rng: &mut Rng) -> Interaction<'_> {
        Interaction {
            albedo: self.albedo,
            phase: &self.phase,
            instance: 0,
            weight: Vec3::ONE,
        }
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

    fn sigma_t(&self, p: Vec3) -> f32 {
        self.inner.sigma_t(p)
    }
    fn sigma_t_at(&self, p: Vec3, time: f32) -> f32 {
        self.inner.sigma_t_at(p, time)
    }
    fn chromatic(&self) -> bool {
        self.inner.chromatic()
    }
    fn sigma_t_rgb_at(&self, p: Vec3, time: f32) -> Vec3 {
        self.inner.sigma_t_rgb_at(p, time)
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
    fn interaction(&self, p: Vec3, rng: &mut Rng) -> Interaction<'_> {
        self.inner.interaction(p, rng)
    }
    fn interaction_at(&self, p: Vec3, time: f32, rng: &mut Rng) -> Interaction<'_> {
        self.inner.interaction_at(p, time, rng)
    }
    fn emits(&self) -> bool {
        self.inner.emits()
    }
    fn holdout(&self, instance: u32) -> bool {
        self.inner.holdout(instance)
    }
    fn emission(&self, p: Vec3, instance: u32, c: &mut Counters) -> Vec3 {
        self.inner.emission(p, instance, c)
    }
    fn emission_at(&self, p: Vec3, time: f32, instance: u32, c: &mut Counters) -> Vec3 {
        self.inner.emission_at(p, time, instance, c)
    }
}
