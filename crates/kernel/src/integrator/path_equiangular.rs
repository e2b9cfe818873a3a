//! Equi-angular sampling (Kulla and Fajardo 2012): a second strategy for
//! the light a path segment scatters toward the camera from sphere, point
//! and spot lights, beside the free flight's collision.
//!
//! Along a segment `o + t w`, the light of light `k` scattered once more is
//! `integral T(0, t) sigma_s(t) N_k(t) dt`, `N_k` the next-event estimate
//! at the point. Delta tracking estimates it at its collision (density
//! `sigma_t T`), which in thin media falls anywhere but near a light, where
//! `N_k` grows as `1 / d^2`: a beam in fog converges slowly and a point
//! light inside a cloud has no finite variance. Equi-angular sampling
//! draws `t` in the media's span of the segment with density
//! `h / ((theta_b - theta_a) (h^2 + (t - delta)^2))` toward the light's
//! centre, which cancels the `1 / d^2`, and estimates `T(0, t)` by the
//! render's transmittance estimator (ratio tracking: unbiased in any
//! heterogeneous medium, as in Kutz et al. 2017's decomposition of
//! null-collision estimators) and `sigma_s` by a lookup.
//!
//! The two strategies' weights are any pair summing to one at each `t`
//! (Veach 1997's multi-sample model), so each must be a deterministic
//! function of the segment and `t` that both sites compute alike. They
//! take the power heuristic of the equi-angular density against the free
//! flight's collision density, `sigma_t(t) T(0, t)` ([`collision_density`]).
//! That density needs `T(0, t)`, which in a heterogeneous medium the
//! trackers only estimate (ratio tracking's estimate is random, and a
//! random density in the power heuristic, drawn independently at the two
//! sites, would no longer make the weights sum to one at each `t`: the
//! estimate would be biased). So the weights take the transmittance between
//! its two deterministic bounds, the majorant segments' `exp(-integral
//! majorant)` and `exp(-integral minorant)`: their geometric mean, which
//! is the exact transmittance in a homogeneous medium (minorant =
//! majorant) and within those bounds elsewhere. Both strategies stay exact
//! for any weights; these only decide the noise.
//!
//! One light per segment takes the equi-angular sample, picked in
//! proportion to its unoccluded single scattering along the span,
//! `I (theta_b - theta_a) / h` ([`PointPick`]): among a few lights, each
//! weighed so; among many, by a light tree weighing its nodes by the same
//! integral along the segment (Cycles' light tree for volume segments).

use glam::Vec3;

use super::light_choice::LightChoice;
use super::light_tree::LightTree;
use super::mis::Strategies;
use super::path::PathTracer;
use super::path_state::{Arrival, Path, Vertex};
use super::per_light::MAX_PICKED_LIGHTS;
use super::LightSampling;
use crate::counters::Counters;
use crate::light::{LightBounds, Lights};
use crate::medium::Media;
use crate::ray::Ray;
use crate::sampling::SampleStream;
use crate::spectrum::Spectrum;
use crate::tracking::transmittance;

/// The light sample rank the equi-angular point's next-event estimate
/// draws (past the stratified ranks a vertex's own samples use).
const EQUIANGULAR_LIGHT_SAMPLE: u32 = 2;

/// Equi-angular sampling of distance along a ray toward a point, over a
/// span of the ray.
#[derive(Clone, Copy, Debug)]
pub(super) struct EquiAngular {
    /// Distance along the ray to the point's foot.
    delta: f32,
    /// The point's distance from the ray.
    h: f32,
    theta_a: f32,
    theta_b: f32,
}

impl EquiAngular {
    /// Toward `c` along `ray` over `[t0, t1]`; `None` for an empty span or
    /// a ray through `c` (its density would be a delta).
    #[inline]
    pub fn new(ray: &Ray, c: Vec3, t0: f32, t1: f32) -> Option<Self> {
        let to_c = c - ray.origin;
        let delta = to_c.dot(ray.dir);
        let h = (to_c - delta * ray.dir).length();
        let scale = to_c.length().max(t1 - t0);
        // Written so that NaN fails too.
        let usable = t1 > t0 && h > 1e-5 * scale && h.is_finite();
        if !usable {
            return None;
        }
        let theta_a = ((t0 - delta) / h).atan();
        let theta_b = ((t1 - delta) / h).atan();
        (theta_b > theta_a).then_some(Self {
            delta,
            h,
            theta_a,
            theta_b,
        })
    }

    /// A distance drawn with `u`, and its density.
    #[inline]
    pub fn sample(&self, u: f32) -> (f32, f32) {
        let theta = self.theta_a + u * (self.theta_b - self.theta_a);
        let t = self.delta + self.h * theta.tan();
        (t, self.pdf(t))
    }

    /// The density of drawing `t`.
    #[inline]
    pub fn pdf(&self, t: f32) -> f32 {
        let x = t - self.delta;
        self.h / ((self.theta_b - self.theta_a) * (self.h * self.h + x * x))
    }

    /// `integral dt / d^2` over the span: the unoccluded single scattering
    /// of a unit point light, up to its phase and medium.
    #[inline]
    fn reach(&self) -> f32 {
        (self.theta_b - self.theta_a) / self.h
    }
}

/// The equi-angular strategy's weight at `t`, drawn with density `pdf`,
/// against the free flight's collision density `flight` there (see the
/// module documentation).
#[inline]
fn weight(pdf: f32, flight: f32) -> f32 {
    Strategies::drawn_with(pdf).or(flight).weight()
}

/// The free flight's collision density at `t` along `ray`, as the MIS
/// weights take it: `sigma_t(t)` times the geometric mean of the majorant
/// segments' bounds on `T(0, t)` (exact in a homogeneous medium; see the
/// module documentation). Deterministic: the equi-angular sample and the
/// collision's next-event estimate compute the same number.
#[inline]
pub(super) fn collision_density<M: Media>(medium: &M, ray: &Ray, t: f32) -> f32 {
    let sigma: f32 = medium.extinction(ray.at(t), ray.time);
    if sigma.is_nan() || sigma <= 0.0 {
        return 0.0;
    }
    let (mut least, mut most) = (0.0f32, 0.0f32);
    for s in medium.majorants(ray.origin, ray.dir, 0.0, t) {
        let len = (s.t1.min(t) - s.t0.max(0.0)).max(0.0);
        least += s.minorant * len;
        most += s.majorant * len;
    }
    let density = sigma * (-0.5 * (least + most)).exp();
    if density.is_finite() {
        density
    } else {
        0.0
    }
}

/// A segment's span in the media, `[t0, t1]`, within `t_max`.
#[inline]
fn span<M: Media>(medium: &M, ray: &Ray) -> Option<(f32, f32)> {
    let (t0, t1) = medium
        .bounds()
        .clip_ray(ray.origin, ray.dir, 0.0, ray.t_max)?;
    (t1 > t0 && t1.is_finite()).then_some((t0, t1))
}

/// How a segment picks the point-like light its equi-angular sample aims
/// at.
#[derive(Clone, Debug)]
pub(crate) enum PointPick {
    /// Among a few: each light's centre and intensity luminance, weighed
    /// by its reach along the segment.
    Few(Vec<(usize, Vec3, f32)>),
    /// Among many: a light tree over them.
    Many(LightTree),
    /// Uniformly (the baseline the others are measured against): the
    /// lights' indices.
    Uniform(Vec<usize>),
}

impl PointPick {
    /// The pick among the lights of `lights` at the indices `points`
    /// (`uniform`: each alike).
    pub fn new(lights: &Lights, points: &[usize], uniform: bool) -> Self {
        if uniform {
            return Self::Uniform(points.to_vec());
        }
        if points.len() > MAX_PICKED_LIGHTS {
            if let Some(tree) = LightTree::new(lights, points) {
                return Self::Many(tree);
            }
        }
        Self::Few(
            points
                .iter()
                .filter_map(|&i| {
                    let light = lights.get(i);
                    Some((i, light.point_centre()?, light.luminance()))
                })
                .collect(),
        )
    }

    /// The light `u` picks for `ray`'s span `[t0, t1]`: its index, its
    /// sampler and its probability.
    #[inline]
    fn pick(
        &self,
        lights: &Lights,
        ray: &Ray,
        t0: f32,
        t1: f32,
        u: f32,
    ) -> Option<(usize, EquiAngular, f32)> {
        match self {
            Self::Few(points) => {
                // Two passes: the sum, then the pick, recomputing each
                // light's sampler.
                let reach = |&(i, c, l): &(usize, Vec3, f32)| {
                    let ea = EquiAngular::new(ray, c, t0, t1)?;
                    let w = l * ea.reach();
                    (w > 0.0 && w.is_finite()).then_some((i, ea, w))
                };
                let total: f32 = points.iter().filter_map(reach).map(|r| r.2).sum();
                if !(total > 0.0 && total.is_finite()) {
                    return None;
                }
                let u = u * total;
                let mut end = 0.0;
                let mut chosen = None;
                for r in points.iter().filter_map(reach) {
                    end += r.2;
                    chosen = Some(r);
                    if u < end {
                        break;
                    }
                }
                chosen.map(|(i, ea, w)| (i, ea, w / total))
            }
            Self::Uniform(points) => {
                let k = ((u * points.len() as f32) as usize).min(points.len().checked_sub(1)?);
                let i = points[k];
                let ea = EquiAngular::new(ray, lights.get(i).point_centre()?, t0, t1)?;
                Some((i, ea, 1.0 / points.len() as f32))
            }
            Self::Many(tree) => {
                let reach =
                    |b: &LightBounds| b.segment_importance_range(ray.origin, ray.dir, t0, t1);
                let (i, q) = tree.pick(reach, u)?;
                let ea = EquiAngular::new(ray, lights.get(i).point_centre()?, t0, t1)?;
                Some((i, ea, q))
            }
        }
    }

    /// The probability that [`Self::pick`] picks light `i` for `ray`'s
    /// span `[t0, t1]` (0 for a light it does not hold).
    #[inline]
    fn probability(&self, ray: &Ray, t0: f32, t1: f32, i: usize) -> f32 {
        match self {
            Self::Few(points) => {
                let reach = |&(_, c, l): &(usize, Vec3, f32)| {
                    let w = l * EquiAngular::new(ray, c, t0, t1)?.reach();
                    (w > 0.0 && w.is_finite()).then_some(w)
                };
                let total: f32 = points.iter().filter_map(reach).sum();
                let own = points.iter().find(|p| p.0 == i).and_then(reach);
                match own {
                    Some(w) if total > 0.0 && total.is_finite() => w / total,
                    _ => 0.0,
                }
            }
            Self::Uniform(points) => {
                // The indices are in ascending order.
                if points.binary_search(&i).is_ok() {
                    1.0 / points.len() as f32
                } else {
                    0.0
                }
            }
            Self::Many(tree) => {
                let reach =
                    |b: &LightBounds| b.segment_importance_range(ray.origin, ray.dir, t0, t1);
                tree.probability(reach, i)
            }
        }
    }
}

impl<M: Media> PathTracer<'_, M> {
    /// The probability that a vertex at `p` whose light choice is weighed
    /// ([`LightChoice::Weighed`]: many lights, no shadow grid deciding)
    /// samples light `i`, and 1 where vertices choose otherwise: the
    /// factor the MIS weights give the collision's next-event estimate,
    /// the same at both sites (see [`Self::collision_weight`]).
    #[inline]
    fn weighed_share(&self, p: Vec3, i: usize) -> f32 {
        let weighed = self.shadows.is_none() || self.sampler.sampling() != LightSampling::One;
        if !weighed {
            return 1.0;
        }
        self.sampler.weighed_probability(p, i).unwrap_or(1.0)
    }

    /// Whether a segment flown at `path.depth` takes an equi-angular sample:
    /// where a collision on it would estimate the lights (not past the
    /// last scattering event, not when only emission is gathered).
    #[inline]
    pub(super) fn equiangular_runs(&self, path: &Path) -> bool {
        self.equiangular && !path.emission_only && self.max_depth.is_none_or(|m| path.depth < m)
    }

    /// The weight of the next-event estimate of point-like light `i`,
    /// centred at `centre` and sampled with probability `pick`, at vertex
    /// `v` against the equi-angular sample of the segment that reached it:
    /// one minus the equi-angular strategy's weight there. Each strategy's
    /// density of gathering light `i` at `t` carries its pick: the
    /// segment's pick of `i` times the equi-angular density, against the
    /// vertex's pick of `i` times the collision density (where vertices
    /// weigh many lights; 1 otherwise, as [`Self::weighed_share`]), so a
    /// light the segment seldom aims at is left to the collisions near it.
    #[inline]
    pub(super) fn collision_weight(&self, v: &Vertex, i: usize, centre: Vec3, pick: f32) -> f32 {
        if !self.equiangular {
            return 1.0;
        }
        let ray = v.ray_in;
        let Some((t0, t1)) = span(self.medium, ray) else {
            return 1.0;
        };
        let Some(ea) = EquiAngular::new(ray, centre, t0, t1) else {
            return 1.0;
        };
        let t = (v.p - ray.origin).dot(ray.dir);
        let q = self.point_pick.probability(ray, t0, t1, i);
        // The vertex's pick where it weighs many lights: the same number
        // `weighed_share` gives the equi-angular sample at this point.
        let share = match v.choice {
            LightChoice::Weighed { .. } => pick,
            _ => 1.0,
        };
        1.0 - weight(
            q * ea.pdf(t),
            share * collision_density(self.medium, ray, t),
        )
    }

    /// The equi-angular sample of the path's current segment: one sphere
    /// light picked by its reach, a point drawn toward it, and the light
    /// scattered there toward the path, weighed against the collision.
    pub(super) fn equiangular<S: Spectrum>(
        &self,
        path: &mut Path,
        draws: &mut SampleStream,
        c: &mut Counters,
    ) {
        let ray = path.ray;
        let Some((t0, t1)) = span(self.medium, &ray) else {
            return;
        };
        let u = draws.rng().uniform();
        let Some((light, ea, q)) = self.point_pick.pick(&self.lights, &ray, t0, t1, u) else {
            return;
        };
        let (t, pdf) = ea.sample(draws.rng().uniform());
        if !(t > t0 && t < t1 && pdf > 0.0) {
            return;
        }
        c.equiangular_samples += 1;
        let tr: S = transmittance(self.estimator, self.medium, &ray, t, draws.rng(), c);
        if !tr.any_positive() {
            return;
        }
        let p = ray.at(t);
        let sigma_t: S = self.medium.extinction(p, ray.time);
        let it = self.medium.interaction(p, ray.time, draws.rng());
        if path.depth == 0 && it.holdout {
            return;
        }
        let depth = path.depth + 1;
        let v = Vertex {
            p,
            ray_in: &ray,
            phase: it.phase,
            mis: self.max_depth != Some(depth),
            index: u32::MAX,
            choice: LightChoice::All,
            arrival: Arrival::default(),
        };
        let n = self.sample_light::<S>(
            &v,
            self.lights.get(light),
            1.0,
            EQUIANGULAR_LIGHT_SAMPLE,
            draws,
            c,
        );
        let flight = self.weighed_share(p, light) * collision_density(self.medium, &ray, t);
        let scale = weight(q * pdf, flight) / (q * pdf);
        let e = path.beta * tr.rgb() * sigma_t.rgb() * it.albedo * it.weight * n * scale;
        path.add_to_group(e, self.lights.group(light), self.light_groups);
        if path.depth == 0 {
            path.out.aov.direct += e;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_density_integrates_to_one_and_sampling_follows_it() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -3.0), Vec3::Z);
        let ea = EquiAngular::new(&ray, Vec3::new(0.5, 0.2, 1.0), 0.5, 9.0).unwrap();
        let n = 100_000;
        let h = (9.0 - 0.5) / n as f32;
        let integral: f32 = (0..n).map(|i| ea.pdf(0.5 + (i as f32 + 0.5) * h) * h).sum();
        assert!((integral - 1.0).abs() < 1e-3, "{integral}");
        // The fraction of draws below t is the density's integral to t.
        let below = |t: f32| {
            (0..n)
                .filter(|&i| ea.sample((i as f32 + 0.5) / n as f32).0 < t)
                .count() as f32
                / n as f32
        };
        for t in [2.0, 4.0, 4.2, 6.0] {
            let m = ((t - 0.5) / h) as usize;
            let cdf: f32 = (0..m).map(|i| ea.pdf(0.5 + (i as f32 + 0.5) * h) * h).sum();
            assert!(
                (below(t) - cdf).abs() < 2e-3,
                "at {t}: {} vs {cdf}",
                below(t)
            );
        }
        let (t, pdf) = ea.sample(0.3);
        assert_eq!(pdf, ea.pdf(t));
        assert!(
            EquiAngular::new(&ray, Vec3::new(0.0, 0.0, 2.0), 0.5, 9.0).is_none(),
            "on the ray"
        );
    }

    #[test]
    fn the_weights_of_both_strategies_sum_to_one() {
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        let ea = EquiAngular::new(&ray, Vec3::new(3.0, 0.5, 0.0), 0.0, 20.0).unwrap();
        for t in [0.1, 2.9, 3.0, 7.0, 19.0] {
            let w = weight(ea.pdf(t), 1.0 / 20.0);
            assert!((0.0..=1.0).contains(&w));
            if t == 3.0 {
                assert!(w > 0.99, "about the light: {w}");
            }
            if t == 19.0 {
                assert!(w < 0.5, "far from it: {w}");
            }
        }
    }

    /// In a homogeneous medium the collision density the weights take is
    /// the free flight's own, `sigma exp(-sigma (t - t0))` from where the
    /// ray enters; zero outside the medium.
    #[test]
    fn a_homogeneous_mediums_collision_density_is_exact() {
        use crate::medium::{ConstantBox, Medium};
        let sigma = 0.7;
        let field = ConstantBox::new(Vec3::ZERO, Vec3::splat(10.0), 1.0, 1.0);
        let medium =
            crate::volumes::Volumes::from(Medium::new(field, sigma, Vec3::splat(0.9), 0.0));
        let ray = Ray::new(Vec3::new(-2.0, 5.0, 5.0), Vec3::X);
        for t in [2.5f32, 4.0, 9.0, 11.9] {
            let want = sigma * (-sigma * (t - 2.0)).exp();
            let got = collision_density(&medium, &ray, t);
            assert!((got / want - 1.0).abs() < 1e-5, "at {t}: {got} vs {want}");
        }
        assert_eq!(collision_density(&medium, &ray, 1.0), 0.0);
        assert_eq!(collision_density(&medium, &ray, 12.5), 0.0);
    }
}
