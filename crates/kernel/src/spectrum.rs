//! [`Spectrum`]: what a transmittance or an extinction is, one type for grey
//! and colour.
//!
//! A grey medium (every channel's extinction the same) is tracked with one
//! scalar: `f32`. A chromatic one (extinction per RGB channel, see
//! [`Medium`](crate::Medium)) with three: `Vec3`. The trackers, the path
//! tracer and the marchers are written once, generic over this trait, and
//! the instance is chosen once per camera sample from
//! [`Media::chromatic`]; so grey media run exactly the scalar code they
//! always ran (same operations, same order, bit-identical images) and pay
//! nothing for the colour case.
//!
//! The path throughput `beta` is always a `Vec3` (a coloured albedo tints
//! it even in a grey medium); what is per-type is how extinction is looked
//! up, how a transmittance is weighted and rouletted, and how a tentative
//! collision of a free flight is decided ([`Spectrum::collide`]).

use glam::Vec3;

use crate::counters::Counters;
use crate::medium::MajorantSegment;
use crate::sampling::Rng;
use crate::tracking::roulette::{ROULETTE_Q, ROULETTE_THRESHOLD};

/// What a free flight's tentative collision turned out to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Collision {
    Real,
    Null,
    /// The path's throughput is zero or NaN: nothing left to weight.
    Dead,
}

/// Extinction and transmittance of one channel (`f32`) or three (`Vec3`).
pub trait Spectrum: Copy + Send + Sync + std::fmt::Debug + 'static {
    const ZERO: Self;
    const ONE: Self;
    /// Whether channels are tracked apart (`Vec3`).
    const CHROMATIC: bool;

    /// The channels of a medium whose extinction is `tint` times `sigma`,
    /// `sigma` being its largest channel: the scalar itself for `f32`
    /// (what a grey tracker or the light grid looks up), the channels for
    /// `Vec3`.
    fn tinted(sigma: f32, tint: Vec3) -> Self;
    /// The same value in every channel.
    fn splat(x: f32) -> Self;
    /// As an RGB colour (a scalar applies to every channel).
    fn rgb(self) -> Vec3;
    /// `self` times a colour, per channel.
    fn tint(self, v: Vec3) -> Vec3;
    /// Whether any channel is positive (false for NaN).
    fn any_positive(self) -> bool;
    fn max_channel(self) -> f32;
    /// The smallest channel (a march stops once every channel is opaque).
    fn min_channel(self) -> f32;
    /// The channels' mean.
    fn mean(self) -> f32;
    fn scale(self, h: f32) -> Self;
    fn add(self, other: Self) -> Self;
    fn mul(self, other: Self) -> Self;
    fn one_minus(self) -> Self;
    /// `exp(-self)` per channel.
    fn exp_neg(self) -> Self;

    /// A looked-up extinction made safe for ratio weights: clamped to
    /// `[0, majorant]` per channel where channels are tracked apart (the
    /// probabilities of spectral tracking need it), unchanged for a scalar,
    /// whose weight is clamped at 0 instead ([`Spectrum::null_fraction`]).
    fn clamp_to_majorant(self, majorant: f32) -> Self;
    /// Ratio tracking's weight at a tentative collision (Novak, Selle,
    /// Jarosz 2014, eq. 6): `1 - sigma_t / sigma_maj`, at least 0 (pbrt-v4
    /// clamps `sigma_n` the same way).
    fn null_fraction(sigma: Self, majorant: f32) -> Self;
    /// pbrt-v4's Russian roulette on a transmittance estimate: below
    /// [`ROULETTE_THRESHOLD`] (its largest channel) it becomes 0 with
    /// probability [`ROULETTE_Q`] and is divided by `1 - q` otherwise, so
    /// its expectation is unchanged. Returns false when the estimate is
    /// (now) zero and the walk can stop.
    fn roulette(&mut self, rng: &mut Rng) -> bool;

    /// Decides a free flight's tentative collision at `t` inside `segment`
    /// and weights `beta` for it (see `tracking::delta`).
    /// `extinction` looks the medium up there (and counts it), called at
    /// most once and only where the decision needs it.
    fn collide(
        segment: &MajorantSegment,
        beta: &mut Vec3,
        rng: &mut Rng,
        c: &mut Counters,
        extinction: impl FnOnce(&mut Counters) -> Self,
    ) -> Collision;
    /// Alpha (`1 - T`) of a camera ray whose first free flight escaped
    /// with throughput `beta`: 0 for a scalar flight (its escape indicator
    /// is the track-length estimate of `T`), the channels' mean `1 - T`
    /// from the null-collision weights otherwise.
    fn escaped_alpha(beta: Vec3) -> f32;
}

/// Luminance (Rec. 709): how a colour is weighed where one number stands
/// for it (the light choice's estimates).
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl Spectrum for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const CHROMATIC: bool = false;

    #[inline]
    fn tinted(sigma: f32, _tint: Vec3) -> Self {
        sigma
    }
    #[inline]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline]
    fn rgb(self) -> Vec3 {
        Vec3::splat(self)
    }
    #[inline]
    fn tint(self, v: Vec3) -> Vec3 {
        self * v
    }
    #[inline]
    fn any_positive(self) -> bool {
        self > 0.0
    }
    #[inline]
    fn max_channel(self) -> f32 {
        self
    }
    #[inline]
    fn min_channel(self) -> f32 {
        self
    }
    #[inline]
    fn mean(self) -> f32 {
        self
    }
    #[inline]
    fn scale(self, h: f32) -> Self {
        self * h
    }
    #[inline]
    fn add(self, other: Self) -> Self {
        self + other
    }
    #[inline]
    fn mul(self, other: Self) -> Self {
        self * other
    }
    #[inline]
    fn one_minus(self) -> Self {
        1.0 - self
    }
    #[inline]
    fn exp_neg(self) -> Self {
        (-self).exp()
    }
    #[inline]
    fn clamp_to_majorant(self, _majorant: f32) -> Self {
        self
    }
    #[inline]
    fn null_fraction(sigma: Self, majorant: f32) -> Self {
        (1.0 - sigma / majorant).max(0.0)
    }
    #[inline]
    fn roulette(&mut self, rng: &mut Rng) -> bool {
        if *self <= 0.0 {
            *self = 0.0;
            return false;
        }
        if *self < ROULETTE_THRESHOLD {
            if rng.uniform() < ROULETTE_Q {
                *self = 0.0;
                return false;
            }
            *self /= 1.0 - ROULETTE_Q;
        }
        true
    }

    /// Delta tracking (Woodcock et al. 1965): real with probability
    /// `sigma_t / sigma_maj`, `beta` untouched (pbrt-v4 `SampleT_maj` with
    /// absorption and scattering merged, since the path integrator weights
    /// by albedo). When `xi * sigma_maj` falls below the segment's minorant
    /// the collision is real whatever the density, so it is accepted
    /// without a lookup: the same decision with the same random number,
    /// only cheaper (the control part of decomposition tracking, Kutz et
    /// al. 2017).
    #[inline]
    fn collide(
        segment: &MajorantSegment,
        _beta: &mut Vec3,
        rng: &mut Rng,
        c: &mut Counters,
        extinction: impl FnOnce(&mut Counters) -> Self,
    ) -> Collision {
        let xi = rng.uniform() * segment.majorant;
        if xi < segment.minorant || xi < extinction(c) {
            Collision::Real
        } else {
            Collision::Null
        }
    }

    #[inline]
    fn escaped_alpha(_beta: Vec3) -> f32 {
        0.0
    }
}

impl Spectrum for Vec3 {
    const ZERO: Self = Vec3::ZERO;
    const ONE: Self = Vec3::ONE;
    const CHROMATIC: bool = true;

    #[inline]
    fn tinted(sigma: f32, tint: Vec3) -> Self {
        tint * sigma
    }
    #[inline]
    fn splat(x: f32) -> Self {
        Vec3::splat(x)
    }
    #[inline]
    fn rgb(self) -> Vec3 {
        self
    }
    #[inline]
    fn tint(self, v: Vec3) -> Vec3 {
        self * v
    }
    #[inline]
    fn any_positive(self) -> bool {
        self.max_element() > 0.0
    }
    #[inline]
    fn max_channel(self) -> f32 {
        self.max_element()
    }
    #[inline]
    fn min_channel(self) -> f32 {
        self.min_element()
    }
    #[inline]
    fn mean(self) -> f32 {
        self.element_sum() / 3.0
    }
    #[inline]
    fn scale(self, h: f32) -> Self {
        self * h
    }
    #[inline]
    fn add(self, other: Self) -> Self {
        self + other
    }
    #[inline]
    fn mul(self, other: Self) -> Self {
        self * other
    }
    #[inline]
    fn one_minus(self) -> Self {
        Vec3::ONE - self
    }
    #[inline]
    fn exp_neg(self) -> Self {
        Vec3::new((-self.x).exp(), (-self.y).exp(), (-self.z).exp())
    }
    #[inline]
    fn clamp_to_majorant(self, majorant: f32) -> Self {
        self.min(Vec3::splat(majorant)).max(Vec3::ZERO)
    }
    /// Every factor lies in `[0, 1]`: the extinction was clamped to the
    /// majorant, which bounds every channel.
    #[inline]
    fn null_fraction(sigma: Self, majorant: f32) -> Self {
        Vec3::ONE - sigma / majorant
    }
    /// On the largest channel: the whole estimate lives or dies together,
    /// so every channel's expectation is unchanged.
    #[inline]
    fn roulette(&mut self, rng: &mut Rng) -> bool {
        let m = self.max_element();
        if m.is_nan() || m <= 0.0 {
            *self = Vec3::ZERO;
            return false;
        }
        if m < ROULETTE_THRESHOLD {
            if rng.uniform() < ROULETTE_Q {
                *self = Vec3::ZERO;
                return false;
            }
            *self /= 1.0 - ROULETTE_Q;
        }
        true
    }

    /// Spectral tracking (Kutz, Habel, Li, Novak 2017, section 4, with the
    /// history-aware probabilities of its eq. 16): real with probability
    /// `P_r = avg(beta sigma_t) / (sigma_maj avg(beta))`, `beta` multiplied
    /// by `sigma_t / (sigma_maj P_r)` at a real collision and by
    /// `sigma_n / (sigma_maj P_n)` at a null one. Every channel's estimate
    /// is unbiased whatever the probabilities, as long as they are positive
    /// wherever the channel's coefficient is; the averages over
    /// `beta`-weighted coefficients keep the weights bounded (each factor is
    /// at most 3 / the channel's share of `avg(beta)`). The role is that of
    /// pbrt-v4's hero-wavelength spectral MIS (Miller et al. 2019); with
    /// fixed RGB channels the probabilities can use all three at once.
    /// With equal channels it is delta tracking: `P_r = sigma_t /
    /// sigma_maj` and the weights are 1.
    #[inline]
    fn collide(
        segment: &MajorantSegment,
        beta: &mut Vec3,
        rng: &mut Rng,
        c: &mut Counters,
        extinction: impl FnOnce(&mut Counters) -> Self,
    ) -> Collision {
        let maj = segment.majorant;
        let sigma = extinction(c);
        let mean_beta = beta.element_sum();
        if mean_beta.is_nan() || mean_beta <= 0.0 {
            *beta = Vec3::ZERO;
            return Collision::Dead;
        }
        // Sums rather than averages: the factor 3 cancels.
        let p_real = ((*beta * sigma).element_sum() / (maj * mean_beta)).clamp(0.0, 1.0);
        if rng.uniform() < p_real {
            *beta *= sigma / (maj * p_real);
            return Collision::Real;
        }
        *beta *= (Vec3::splat(maj) - sigma) / (maj * (1.0 - p_real));
        Collision::Null
    }

    #[inline]
    fn escaped_alpha(beta: Vec3) -> f32 {
        1.0 - beta.element_sum() / 3.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both instances' roulettes keep the estimate's mean and only ever
    /// touch estimates below the threshold.
    #[test]
    fn roulette_keeps_the_mean_of_both_instances() {
        let mut rng = Rng::new(3, 0, 0);
        let n = 200_000;
        let (mut grey, mut rgb) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let mut g = 0.02f32;
            let mut c = Vec3::new(0.02, 0.01, 0.0);
            g.roulette(&mut rng);
            c.roulette(&mut rng);
            grey += f64::from(g);
            rgb += f64::from(c.x);
        }
        // Survivors are 0.08 with probability 0.25: a standard deviation
        // of 0.0346 per draw, 7.7e-5 for the mean of 200,000.
        for mean in [grey / n as f64, rgb / n as f64] {
            assert!((mean - 0.02).abs() < 5.0 * 7.8e-5, "{mean}");
        }
        let mut big = 0.5f32;
        assert!(big.roulette(&mut rng) && big == 0.5);
        let mut dead = Vec3::splat(f32::NAN);
        assert!(!dead.roulette(&mut rng) && dead == Vec3::ZERO);
    }

    #[test]
    fn null_fractions_are_clamped_weights() {
        assert_eq!(f32::null_fraction(3.0, 2.0), 0.0);
        assert_eq!(f32::null_fraction(0.5, 2.0), 0.75);
        let s = Vec3::new(3.0, -1.0, 1.0).clamp_to_majorant(2.0);
        assert_eq!(Vec3::null_fraction(s, 2.0), Vec3::new(0.0, 1.0, 0.5));
    }
}
