//! The scene's lights, as a list: distant lights (a direction, optionally
//! a small disc: the sun, the moon) and domes (light from every direction
//! at infinity, constant or an importance-sampled HDR map). A light that
//! delivers nothing is dropped by [`Lights::pruned`] and costs nothing: no
//! samples, no shadow rays. Each light is tagged with the light group its
//! contributions go to; the integrators never ask how many lights there
//! are or of which kind, only for the list and each light's group.

use std::f32::consts::PI;
use std::sync::Arc;

use glam::Vec3;

use crate::env_map::EnvMap;

use crate::sampling::{uniform_cone, uniform_sphere, UNIFORM_SPHERE_PDF};

/// A direction toward a light with the radiance arriving along it and the
/// solid-angle pdf of having sampled it (`None` for a delta light).
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub to_light: Vec3,
    pub radiance: Vec3,
    pub pdf: Option<f32>,
}

/// A directional light like Mitsuba 3's `directional` emitter: `irradiance`
/// is measured on a plane perpendicular to the light's direction.
///
/// With a non-zero angular diameter the sun is a cone of uniform radiance
/// `irradiance / solid_angle`, so the light it delivers into a medium equals
/// the delta light's (`integral of L over the cone = irradiance`) and
/// changing the angle only softens shadows.
#[derive(Clone, Copy, Debug)]
pub struct Sun {
    /// Unit vector pointing FROM the light toward the scene.
    direction: Vec3,
    irradiance: Vec3,
    /// `1 - cos(half angle)`, computed as `2 sin^2(half / 2)` for precision.
    one_minus_cos: f32,
    solid_angle: f32,
}

impl Sun {
    /// `direction` points from the light toward the scene (normalised here);
    /// `angular_diameter` is the full apex angle of the disc in radians
    /// (0 = delta light; the real sun is about 0.0093; up to 2 pi, where the
    /// "disc" is the whole sphere, which the tests use as a furnace).
    pub fn new(direction: Vec3, irradiance: Vec3, angular_diameter: f32) -> Self {
        let half = if angular_diameter.is_nan() {
            0.0
        } else {
            (0.5 * angular_diameter).clamp(0.0, PI)
        };
        let one_minus_cos = 2.0 * (0.5 * half).sin().powi(2);
        Self {
            direction: direction.normalize(),
            irradiance,
            one_minus_cos,
            solid_angle: 2.0 * PI * one_minus_cos,
        }
    }

    pub fn direction(&self) -> Vec3 {
        self.direction
    }

    pub fn irradiance(&self) -> Vec3 {
        self.irradiance
    }

    /// `1 - cos` of the disc's angular radius (0 for a delta sun).
    pub fn one_minus_cos_half_angle(&self) -> f32 {
        self.one_minus_cos
    }

    /// A delta light cannot be hit by a sampled direction, so it gets
    /// next-event estimation only and no MIS.
    /// The disc's solid angle (0 for a delta light).
    pub fn solid_angle(&self) -> f32 {
        self.solid_angle
    }

    pub fn is_delta(&self) -> bool {
        self.solid_angle <= 0.0
    }

    /// Samples a direction toward the sun, uniform over its cone.
    pub fn sample(&self, u1: f32, u2: f32) -> LightSample {
        if self.is_delta() {
            return LightSample {
                to_light: -self.direction,
                radiance: self.irradiance,
                pdf: None,
            };
        }
        LightSample {
            to_light: uniform_cone(-self.direction, self.one_minus_cos, u1, u2),
            radiance: self.irradiance / self.solid_angle,
            pdf: Some(1.0 / self.solid_angle),
        }
    }

    /// Radiance and sampling pdf seen along `dir` by a ray escaping the
    /// scene, or `None` outside the disc (always `None` for a delta sun).
    pub fn hit(&self, dir: Vec3) -> Option<(Vec3, f32)> {
        if self.is_delta() {
            return None;
        }
        // 1 - cos(angle to the sun's centre) compared in the same form as
        // the cone was built, so small suns are not lost to rounding.
        let one_minus_cos = 1.0 + dir.dot(self.direction);
        (one_minus_cos <= self.one_minus_cos)
            .then(|| (self.irradiance / self.solid_angle, 1.0 / self.solid_angle))
    }
}

/// Light arriving from every direction at infinity: a constant radiance,
/// or an HDR [`EnvMap`] whose texels are multiplied by `radiance` (the
/// map's intensity, per channel).
#[derive(Clone, Debug)]
pub struct Environment {
    pub radiance: Vec3,
    pub map: Option<Arc<EnvMap>>,
}

impl Environment {
    pub fn new(radiance: Vec3) -> Self {
        Self {
            radiance,
            map: None,
        }
    }

    /// An environment map scaled by `intensity`.
    pub fn from_map(map: Arc<EnvMap>, intensity: Vec3) -> Self {
        Self {
            radiance: intensity,
            map: Some(map),
        }
    }

    /// Samples a direction toward the sky: uniformly over the sphere for a
    /// constant environment (the only light-side strategy there is; MIS
    /// with phase sampling adds the rest), by the map's distribution for a
    /// map.
    #[inline]
    pub fn sample(&self, u1: f32, u2: f32) -> LightSample {
        match &self.map {
            None => LightSample {
                to_light: uniform_sphere(u1, u2),
                radiance: self.radiance,
                pdf: Some(UNIFORM_SPHERE_PDF),
            },
            Some(map) => {
                let (to_light, l, pdf) = map.sample(u1, u2);
                LightSample {
                    to_light,
                    radiance: l * self.radiance,
                    pdf: Some(pdf),
                }
            }
        }
    }

    /// Radiance along `dir` and the solid-angle density with which
    /// [`sample`](Self::sample) would have picked it.
    #[inline]
    pub fn eval(&self, dir: Vec3) -> (Vec3, f32) {
        match &self.map {
            None => (self.radiance, UNIFORM_SPHERE_PDF),
            Some(map) => {
                let (l, pdf) = map.eval(dir);
                (l * self.radiance, pdf)
            }
        }
    }

    /// Radiance averaged over the sphere (what the two-pass light grid,
    /// which stores only the sky's transmittance, lights with).
    pub fn mean_radiance(&self) -> Vec3 {
        match &self.map {
            None => self.radiance,
            Some(map) => map.mean() * self.radiance,
        }
    }

    /// Whether it delivers no light at all.
    pub fn is_black(&self) -> bool {
        self.radiance.max_element() <= 0.0 || self.map.as_ref().is_some_and(|m| m.is_black())
    }
}

/// One light of the scene.
#[derive(Clone, Debug)]
pub enum Light {
    /// Light arriving along one direction, or from a small disc about it.
    Distant(Sun),
    /// Light arriving from every direction.
    Dome(Environment),
}

impl From<Sun> for Light {
    fn from(sun: Sun) -> Self {
        Self::Distant(sun)
    }
}

impl From<Environment> for Light {
    fn from(env: Environment) -> Self {
        Self::Dome(env)
    }
}

/// What a light is, for counters and the default light groups.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightKind {
    Distant = 0,
    Dome = 1,
}

impl Light {
    pub fn kind(&self) -> LightKind {
        match self {
            Self::Distant(_) => LightKind::Distant,
            Self::Dome(_) => LightKind::Dome,
        }
    }

    /// The luminance of a distant light's irradiance or of a dome's mean
    /// radiance: what a light choice weighs it by, times the phase
    /// function toward a distant light.
    pub fn luminance(&self) -> f32 {
        match self {
            Self::Distant(sun) => crate::spectrum::luminance(sun.irradiance()),
            Self::Dome(env) => crate::spectrum::luminance(env.mean_radiance()),
        }
    }

    /// Whether it delivers no light at all.
    pub fn is_black(&self) -> bool {
        match self {
            Self::Distant(sun) => sun.irradiance.max_element() <= 0.0,
            Self::Dome(env) => env.is_black(),
        }
    }

    /// Radiance reaching a ray that escapes along `dir` and the density
    /// with which [`sample`](Self::sample) would have drawn `dir`; `None`
    /// where the light is not seen that way (outside a disc, or a delta
    /// light, which no direction hits).
    #[inline]
    pub fn escaped(&self, dir: Vec3) -> Option<(Vec3, f32)> {
        match self {
            Self::Distant(sun) => sun.hit(dir),
            Self::Dome(env) => Some(env.eval(dir)),
        }
    }
}

/// The light group of each default kind and of the media's emission:
/// indices into [`crate::compositing::DEFAULT_LIGHT_GROUPS`].
const DEFAULT_GROUP_DISTANT: u8 = 0;
const DEFAULT_GROUP_DOME: u8 = 1;
const DEFAULT_GROUP_EMISSION: u8 = 2;

/// The scene's lights, each with the light group (an index into the
/// render's light-group layers) its light is tagged with.
#[derive(Clone, Debug)]
pub struct Lights {
    list: Vec<Light>,
    groups: Vec<u8>,
    emission_group: u8,
}

impl Default for Lights {
    fn default() -> Self {
        Self::new([])
    }
}

impl FromIterator<Light> for Lights {
    fn from_iter<I: IntoIterator<Item = Light>>(iter: I) -> Self {
        Self::new(iter)
    }
}

impl Lights {
    /// `lights` in order, grouped by kind: distant lights in the layer
    /// `sun`, domes in `sky`, emission in `emission`
    /// ([`crate::compositing::DEFAULT_LIGHT_GROUPS`]).
    pub fn new(lights: impl IntoIterator<Item = Light>) -> Self {
        let list: Vec<Light> = lights.into_iter().collect();
        let groups = list
            .iter()
            .map(|l| match l.kind() {
                LightKind::Distant => DEFAULT_GROUP_DISTANT,
                LightKind::Dome => DEFAULT_GROUP_DOME,
            })
            .collect();
        Self {
            list,
            groups,
            emission_group: DEFAULT_GROUP_EMISSION,
        }
    }

    /// A sun and a sky, either absent: the usual outdoor pair.
    pub fn sun_and_sky(sun: Option<Sun>, sky: Option<Environment>) -> Self {
        Self::new(sun.map(Light::from).into_iter().chain(sky.map(Light::from)))
    }

    /// The lights, in the order their samples are drawn.
    #[inline]
    pub fn iter(&self) -> std::slice::Iter<'_, Light> {
        self.list.iter()
    }

    #[inline]
    pub fn len(&self) -> usize {
        self.list.len()
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    #[inline]
    pub fn get(&self, i: usize) -> &Light {
        &self.list[i]
    }

    /// The light group light `i` is tagged with.
    #[inline]
    pub fn group(&self, i: usize) -> usize {
        usize::from(self.groups[i])
    }

    /// The light group the media's emission is tagged with.
    #[inline]
    pub fn emission_group(&self) -> usize {
        usize::from(self.emission_group)
    }

    /// The distant lights with their indices.
    pub fn distant(&self) -> impl Iterator<Item = (usize, &Sun)> {
        self.list.iter().enumerate().filter_map(|(i, l)| match l {
            Light::Distant(sun) => Some((i, sun)),
            Light::Dome(_) => None,
        })
    }

    /// The domes.
    pub fn domes(&self) -> impl Iterator<Item = &Environment> {
        self.list.iter().filter_map(|l| match l {
            Light::Dome(env) => Some(env),
            Light::Distant(_) => None,
        })
    }

    /// Drops lights that deliver nothing (zero irradiance or radiance), so
    /// they cost nothing either; the others keep their order and groups.
    pub fn pruned(self) -> Self {
        let (list, groups) = self
            .list
            .into_iter()
            .zip(self.groups)
            .filter(|(l, _)| !l.is_black())
            .unzip();
        Self {
            list,
            groups,
            emission_group: self.emission_group,
        }
    }
}
