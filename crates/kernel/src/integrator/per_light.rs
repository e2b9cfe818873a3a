//! A vertex's light pick as plain values: one number per light, in a
//! fixed array, and the defensive shares the pick's weights are made
//! into (`light_choice.rs` decides what the weights are).

use glam::Vec4;

/// A pick probability is at least this (among two lights; among `n`, at
/// least `min(MIN_PROBABILITY, 1 / 2n)`).
pub const MIN_PROBABILITY: f32 = 0.05;

/// The most lights a vertex picks among; a scene with more samples every
/// light ([`LightSampling::resolve`](super::LightSampling::resolve)).
///
/// The pick is computed at every vertex and carried to the next one for
/// the escaped ray's weight, so its probabilities are a plain array on the
/// stack: a growable one (with its spill checks and drops) cost the thick
/// benchmark cloud a sixth of its render time. Past it a light tree picks
/// (`many_lights.rs`), which does not weigh each light at every vertex.
pub const MAX_PICKED_LIGHTS: usize = 8;

/// One value per light, in the order of [`Lights`](crate::Lights) (at most
/// [`MAX_PICKED_LIGHTS`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PerLight {
    values: [f32; MAX_PICKED_LIGHTS],
    len: usize,
}

impl PerLight {
    /// The values as two four-lane vectors, the lanes past the lights'
    /// zero.
    #[inline]
    pub fn lanes(&self) -> Lanes {
        [
            Vec4::from_slice(&self.values[..4]),
            Vec4::from_slice(&self.values[4..]),
        ]
    }

    /// The values of `lanes` for `n` lights.
    #[inline]
    pub fn from_lanes(lanes: Lanes, n: usize) -> Self {
        let mut p = Self::zeros(n);
        lanes[0].write_to_slice(&mut p.values[..4]);
        lanes[1].write_to_slice(&mut p.values[4..]);
        p
    }

    /// `n` zeros (`n` at most [`MAX_PICKED_LIGHTS`]).
    #[inline]
    pub fn zeros(n: usize) -> Self {
        debug_assert!(n <= MAX_PICKED_LIGHTS);
        Self {
            values: [0.0; MAX_PICKED_LIGHTS],
            len: n.min(MAX_PICKED_LIGHTS),
        }
    }
}

impl std::ops::Deref for PerLight {
    type Target = [f32];
    #[inline]
    fn deref(&self) -> &[f32] {
        &self.values[..self.len]
    }
}

impl std::ops::DerefMut for PerLight {
    #[inline]
    fn deref_mut(&mut self) -> &mut [f32] {
        &mut self.values[..self.len]
    }
}

/// Turns weights into their shares of the sum, every share at least the
/// defensive floor `min(MIN_PROBABILITY, 1 / (2 n))` (those above it
/// scaled down to make room), so that no light is starved where the
/// weights are wrong; equal shares where the weights sum to nothing or
/// overflow.
#[inline]
pub(super) fn into_shares(p: &mut PerLight) {
    let (n, w) = (p.len(), p.lanes());
    let total = w[0].element_sum() + w[1].element_sum();
    *p = PerLight::from_lanes(lane_shares(w, total, n, lanes_of(n)), n);
}

/// [`into_shares`]'s rule one weight at a time: the share of one light,
/// for sunward scattering's keep probability, which asks for one light's
/// and would otherwise write a weight into an array only to read it back
/// as lanes (a wait on the store at every call).
#[derive(Clone, Copy, Debug)]
pub(super) struct Shares {
    total: f32,
    floor: f32,
    /// What a share above the floor is multiplied by (exactly 1 where no
    /// share is below it).
    scale: f32,
    /// `Some(1 / n)` where the weights say nothing.
    equal: Option<f32>,
}

impl Shares {
    #[inline]
    pub(super) fn of(weights: impl Iterator<Item = f32> + Clone) -> Self {
        let (n, total) = weights
            .clone()
            .fold((0u32, 0.0f32), |(n, t), w| (n + 1, t + w));
        let floor = defensive_floor(n);
        let mut shares = Self {
            total,
            floor,
            scale: 1.0,
            equal: None,
        };
        if !(total > 0.0 && total.is_finite()) {
            shares.equal = Some(1.0 / n as f32);
            return shares;
        }
        let (mut low, mut high) = (0u32, 0.0f32);
        for w in weights {
            let p = w / total;
            if p < floor {
                low += 1;
            } else {
                high += p;
            }
        }
        if low > 0 {
            shares.scale = (1.0 - floor * low as f32) / high;
        }
        shares
    }

    /// The share of weight `w`, one of those the shares were made of.
    #[inline]
    pub(super) fn share(self, w: f32) -> f32 {
        if let Some(equal) = self.equal {
            return equal;
        }
        let p = w / self.total;
        if p < self.floor {
            self.floor
        } else if self.scale == 1.0 {
            p
        } else {
            p * self.scale
        }
    }
}

/// [`Shares::of`]`([w, other])`'s share of `w`, bit for bit, for the
/// commonest scene (a sun and a sky): where the general rule copies the
/// weights and walks them twice, two lights need one division each.
/// Their sum is the same in either order, and of two shares summing to one
/// at most one is below the floor; if one is, the other alone is scaled.
#[inline]
pub(super) fn share_of_two(w: f32, other: f32) -> f32 {
    let total = w + other;
    let floor = defensive_floor(2);
    if !(total > 0.0 && total.is_finite()) {
        return 0.5;
    }
    let p = w / total;
    if p < floor {
        return floor;
    }
    if other / total >= floor {
        return p;
    }
    let scale = (1.0 - floor) / p;
    if scale == 1.0 {
        p
    } else {
        p * scale
    }
}

/// A [`PerLight`]'s values as two four-lane vectors.
pub(super) type Lanes = [Vec4; 2];

/// [`into_shares`] of weights `w` summing to `total`, for `n` lights whose
/// lanes [`lanes_of`] marks; over the lanes, with no loop over the lights
/// (this runs at every path vertex).
#[inline]
pub(super) fn lane_shares(w: Lanes, total: f32, n: usize, lights: Lanes) -> Lanes {
    if !(total > 0.0 && total.is_finite()) {
        let equal = 1.0 / n as f32;
        return lights.map(|l| l * equal);
    }
    let floor = defensive_floor(n as u32);
    let p = w.map(|w| w / total);
    // The lanes past the lights hold 0 and are never below their floor 0.
    let low = [0, 1].map(|k| p[k].cmplt(lights[k] * floor));
    let count = low[0].bitmask().count_ones() + low[1].bitmask().count_ones();
    if count == 0 {
        return p;
    }
    let high: f32 = (0..2)
        .map(|k| Vec4::select(low[k], Vec4::ZERO, p[k]).element_sum())
        .sum();
    let scale = (1.0 - floor * count as f32) / high;
    [0, 1].map(|k| Vec4::select(low[k], Vec4::splat(floor), p[k] * scale))
}

/// 1 in the lanes of `n` lights, 0 past them.
pub(super) fn lanes_of(n: usize) -> Lanes {
    let mut ones = PerLight::zeros(n.min(MAX_PICKED_LIGHTS));
    ones.iter_mut().for_each(|x| *x = 1.0);
    ones.lanes()
}

/// The least share among `n` lights.
#[inline]
fn defensive_floor(n: u32) -> f32 {
    if n < 2 {
        0.0
    } else {
        MIN_PROBABILITY.min(0.5 / n as f32)
    }
}

/// Raises each probability to its light's disc floor (the others
/// unchanged: where they then sum past one, a vertex sometimes samples
/// two).
#[inline]
pub(super) fn raise_to_floors(p: &mut [f32], floors: &[f32]) {
    for (p, &floor) in p.iter_mut().zip(floors) {
        *p = p.max(floor);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shares(w: &[f32]) -> Vec<f32> {
        let mut p = PerLight::zeros(w.len());
        p.copy_from_slice(w);
        into_shares(&mut p);
        p.to_vec()
    }

    /// The one-weight rule gives what the lanes give.
    #[test]
    fn one_share_is_the_lanes_share() {
        for w in [
            &[1.0f32, 3.0][..],
            &[1e-4, 1.0],
            &[0.0, 2.0, 5.0],
            &[1e-6, 1.0, 2.0, 0.0, 3.0, 1e-3, 4.0, 0.5],
            &[0.0, 0.0],
        ] {
            let all = shares(w);
            let one = Shares::of(w.iter().copied());
            for (i, &p) in all.iter().enumerate() {
                assert!((one.share(w[i]) - p).abs() <= 1e-7, "{w:?}: light {i}");
            }
        }
    }

    /// Two lights' share is the general rule's to the bit, over weights
    /// from zero through the floor's edge to overflow and NaN.
    #[test]
    fn two_lights_share_as_the_general_rule() {
        let mut rng = cirrus_testkit::SplitMix64(5);
        let special = [
            0.0,
            1e-30,
            0.05,
            0.0526315,
            0.95,
            1.0,
            19.0,
            1e30,
            f32::MAX,
            f32::INFINITY,
            f32::NAN,
        ];
        let mut pairs: Vec<(f32, f32)> = special
            .iter()
            .flat_map(|&a| special.iter().map(move |&b| (a, b)))
            .collect();
        for _ in 0..100_000 {
            let scale = 10f32.powi(rng.below(9) as i32 - 4);
            pairs.push((rng.unit() * scale, rng.unit()));
        }
        for (a, b) in pairs {
            for (w, other, i) in [(a, b, 0), (b, a, 1)] {
                let general = Shares::of([a, b].into_iter()).share([a, b][i]);
                let two = share_of_two(w, other);
                assert_eq!(two.to_bits(), general.to_bits(), "{a} {b}: light {i}");
            }
        }
    }

    /// Shares sum to one, follow the weights where every share is above
    /// the floor, and lift every light to the floor otherwise, for any
    /// number of lights; equal where the weights say nothing.
    #[test]
    fn shares_keep_every_light_at_its_floor() {
        let cases: [&[f32]; 7] = [
            &[1.0, 3.0],
            &[1e-4, 1.0],
            &[0.0, 2.0, 5.0],
            &[1.0; MAX_PICKED_LIGHTS],
            &[1e-6, 1.0, 2.0, 0.0, 3.0, 1e-3, 4.0, 0.5],
            &[0.0, 0.0],
            &[f32::INFINITY, 1.0],
        ];
        for w in cases {
            let p = shares(w);
            let n = w.len() as f32;
            let floor = MIN_PROBABILITY.min(0.5 / n);
            assert!((p.iter().sum::<f32>() - 1.0).abs() < 1e-5, "{w:?}: {p:?}");
            assert!(p.iter().all(|&p| p >= floor - 1e-7), "{w:?}: {p:?}");
        }
        assert_eq!(shares(&[1.0, 3.0]), [0.25, 0.75]);
        let p = shares(&[0.0, 2.0, 6.0]);
        assert_eq!(p[0], MIN_PROBABILITY);
        assert!((p[2] / p[1] - 3.0).abs() < 1e-5, "{p:?}");
        assert_eq!(shares(&[0.0, 0.0]), [0.5, 0.5]);
    }
}
