//! Random numbers and the sampling routines built on them.
//!
//! The generator is counter-based: the `n`-th number of a stream is a hash
//! of `(seed, stream, sample, n)`, with no state shared between pixels. A
//! pixel's samples therefore do not depend on which thread renders them or in
//! what order, which is what makes images bit-identical across thread counts.
//!
//! A camera sample draws through a [`SampleStream`]: with
//! [`SamplerKind::Random`] every number comes from the [`Rng`]; with
//! [`SamplerKind::Sobol`] (the default) the draws that matter most come from
//! Owen-scrambled Sobol points ([`crate::sobol`]), keyed like the `Rng` by
//! (seed, pixel index in the full image, sample index), so thread counts,
//! crops and time budgets see the same numbers.
//!
//! ## Allocation of low-discrepancy draws
//!
//! Each [`Draw`] is its own shuffled, scrambled 1D or 2D point set (Burley
//! 2020's padding), so a draw that is skipped (a light with no sample, a
//! path ended early) shifts nothing else. Per camera sample:
//!
//! | draw | dims | where |
//! |---|---|---|
//! | pixel jitter | 2 | the camera ray's position in the pixel |
//!
//! then for each path vertex `b` (the `b`-th free flight and what follows
//! its collision), while `b <` [`SOBOL_VERTICES`]:
//!
//! | draw | dims | where |
//! |---|---|---|
//! | free-flight distance | 1 | the first optical depth of the delta-tracking walk |
//! | first light sample's direction | 2 | next-event estimation of the first light the vertex samples |
//! | first light sample's shadow ray | 1 | the first optical depth of its transmittance walk |
//! | second light sample's direction | 2 | ... of the second light it samples (every light sampled, or a disc's floor) |
//! | second light sample's shadow ray | 1 | ... |
//! | phase direction | 2 | the scattered direction |
//! | Russian roulette | 1 | the path's survival |
//!
//! With motion blur on (a shutter of non-zero length), the camera sample
//! also draws its **time**: a 1D set of its own, after every slot above
//! ([`Draw::Time`]), or with the random sampler a hash of the sample's key
//! that advances nothing. Either way no other draw moves, so an image
//! without motion is bit-identical to one rendered before time existed.
//!
//! There is no light-selection draw: every scattering event samples each
//! light. Everything else comes from the hashed [`Rng`]: draws made a
//! variable number of times (null-collision decisions and the optical
//! depths after the first, transmittance roulette, the instance picked
//! among overlapping volumes) and every draw past the vertex budget, where
//! the integrand's effective dimension is too high for stratification to
//! pay.

use std::f32::consts::PI;

use glam::Vec3;

use crate::sobol::{OwenSobol, SobolIndex};

/// SplitMix64's output function (Steele, Lea, Flood 2014): a bijective
/// 64-bit mixer whose outputs for consecutive inputs pass BigCrush.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;

/// A counter-based generator: SplitMix64 whose starting state is a hash of
/// `(seed, stream, sample)`, so the `n`-th draw is `mix64(key + n * GOLDEN)`.
///
/// One value can be queued ahead of the stream ([`Rng::queue`]): that is
/// how a low-discrepancy number reaches the first draw of a tracker, whose
/// later draws stay on the stream.
#[derive(Clone, Debug)]
pub struct Rng {
    key: u64,
    counter: u64,
    queued: Option<f32>,
}

impl Rng {
    /// `stream` is typically a pixel index and `sample` the sample index.
    pub fn new(seed: u64, stream: u64, sample: u64) -> Self {
        let mut h = mix64(seed.wrapping_add(GOLDEN));
        h = mix64(h ^ stream.wrapping_mul(0xd6e8_feb8_6659_fd93));
        h = mix64(h ^ sample.wrapping_mul(0xa076_1d64_78bd_642f));
        Self {
            key: h,
            counter: 0,
            queued: None,
        }
    }

    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.counter = self.counter.wrapping_add(1);
        mix64(self.key.wrapping_add(self.counter.wrapping_mul(GOLDEN)))
    }

    /// Uniform in `[0, 1)`: the queued value if there is one, else the
    /// stream's top 24 bits, so every value is exact in f32 and 1.0 is
    /// never returned.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        if let Some(u) = self.queued.take() {
            return u;
        }
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    /// Makes the next [`uniform`](Self::uniform) return `u` (in `[0, 1)`)
    /// without advancing the stream.
    #[inline]
    pub fn queue(&mut self, u: f32) {
        self.queued = Some(u);
    }

    /// Drops a queued value nobody drew.
    #[inline]
    pub fn clear_queue(&mut self) {
        self.queued = None;
    }

    /// How many numbers this stream has produced (its dimension).
    pub fn dimension(&self) -> u64 {
        self.counter
    }
}

settings_enum! {
    /// Where a camera sample's numbers come from.
    pub enum SamplerKind {
        /// Owen-scrambled Sobol points for the draws of the first path
        /// vertices, the hashed stream for the rest.
        #[default]
        Sobol = "sobol",
        /// Every number from the hashed stream (independent samples).
        Random = "random",
    }
}

/// Path vertices (free flights, counted from the camera's) whose draws
/// come from Sobol points; later ones use the hashed stream.
pub const SOBOL_VERTICES: u32 = 6;

/// A vertex's light samples whose numbers come from Sobol points (a
/// vertex samples one light, or every light, or two where a disc needs it).
pub const STRATIFIED_LIGHT_SAMPLES: u32 = 2;

/// What a number is drawn for: its place in the allocation of the
/// module documentation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Draw {
    PixelJitter,
    FreeFlight,
    /// The direction of a vertex's `k`-th light sample (counted from 0
    /// in the order the vertex samples its lights)...
    LightDirection(u32),
    /// ...and the first optical depth of its shadow ray. Samples past
    /// [`STRATIFIED_LIGHT_SAMPLES`] draw from the hashed stream.
    LightShadow(u32),
    Phase,
    Roulette,
    /// The camera sample's shutter time (one per sample, not per vertex).
    Time,
}

impl Draw {
    const PER_VERTEX: u32 = 7;

    /// The point set this draw uses at path vertex `vertex`; `None` past
    /// the vertex budget.
    fn slot(self, vertex: u32) -> Option<u32> {
        let k = match self {
            Self::PixelJitter => return Some(0),
            // After every per-vertex slot, so adding it moved none of them.
            Self::Time => return Some(1 + SOBOL_VERTICES * Self::PER_VERTEX),
            Self::FreeFlight => 0,
            Self::LightDirection(k) if k < STRATIFIED_LIGHT_SAMPLES => 1 + 2 * k,
            Self::LightShadow(k) if k < STRATIFIED_LIGHT_SAMPLES => 2 + 2 * k,
            Self::LightDirection(_) | Self::LightShadow(_) => return None,
            Self::Phase => 5,
            Self::Roulette => 6,
        };
        (vertex < SOBOL_VERTICES).then(|| 1 + vertex * Self::PER_VERTEX + k)
    }
}

/// Keeps the Sobol seeds apart from the `Rng` keys of the same pixel.
const SOBOL_DOMAIN: u64 = 0x5e1b_0150_b01c_0de5;
/// Keeps the random sampler's shutter times apart from its stream.
const TIME_DOMAIN: u64 = 0x7133_5b0e_c0de_d0e5;

/// The numbers of one camera sample: the hashed [`Rng`] and, with the
/// Sobol sampler, the pixel's key and the sample's index into its point
/// sets. Nothing is allocated; the seeds of a draw's point set are hashed
/// when it is drawn.
#[derive(Clone, Debug)]
pub struct SampleStream {
    rng: Rng,
    sobol: Option<SobolKey>,
}

#[derive(Clone, Copy, Debug)]
struct SobolKey {
    /// A hash of (seed, pixel index in the full image).
    pixel: u64,
    /// The sample index: the point taken from each set.
    index: SobolIndex,
}

impl SampleStream {
    /// Sample `sample` of pixel `pixel` (its index in the full image).
    /// With [`SamplerKind::Random`] this is exactly `Rng::new(seed, pixel,
    /// sample)`, drawn in the order the renderer always drew.
    pub fn new(kind: SamplerKind, seed: u64, pixel: u64, sample: u32) -> Self {
        let rng = Rng::new(seed, pixel, u64::from(sample));
        let sobol = match kind {
            SamplerKind::Random => None,
            SamplerKind::Sobol => Some(SobolKey {
                pixel: mix64(mix64(seed ^ SOBOL_DOMAIN) ^ pixel.wrapping_mul(GOLDEN)),
                index: SobolIndex::new(sample),
            }),
        };
        Self { rng, sobol }
    }

    /// A stream that draws everything from `rng`.
    pub fn random(rng: Rng) -> Self {
        Self { rng, sobol: None }
    }

    /// The hashed stream, for draws outside the allocation.
    #[inline]
    pub fn rng(&mut self) -> &mut Rng {
        &mut self.rng
    }

    pub fn into_rng(self) -> Rng {
        self.rng
    }

    /// The point set and index of `draw` at `vertex`, if it is a Sobol
    /// draw. Its three seeds come from one 64-bit hash: its low and high
    /// halves, and the high half of its product with an odd constant, which
    /// depends on every bit of it.
    #[inline]
    fn points(&self, draw: Draw, vertex: u32) -> Option<(OwenSobol, SobolIndex)> {
        let key = self.sobol?;
        let slot = draw.slot(vertex)?;
        let h = mix64(key.pixel ^ u64::from(slot + 1).wrapping_mul(GOLDEN));
        let set = OwenSobol {
            shuffle: h as u32,
            scramble: [(h >> 32) as u32, (h.wrapping_mul(GOLDEN) >> 32) as u32],
        };
        Some((set, key.index))
    }

    /// One number in `[0, 1)` for `draw` at path vertex `vertex`.
    #[inline]
    pub fn get_1d(&mut self, draw: Draw, vertex: u32) -> f32 {
        match self.points(draw, vertex) {
            Some((set, i)) => set.get_1d(i),
            None => self.rng.uniform(),
        }
    }

    /// Two numbers in `[0, 1)` for `draw` at path vertex `vertex`.
    #[inline]
    pub fn get_2d(&mut self, draw: Draw, vertex: u32) -> (f32, f32) {
        match self.points(draw, vertex) {
            Some((set, i)) => set.get_2d(i),
            None => {
                let u = self.rng.uniform();
                (u, self.rng.uniform())
            }
        }
    }

    /// The camera sample's shutter-time number in `[0, 1)`: the Sobol
    /// point of [`Draw::Time`], or (random sampler) a hash of the stream's
    /// key. Never advances the hashed stream, so drawing it changes no
    /// other number of the sample.
    #[inline]
    pub fn time(&self) -> f32 {
        match self.points(Draw::Time, 0) {
            Some((set, i)) => set.get_1d(i),
            None => {
                let h = mix64(self.rng.key ^ TIME_DOMAIN);
                (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
            }
        }
    }

    /// Runs `f` (a tracker) on the hashed stream with `draw`'s number
    /// queued as the first it draws, so only that first draw (the walk's
    /// first optical depth) is stratified. A number `f` left undrawn is
    /// dropped, never passed on.
    #[inline]
    pub fn leading<T>(&mut self, draw: Draw, vertex: u32, f: impl FnOnce(&mut Rng) -> T) -> T {
        if let Some((set, i)) = self.points(draw, vertex) {
            self.rng.queue(set.get_1d(i));
        }
        let out = f(&mut self.rng);
        self.rng.clear_queue();
        out
    }
}

/// An optical depth with density `exp(-tau)`: `-ln(1 - u)`, finite for
/// `u` in `[0, 1)`.
#[inline]
pub fn sample_exponential(u: f32) -> f32 {
    -(1.0 - u).ln()
}

/// Uniform direction on the unit sphere; pdf `1 / (4 pi)`.
#[inline]
pub fn uniform_sphere(u1: f32, u2: f32) -> Vec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u2;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Uniform direction in the cone of half-angle `alpha` around `axis`, given
/// `one_minus_cos = 1 - cos(alpha)` (passed instead of `cos(alpha)` because
/// for the sun's 0.27 degrees `1 - cos` loses half its digits in f32).
#[inline]
pub fn uniform_cone(axis: Vec3, one_minus_cos: f32, u1: f32, u2: f32) -> Vec3 {
    let omc = u1 * one_minus_cos; // 1 - cos(theta), uniform in [0, 1 - cos(alpha)]
    let cos_theta = 1.0 - omc;
    let sin_theta = (omc * (2.0 - omc)).max(0.0).sqrt();
    let phi = 2.0 * PI * u2;
    from_local(
        axis,
        sin_theta * phi.cos(),
        sin_theta * phi.sin(),
        cos_theta,
    )
}

/// The direction with coordinates `(x, y, z)` in an orthonormal frame whose z
/// axis is `axis` (frame from Duff et al. 2017, via glam).
#[inline]
pub fn from_local(axis: Vec3, x: f32, y: f32, z: f32) -> Vec3 {
    let (s, t) = axis.any_orthonormal_pair();
    (x * s + y * t + z * axis).normalize()
}

/// Veach's power heuristic (beta = 2) for two strategies with one sample
/// each: the weight of the strategy with pdf `a`.
#[inline]
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2.is_infinite() {
        return 1.0;
    }
    if a2 + b2 > 0.0 {
        a2 / (a2 + b2)
    } else {
        0.0
    }
}
