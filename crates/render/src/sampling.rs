//! Random numbers and the sampling routines built on them.
//!
//! The generator is counter-based: the `n`-th number of a stream is a hash
//! of `(seed, stream, sample, n)`, with no state shared between pixels. A
//! pixel's samples therefore do not depend on which thread renders them or in
//! what order, which is what makes images bit-identical across thread counts.

use std::f32::consts::PI;

use glam::Vec3;

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
#[derive(Clone, Debug)]
pub struct Rng {
    key: u64,
    counter: u64,
}

impl Rng {
    /// `stream` is typically a pixel index and `sample` the sample index.
    pub fn new(seed: u64, stream: u64, sample: u64) -> Self {
        let mut h = mix64(seed.wrapping_add(GOLDEN));
        h = mix64(h ^ stream.wrapping_mul(0xd6e8_feb8_6659_fd93));
        h = mix64(h ^ sample.wrapping_mul(0xa076_1d64_78bd_642f));
        Self { key: h, counter: 0 }
    }

    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.counter = self.counter.wrapping_add(1);
        mix64(self.key.wrapping_add(self.counter.wrapping_mul(GOLDEN)))
    }

    /// Uniform in `[0, 1)`: the top 24 bits, so every value is exact in f32
    /// and 1.0 is never returned.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    /// How many numbers this stream has produced (its dimension).
    pub fn dimension(&self) -> u64 {
        self.counter
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
