//! Guided free flights: delta tracking whose tentative collisions are made
//! real or null with probabilities set by an estimate of what each choice
//! brings, and weighted so that the flight estimates what the analog one
//! does.
//!
//! In the null-collision form of the radiative transfer equation (Galtier
//! et al. 2013; Kutz et al. 2017, "weighted delta tracking"; Novák et al.
//! 2018), a tentative collision drawn at the majorant's rate is real with
//! density share `P_r = sigma_t / sigma_maj` and null with `1 - P_r`. Any
//! probability `P` of calling it real is unbiased if the real branch is
//! weighted `P_r / P` and the null branch `(1 - P_r) / (1 - P)`. The
//! zero-variance choice (Herholz et al. 2019, section 5: collisions in
//! proportion to transmittance times the in-scattered radiance) weighs
//! the two branches by what they bring back:
//!
//! `P* = sigma_t L_s / (sigma_t L_s + sigma_n L_b)`,
//!
//! `L_s` the radiance the collision scatters back along the ray, `L_b` the
//! radiance arriving along the ray from beyond it, which a null collision
//! goes on to gather. The caller supplies `w = L_s / L_b` per point. An
//! estimate of `w` can be far off, so the flight takes the defensive mix
//! `P = (P_r + P*) / 2`: both branch weights then stay at most 2.

use glam::Vec3;

use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::Rng;
use crate::spectrum::lookup;
use crate::stats::Counters;

use super::walk::{Event, Walk};
use super::FreeFlight;

/// A grey free flight along `ray` within `[0, t_max]` whose tentative
/// collisions are decided by `worth(p)`, the estimated ratio of what a
/// real collision at `p` brings to what a null one does (`None` where
/// there is no estimate: there the decision is delta tracking's own).
/// `beta` takes the branch weights: on escape its expectation is the
/// transmittance, at a collision it is weighted as delta tracking's
/// collision density over the flight's.
pub fn sample_guided_free_flight<M: Media>(
    medium: &M,
    ray: &Ray,
    t_max: f32,
    beta: &mut Vec3,
    rng: &mut Rng,
    c: &mut Counters,
    mut worth: impl FnMut(Vec3) -> Option<f32>,
) -> FreeFlight {
    let segments = medium.majorants(ray.origin, ray.dir, 0.0, t_max);
    let mut walk = Walk::new(segments, false, rng);
    loop {
        match walk.next(rng, c) {
            Event::Enter(_) => {}
            Event::End => return FreeFlight::Escaped,
            Event::Capped => return FreeFlight::Capped,
            Event::Collision { t, segment, .. } => {
                let sigma = lookup::<f32, M>(medium, ray, t, segment.majorant, c);
                let real = sigma / segment.majorant;
                let p = match worth(ray.at(t)) {
                    Some(w) => {
                        c.guided_collisions += 1;
                        real_probability(real, w)
                    }
                    None => real,
                };
                if rng.uniform() < p {
                    c.real_collisions += 1;
                    *beta *= real / p;
                    return FreeFlight::Collision { t };
                }
                c.null_collisions += 1;
                *beta *= (1.0 - real) / (1.0 - p);
            }
        }
    }
}

/// The probability of calling a tentative collision real: the defensive
/// half-and-half mix of delta tracking's `real` (`sigma_t / sigma_maj`)
/// and the zero-variance share for a real-to-null worth ratio `worth`.
/// It is 0 exactly when `real` is 0 and 1 exactly when `real` is 1, so
/// neither branch weight divides by zero.
#[inline]
pub(crate) fn real_probability(real: f32, worth: f32) -> f32 {
    let scattered = real * worth;
    let total = scattered + (1.0 - real);
    let zero_variance = if total > 0.0 && total.is_finite() {
        scattered / total
    } else {
        real
    };
    0.5 * (real + zero_variance)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mix keeps both branch weights in (0, 2] for every share and
    /// worth, and reduces to delta tracking for a worth of 1.
    #[test]
    fn branch_weights_stay_bounded() {
        for &real in &[0.0f32, 1e-6, 0.01, 0.3, 0.5, 0.9, 0.999_99, 1.0] {
            for &worth in &[0.0f32, 1e-9, 0.01, 0.5, 1.0, 2.0, 100.0, 1e9, f32::INFINITY] {
                let p = real_probability(real, worth);
                assert!((0.0..=1.0).contains(&p), "p {p} for {real}, {worth}");
                if real > 0.0 {
                    let w = real / p;
                    assert!(
                        w > 0.0 && w <= 2.0 + 1e-5,
                        "real weight {w} at {real}, {worth}"
                    );
                } else {
                    assert_eq!(p, 0.0);
                }
                if real < 1.0 {
                    let w = (1.0 - real) / (1.0 - p);
                    assert!(
                        w > 0.0 && w <= 2.0 + 1e-5,
                        "null weight {w} at {real}, {worth}"
                    );
                } else {
                    assert_eq!(p, 1.0);
                }
            }
            assert!((real_probability(real, 1.0) - real).abs() < 1e-6);
        }
    }

    /// A higher worth makes collisions likelier to be real.
    #[test]
    fn worth_orders_the_probability() {
        let real = 0.4;
        let ps: Vec<f32> = [0.01, 0.1, 1.0, 10.0, 100.0]
            .iter()
            .map(|&w| real_probability(real, w))
            .collect();
        assert!(ps.windows(2).all(|w| w[0] < w[1]), "{ps:?}");
        assert!(ps[0] > 0.2 && ps[4] < 0.7 + 1e-3, "{ps:?}");
    }
}
