//! One rule for weighing the strategies that can draw the same sample
//! (Veach 1997, multiple importance sampling): each site names the density
//! of the strategy that drew it and of every other a vertex has that
//! could have drawn it (phase sampling; a light's own sampling, its pick
//! probability folded in; sunward scattering; equi-angular sampling
//! against the span's uniform density), and [`Strategies::weight`]
//! combines them by the power heuristic, `p_own^2 / sum p_k^2`.
//!
//! Weights compose where strategies meet at different vertices (the
//! sunward light's estimate is weighed against sunward scattering at the
//! previous vertex and against phase sampling at its own); every product
//! of weights still sums to one over the strategies.

/// The densities at one sample of the strategy that drew it and of the
/// others that could have.
#[derive(Clone, Copy, Debug)]
pub(super) struct Strategies {
    own: f32,
    /// The sum of the others' squared densities.
    others: f32,
}

impl Strategies {
    /// A sample drawn with density `own`.
    #[inline]
    pub fn drawn_with(own: f32) -> Self {
        Self { own, others: 0.0 }
    }

    /// ... which another strategy draws with density `density`.
    #[inline]
    pub fn or(self, density: f32) -> Self {
        Self {
            others: self.others + density * density,
            ..self
        }
    }

    /// The drawing strategy's weight: 1 for an infinite density (a delta
    /// no other strategy can draw), 0 where every density is 0.
    #[inline]
    pub fn weight(self) -> f32 {
        let own2 = self.own * self.own;
        if own2.is_infinite() {
            return 1.0;
        }
        if own2 + self.others > 0.0 {
            own2 / (own2 + self.others)
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::power_heuristic;

    /// Two strategies weigh as the power heuristic, to the bit, and any
    /// number's weights sum to one.
    #[test]
    fn weights_are_the_power_heuristics_and_sum_to_one() {
        let values = [0.0f32, 1e-30, 0.3, 1.0, 7.5, 1e19, f32::INFINITY];
        for &a in &values {
            for &b in &values {
                let w = Strategies::drawn_with(a).or(b).weight();
                assert_eq!(w.to_bits(), power_heuristic(a, b).to_bits(), "{a} {b}");
            }
        }
        let d = [0.2f32, 3.0, 0.7, 1.1];
        let sum: f32 = (0..d.len())
            .map(|k| {
                let others = d.iter().enumerate().filter(|&(j, _)| j != k);
                others
                    .fold(Strategies::drawn_with(d[k]), |s, (_, &x)| s.or(x))
                    .weight()
            })
            .sum();
        assert!((sum - 1.0).abs() < 1e-6, "{sum}");
    }
}
