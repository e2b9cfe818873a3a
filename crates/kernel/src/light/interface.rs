//! What the integrators ask of a light, whatever its kind: one method per
//! question and, inside each, the one match on the kinds. A new kind is
//! one file and one arm in each method here; the integrators never name a
//! kind.

use glam::Vec3;

use super::bounds::LightBounds;
use super::{Light, LightSample, Sun};
use crate::counters::Counters;
use crate::phase::Phase;
use crate::spectrum::luminance;

/// Where a light lies, seen from a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Whence {
    /// From every direction (a dome).
    Everywhere,
    /// Along unit `dir`, a shadow ray toward it travelling `distance`
    /// (infinite for a distant light; to a ball's surface for a ball).
    Toward { dir: Vec3, distance: f32 },
}

/// A light surface a ray meets: the distance, the radiance it sees there
/// and the solid-angle density with which the light's own sampling from
/// the ray's origin draws the ray's direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightHit {
    pub t: f32,
    pub radiance: Vec3,
    pub pdf: f32,
}

impl Light {
    /// A direction toward the light from `p` drawn with `(u1, u2)`, the
    /// radiance along it and its density (`None` for a delta light).
    #[inline]
    pub fn sample_toward(&self, p: Vec3, u1: f32, u2: f32) -> LightSample {
        match self {
            Self::Distant(sun) => sun.sample(u1, u2),
            Self::Dome(env) => env.sample(u1, u2),
            Self::Sphere(s) => s.sample(p, u1, u2),
            Self::Area(a) => a.sample(p, u1, u2),
        }
    }

    /// A sample for the marchers, which take a distant light's disc as
    /// its irradiance along a direction drawn in the disc (no density:
    /// `pdf` is `None` and `radiance` what the sample delivers); `None`
    /// for a light from every direction, which they reach by the phase
    /// function instead.
    #[inline]
    pub fn march_sample(&self, p: Vec3, u1: f32, u2: f32) -> Option<LightSample> {
        match self {
            Self::Distant(sun) => Some(LightSample {
                radiance: sun.irradiance(),
                pdf: None,
                ..sun.sample(u1, u2)
            }),
            Self::Dome(_) => None,
            Self::Sphere(s) => Some(s.sample(p, u1, u2)),
            Self::Area(a) => Some(a.sample(p, u1, u2)),
        }
    }

    /// Where a ray from `p` along unit `dir` meets the light's surface
    /// within `t_max` (lights at infinity and points have none).
    #[inline]
    pub fn hit(&self, p: Vec3, dir: Vec3, t_max: f32) -> Option<LightHit> {
        let (t, radiance, pdf) = match self {
            Self::Distant(_) | Self::Dome(_) => return None,
            Self::Sphere(s) => s.hit(p, dir, t_max)?,
            Self::Area(a) => a.hit(p, dir, t_max)?,
        };
        Some(LightHit { t, radiance, pdf })
    }

    /// The solid-angle density with which [`Self::sample_toward`] from
    /// `p` draws unit `dir` (0 for a delta light or a direction that
    /// misses).
    pub fn density(&self, p: Vec3, dir: Vec3) -> f32 {
        if let Some((_, pdf)) = self.escaped(dir) {
            return pdf;
        }
        self.hit(p, dir, f32::INFINITY).map_or(0.0, |h| h.pdf)
    }

    /// Whether the light lies at infinity (reached by escaping rays).
    #[inline]
    pub fn is_at_infinity(&self) -> bool {
        matches!(self, Self::Distant(_) | Self::Dome(_))
    }

    /// Whether rays can meet it: a ball or an area light.
    #[inline]
    pub fn is_surface(&self) -> bool {
        match self {
            Self::Sphere(s) => !s.is_point(),
            Self::Area(_) => true,
            Self::Distant(_) | Self::Dome(_) => false,
        }
    }

    /// Whether camera rays see it (lights at infinity always).
    #[inline]
    pub fn camera_visible(&self) -> bool {
        match self {
            Self::Distant(_) | Self::Dome(_) => true,
            Self::Sphere(s) => s.camera_visible(),
            Self::Area(a) => a.camera_visible(),
        }
    }

    /// The centre equi-angular sampling draws distances toward: a ball's
    /// or a point's (`None` for other lights).
    #[inline]
    pub fn point_centre(&self) -> Option<Vec3> {
        match self {
            Self::Sphere(s) => Some(s.position()),
            _ => None,
        }
    }

    /// The distant light, for the strategies aimed at one (sunward
    /// scattering).
    #[inline]
    pub fn as_distant(&self) -> Option<&Sun> {
        match self {
            Self::Distant(sun) => Some(sun),
            _ => None,
        }
    }

    /// The radiance of a light the same from every direction (a constant
    /// dome), which any direction sampler can reach; `None` otherwise.
    #[inline]
    pub fn uniform_radiance(&self) -> Option<Vec3> {
        match self {
            Self::Dome(env) if env.map.is_none() => Some(env.radiance),
            _ => None,
        }
    }

    /// The solid angle of a distant light's disc (0 for a delta light and
    /// every other kind).
    #[inline]
    pub fn disc_solid_angle(&self) -> f32 {
        match self {
            Self::Distant(sun) => sun.solid_angle(),
            _ => 0.0,
        }
    }

    /// Where the light lies seen from `p`.
    #[inline]
    pub fn whence(&self, p: Vec3) -> Whence {
        match self {
            Self::Distant(sun) => Whence::Toward {
                dir: -sun.direction(),
                distance: f32::INFINITY,
            },
            Self::Dome(_) => Whence::Everywhere,
            Self::Sphere(s) => {
                let to = s.position() - p;
                let d = to.length();
                Whence::Toward {
                    dir: to.normalize_or_zero(),
                    distance: (d - s.radius()).max(0.0),
                }
            }
            Self::Area(a) => {
                let to = a.centre() - p;
                Whence::Toward {
                    dir: to.normalize_or_zero(),
                    distance: to.length(),
                }
            }
        }
    }

    /// The luminance the light sends toward `p` unoccluded, given the
    /// luminance of its strength ([`Self::luminance`]): that luminance for
    /// a light at infinity, falling off with distance (and a spot's cone,
    /// an area light's angle) for the others.
    #[inline]
    pub fn luminance_at(&self, p: Vec3, luminance: f32) -> f32 {
        match self {
            Self::Distant(_) | Self::Dome(_) => luminance,
            Self::Sphere(s) => s.luminance_at(p, luminance),
            Self::Area(a) => a.luminance_at(p, luminance),
        }
    }

    /// The light at `p` scattered by `phase` toward a ray along `dir`,
    /// unoccluded and the light taken as a point at its centre (a dome by
    /// its mean radiance), times `seen`: the marchers' cached in-scattering.
    #[inline]
    pub fn in_scattered(&self, phase: &Phase, p: Vec3, dir: Vec3, seen: f32) -> Vec3 {
        match self {
            Self::Distant(sun) => {
                let f = phase.eval(dir, -sun.direction());
                sun.irradiance() * (f * seen)
            }
            Self::Dome(env) => env.mean_radiance() * seen,
            Self::Sphere(light) => {
                let to = light.position() - p;
                let d2 = to.length_squared().max(light.radius() * light.radius());
                let w = to.normalize_or_zero();
                let f = phase.eval(dir, w) * light.falloff(-w);
                light.intensity() * (f * seen / d2)
            }
            Self::Area(light) => {
                let w = (light.centre() - p).normalize_or_zero();
                let e = light.luminance_at(p, 1.0);
                light.radiance() * (phase.eval(dir, w) * e * seen)
            }
        }
    }

    /// Its bounds for a light tree (position, orientation, strength);
    /// `None` for lights at infinity, which no tree holds.
    pub fn bounds(&self) -> Option<LightBounds> {
        match self {
            Self::Distant(_) | Self::Dome(_) => None,
            Self::Sphere(s) => {
                let ball = LightBounds::ball(s.position(), s.radius(), luminance(s.intensity()));
                Some(match s.spot() {
                    Some(spot) => ball.within_cone(spot.axis(), spot.cos_outer()),
                    None => ball,
                })
            }
            Self::Area(a) => Some(LightBounds::area(a)),
        }
    }

    /// Counts a light sample drawn (the domes' counter).
    #[inline]
    pub fn count_sample(&self, c: &mut Counters) {
        c.dome_samples += u64::from(matches!(self, Self::Dome(_)));
    }

    /// Counts a shadow ray traced toward it, in its kind's counter.
    #[inline]
    pub fn count_shadow_ray(&self, c: &mut Counters) {
        match self {
            Self::Distant(_) => c.nee_rays_distant += 1,
            Self::Dome(_) => c.nee_rays_dome += 1,
            Self::Sphere(_) => c.nee_rays_sphere += 1,
            Self::Area(_) => c.nee_rays_area += 1,
        }
    }
}
