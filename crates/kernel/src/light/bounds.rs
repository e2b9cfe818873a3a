//! What a light tree knows of a light or of a cluster of them (Conty
//! Estevez and Kulla 2018; pbrt-v4's `LightBounds`, Cycles' light tree):
//! a box holding them, a cone holding the directions they emit about
//! (`cos_theta_o` about `axis`, their emission spreading `theta_e` past
//! it) and their strength `phi`, the luminance of the intensity each sends
//! along its brightest direction, summed. From these, an importance at a
//! point (`phi cos theta' / d^2`, `theta'` the least angle between the
//! cone and the direction to the point) and along a ray segment (`phi`
//! times the angle the segment spans seen from the box's centre over its
//! distance from the segment, the integral of `1 / d^2` along it, as
//! equi-angular sampling's reach and Cycles' volume segments).
//! Volumes have no normal: no incidence term.

use std::f32::consts::PI;

use glam::Vec3;

use super::{AreaLight, AreaShape};

/// The least squared distance an importance divides by, so that a point
/// at a point light weighs finitely.
const MIN_DISTANCE2: f32 = 1e-12;

/// How far past a spot's cone, in radians, its bounds still see it.
const SPOT_MARGIN: f32 = 0.01;

/// The bounds of one light or of a cluster.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    pub min: Vec3,
    pub max: Vec3,
    pub phi: f32,
    /// The cone's axis (unit; any where the cone is the whole sphere).
    pub axis: Vec3,
    pub cos_theta_o: f32,
    pub cos_theta_e: f32,
}

impl LightBounds {
    /// A ball (or a point, radius 0) emitting alike every way, of
    /// intensity luminance `phi`.
    pub fn ball(centre: Vec3, radius: f32, phi: f32) -> Self {
        Self {
            min: centre - Vec3::splat(radius),
            max: centre + Vec3::splat(radius),
            phi,
            axis: Vec3::Z,
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
        }
    }

    /// The same light sending nothing past the cone of cosine
    /// `cos_outer` about unit `axis` (a spot): the least angle between the
    /// cone and a point is taken from the box's whole extent, and a small
    /// margin past the cone's edge (`SPOT_MARGIN`) keeps a point the spot
    /// barely reaches from being starved by rounding.
    pub fn within_cone(self, axis: Vec3, cos_outer: f32) -> Self {
        if cos_outer <= -1.0 {
            return self;
        }
        Self {
            axis,
            cos_theta_o: cos_outer,
            cos_theta_e: SPOT_MARGIN.cos(),
            ..self
        }
    }

    /// An area light: a flat shape emitting about its normal over a
    /// hemisphere, a cylinder's side every way; `phi` its radiance's
    /// luminance times its largest projected area.
    pub fn area(a: &AreaLight) -> Self {
        let r = a.half_extent();
        let l = crate::spectrum::luminance(a.radiance());
        let (cos_theta_o, phi) = match a.shape() {
            AreaShape::Cylinder => (-1.0, l * a.area() / PI),
            AreaShape::Rect | AreaShape::Disk => (1.0, l * a.area()),
        };
        Self {
            min: a.centre() - r,
            max: a.centre() + r,
            phi,
            axis: a.normal(),
            cos_theta_o,
            cos_theta_e: 0.0,
        }
    }

    #[inline]
    pub fn centre(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// Half the box's diagonal: the radius of a ball holding it.
    #[inline]
    fn radius(&self) -> f32 {
        0.5 * (self.max - self.min).length()
    }

    /// The bounds of both clusters.
    pub fn union(&self, other: &Self) -> Self {
        if self.phi <= 0.0 {
            return *other;
        }
        if other.phi <= 0.0 {
            return *self;
        }
        let (axis, cos_theta_o) = cone_union(
            (self.axis, self.cos_theta_o),
            (other.axis, other.cos_theta_o),
        );
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
            phi: self.phi + other.phi,
            axis,
            cos_theta_o,
            cos_theta_e: self.cos_theta_e.min(other.cos_theta_e),
        }
    }

    /// The cosine of the least angle between the cone and the direction
    /// from the box toward `p`, at squared distance `d2` from its centre,
    /// or `None` where no emission of the cluster reaches `p`.
    #[inline]
    fn cos_theta_prime(&self, p: Vec3, d2: f32) -> Option<f32> {
        if self.cos_theta_o <= -1.0 {
            // Every way: the cone holds every direction.
            return Some(1.0);
        }
        let r = self.radius();
        let wi = (p - self.centre()).normalize_or_zero();
        let cos_w = self.axis.dot(wi);
        let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
        // The cone of directions the box subtends from `p`.
        let cos_b = if d2 <= r * r {
            -1.0
        } else {
            (1.0 - r * r / d2).max(0.0).sqrt()
        };
        let sin_b = (1.0 - cos_b * cos_b).max(0.0).sqrt();
        let sin_o = (1.0 - self.cos_theta_o * self.cos_theta_o).max(0.0).sqrt();
        let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, self.cos_theta_o);
        let sin_x = (1.0 - cos_x * cos_x).max(0.0).sqrt();
        let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
        (cos_p > self.cos_theta_e).then_some(cos_p)
    }

    /// The cluster's importance for a point at `p`.
    #[inline]
    pub fn importance(&self, p: Vec3) -> f32 {
        if self.phi <= 0.0 {
            return 0.0;
        }
        let true_d2 = (p - self.centre()).length_squared();
        let Some(cos_p) = self.cos_theta_prime(p, true_d2) else {
            return 0.0;
        };
        let r = self.radius();
        let d2 = true_d2.max(r * r).max(MIN_DISTANCE2);
        self.phi * cos_p / d2
    }

    /// The cluster's least and greatest importance for a point at `p`,
    /// over where in the box its light may come from: `phi cos theta' /
    /// d^2` with `d` the distance to the box's farthest corner and to its
    /// nearest point (0 inside, floored; Cycles' light tree weighs a
    /// child by both, so a cluster about `p` is not lost behind its size).
    #[inline]
    pub fn importance_range(&self, p: Vec3) -> (f32, f32) {
        if self.phi <= 0.0 {
            return (0.0, 0.0);
        }
        let true_d2 = (p - self.centre()).length_squared();
        let Some(cos_p) = self.cos_theta_prime(p, true_d2) else {
            return (0.0, 0.0);
        };
        let near = (self.min - p).max(p - self.max).max(Vec3::ZERO);
        let far = (p - self.min).abs().max((self.max - p).abs());
        let least = self.phi * cos_p / far.length_squared().max(MIN_DISTANCE2);
        let most = self.phi * cos_p / near.length_squared().max(MIN_DISTANCE2);
        (least, most)
    }

    /// The cluster's importance for the ray segment from `o` along unit
    /// `dir` over `[t0, t1]`: `phi` times `integral dt / d^2` along the
    /// segment, its distance from the box's centre at least the box's
    /// radius (the emission's orientation is not weighed: the segment
    /// sees the cluster from many sides).
    #[inline]
    pub fn segment_importance(&self, o: Vec3, dir: Vec3, t0: f32, t1: f32) -> f32 {
        if self.phi <= 0.0 || t1 <= t0 {
            return 0.0;
        }
        let to_c = self.centre() - o;
        let delta = to_c.dot(dir);
        let h = (to_c - delta * dir)
            .length()
            .max(self.radius())
            .max(MIN_DISTANCE2.sqrt());
        let span = ((t1 - delta) / h).atan() - ((t0 - delta) / h).atan();
        self.phi * span.max(0.0) / h
    }

    /// The cluster's least and greatest importance for the ray segment
    /// from `o` along unit `dir` over `[t0, t1]`, over where in its ball
    /// its light may come from: `phi integral dt / d^2` with the cluster
    /// as a point at the distance of the ball's far side from the line and
    /// of its near side (floored, as at a point: a segment through the
    /// ball may pass as near as it likes to one of its lights). For one
    /// point light both are its exact reach. The segment's counterpart of
    /// [`Self::importance_range`], so that a segment passing by a small
    /// cluster finds it however bright a large cluster beside it is.
    #[inline]
    pub fn segment_importance_range(&self, o: Vec3, dir: Vec3, t0: f32, t1: f32) -> (f32, f32) {
        if self.phi <= 0.0 || t1 <= t0 {
            return (0.0, 0.0);
        }
        let to_c = self.centre() - o;
        let delta = to_c.dot(dir);
        let h = (to_c - delta * dir).length();
        let r = self.radius();
        let reach = |h: f32| {
            let h = h.max(MIN_DISTANCE2.sqrt());
            self.phi * span_angle(h, t0 - delta, t1 - delta) / h
        };
        (reach(h + r), reach(h - r))
    }
}

/// The angle `atan(b / h) - atan(a / h)` that the segment `[a, b]` of a
/// line (`a <= b`) spans seen from a point at distance `h > 0` from it,
/// its foot at 0: one `atan2` of the difference's tangent, by a
/// polynomial (within about 1e-5 radians: the tree's importances need
/// only be the same at the pick and at its probability, not exact, and
/// this runs at every node a segment's pick visits).
#[inline]
fn span_angle(h: f32, a: f32, b: f32) -> f32 {
    // tan(x - y) = (tan x - tan y) / (1 + tan x tan y), times h^2.
    let (y, x) = (h * (b - a), h * h + a * b);
    let (ay, ax) = (y.abs(), x.abs());
    let (lo, hi) = (ay.min(ax), ay.max(ax));
    if hi.is_nan() || hi <= 0.0 {
        return 0.0;
    }
    let z = lo / hi;
    let z2 = z * z;
    let mut r = z
        * (0.999_977_26
            + z2 * (-0.332_623_47
                + z2 * (0.193_543_46
                    + z2 * (-0.116_432_87 + z2 * (0.052_653_32 + z2 * -0.011_721_2)))));
    if ay > ax {
        r = std::f32::consts::FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    if y < 0.0 {
        0.0
    } else {
        r
    }
}

/// `cos(max(0, a - b))` from the sines and cosines of `a` and `b`.
#[inline]
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// The least cone holding cones `a` and `b` (axis, cosine of the
/// half-angle), as pbrt-v4's `DirectionCone::Union`.
fn cone_union(a: (Vec3, f32), b: (Vec3, f32)) -> (Vec3, f32) {
    let whole = (Vec3::Z, -1.0);
    if a.1 <= -1.0 || b.1 <= -1.0 {
        return whole;
    }
    let theta_a = a.1.clamp(-1.0, 1.0).acos();
    let theta_b = b.1.clamp(-1.0, 1.0).acos();
    let theta_d = a.0.dot(b.0).clamp(-1.0, 1.0).acos();
    if (theta_d + theta_b).min(PI) <= theta_a {
        return a;
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return b;
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    if theta_o >= PI {
        return whole;
    }
    let theta_r = theta_o - theta_a;
    let wr = a.0.cross(b.0);
    if wr.length_squared() < 1e-12 {
        return whole;
    }
    let axis = glam::Quat::from_axis_angle(wr.normalize(), theta_r) * a.0;
    (axis.normalize(), theta_o.cos())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cluster's importance is at least each of its lights', at points
    /// around and between them (the bound a tree's pick relies on not to
    /// starve a light), and a flat light has none behind it.
    #[test]
    fn a_cluster_bounds_its_lights() {
        let area =
            |c: Vec3, n: Vec3| AreaLight::new(AreaShape::Rect, c, Vec3::X, Vec3::Y, n, Vec3::ONE);
        let lights = [
            LightBounds::ball(Vec3::ZERO, 0.0, 2.0),
            LightBounds::ball(Vec3::new(4.0, 1.0, 0.0), 0.5, 1.0),
            LightBounds::area(&area(Vec3::new(0.0, 3.0, 0.0), Vec3::Z)),
            LightBounds::area(&area(Vec3::new(2.0, 3.0, 1.0), Vec3::X)),
        ];
        let flat = LightBounds::area(&area(Vec3::ZERO, Vec3::Z));
        assert_eq!(flat.importance(Vec3::new(0.3, 0.2, -4.0)), 0.0);
        assert!(flat.importance(Vec3::new(0.3, 0.2, 2.0)) > 0.0);
        let mut rng = cirrus_testkit::SplitMix64(3);
        for a in 0..lights.len() {
            for b in a + 1..lights.len() {
                let u = lights[a].union(&lights[b]);
                for _ in 0..2000 {
                    let p = Vec3::new(rng.unit(), rng.unit(), rng.unit()) * 20.0 - 10.0;
                    let (ia, ib, iu) = (
                        lights[a].importance(p),
                        lights[b].importance(p),
                        u.importance(p),
                    );
                    assert!(
                        iu > 0.0 || (ia == 0.0 && ib == 0.0),
                        "{a} {b} at {p}: {iu} {ia} {ib}"
                    );
                    let (o, d) = (p, Vec3::new(0.3, -0.5, 0.8).normalize());
                    let (sa, sb) = (
                        lights[a].segment_importance(o, d, 0.0, 15.0),
                        lights[b].segment_importance(o, d, 0.0, 15.0),
                    );
                    let su = u.segment_importance(o, d, 0.0, 15.0);
                    assert!(su > 0.0 || (sa == 0.0 && sb == 0.0));
                    // The range: least no more than greatest, and none
                    // for the cluster only where none for its lights.
                    let range = |b: &LightBounds| b.segment_importance_range(o, d, 0.0, 15.0);
                    let (lu, mu) = range(&u);
                    assert!(lu <= mu && lu > 0.0, "{a} {b} at {p}: {lu} {mu}");
                    assert!(range(&lights[a]).0 > 0.0 && range(&lights[b]).0 > 0.0);
                }
            }
        }
    }

    /// A spot's bounds see it in its cone and a little past, and not
    /// behind it.
    #[test]
    fn a_spots_bounds_are_its_cone() {
        let c = Vec3::new(1.0, 2.0, 3.0);
        let spot = LightBounds::ball(c, 0.0, 5.0).within_cone(Vec3::NEG_Y, 0.5f32.cos());
        let at = |angle: f32| c + 10.0 * Vec3::new(angle.sin(), -angle.cos(), 0.0);
        assert!((spot.importance(at(0.3)) - 0.05).abs() < 1e-6);
        assert!(spot.importance(at(0.5 - 1e-4)) > 0.0);
        assert_eq!(spot.importance(at(0.52)), 0.0);
        assert_eq!(spot.importance(at(2.0)), 0.0);
        assert_eq!(spot.importance_range(at(3.0)), (0.0, 0.0));
        // Clustered with a ball, the spot's side still counts.
        let both = spot.union(&LightBounds::ball(Vec3::ZERO, 0.0, 1.0));
        assert!(both.importance(at(3.0)) > 0.0);
    }

    /// The polynomial span angle is the difference of the two arctangents
    /// to within 2e-5 radians, on either side of the foot and past it.
    #[test]
    fn the_span_angle_is_the_difference_of_the_arctangents() {
        for h in [1e-6f32, 0.01, 0.3, 1.0, 7.0, 500.0] {
            for (a, b) in [
                (-3.0f32, 5.0),
                (0.5, 9.0),
                (-9.0, -0.1),
                (-1e4, 1e4),
                (2.0, 2.0),
            ] {
                let want = (b / h).atan() - (a / h).atan();
                let got = span_angle(h, a, b);
                assert!(
                    (got - want).abs() < 2e-5,
                    "h {h}, [{a}, {b}]: {got} vs {want}"
                );
            }
        }
    }

    /// A point light's segment importance is `phi` times equi-angular
    /// sampling's reach, `(theta_b - theta_a) / h`.
    #[test]
    fn a_points_segment_importance_is_its_reach() {
        let b = LightBounds::ball(Vec3::new(3.0, 2.0, 0.0), 0.0, 5.0);
        let got = b.segment_importance(Vec3::ZERO, Vec3::X, 0.0, 10.0);
        let want = 5.0 * ((7.0f32 / 2.0).atan() - (-3.0f32 / 2.0).atan()) / 2.0;
        assert!((got / want - 1.0).abs() < 1e-5, "{got} vs {want}");
        let (least, most) = b.segment_importance_range(Vec3::ZERO, Vec3::X, 0.0, 10.0);
        assert!((least / want - 1.0).abs() < 1e-5 && (most / want - 1.0).abs() < 1e-5);
    }
}
