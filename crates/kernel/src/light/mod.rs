//! The scene's lights, as a list: distant lights (a direction, optionally
//! a small disc: the sun, the moon: `distant.rs`), domes (light from every
//! direction at infinity, constant or an importance-sampled HDR map:
//! `dome.rs`), sphere lights (a ball or a point, optionally a spot:
//! `sphere.rs`) and area lights (a rectangle or a disc, one-sided:
//! `area.rs`). A light that
//! delivers nothing is dropped by [`Lights::pruned`] and costs nothing: no
//! samples, no shadow rays. Each light is tagged with the light group its
//! contributions go to; the integrators never ask how many lights there
//! are or of which kind, only for the list and each light's group.

mod area;
mod bounds;
mod distant;
mod dome;
mod facing_disk;
mod interface;
mod limits;
mod motion;
mod sphere;
mod spherical_rect;

pub use area::{AreaLight, AreaShape};
pub use bounds::LightBounds;
pub use distant::Sun;
pub use dome::Environment;
pub use interface::{LightHit, Whence};
pub use limits::{shown, MAX_LIGHT_EXTENT, MAX_LIGHT_VALUE};
pub use motion::LightsOverShutter;
pub use sphere::{SphereLight, Spot};

use std::sync::Arc;

use glam::Vec3;

/// A direction toward a light with the radiance arriving along it, the
/// solid-angle pdf of having sampled it (`None` for a delta light) and
/// the distance a shadow ray travels to reach it (infinite for lights at
/// infinity).
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub to_light: Vec3,
    pub radiance: Vec3,
    pub pdf: Option<f32>,
    pub distance: f32,
}

/// One light of the scene.
#[derive(Clone, Debug)]
pub enum Light {
    /// Light arriving along one direction, or from a small disc about it.
    Distant(Sun),
    /// Light arriving from every direction.
    Dome(Environment),
    /// Light from a ball or a point in the scene, optionally a spot.
    Sphere(SphereLight),
    /// Light from one side of a rectangle or a disc in the scene.
    Area(AreaLight),
}

impl From<AreaLight> for Light {
    fn from(light: AreaLight) -> Self {
        Self::Area(light)
    }
}

impl From<SphereLight> for Light {
    fn from(light: SphereLight) -> Self {
        Self::Sphere(light)
    }
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
    Sphere = 2,
    Area = 3,
}

impl Light {
    pub fn kind(&self) -> LightKind {
        match self {
            Self::Distant(_) => LightKind::Distant,
            Self::Dome(_) => LightKind::Dome,
            Self::Sphere(_) => LightKind::Sphere,
            Self::Area(_) => LightKind::Area,
        }
    }

    /// The luminance of a distant light's irradiance, of a dome's mean
    /// radiance or of a sphere light's intensity: what a light choice
    /// weighs it by (times the phase function toward a distant light, and
    /// over the squared distance to a sphere light; an area light by its
    /// radiance).
    pub fn luminance(&self) -> f32 {
        match self {
            Self::Distant(sun) => crate::spectrum::luminance(sun.irradiance()),
            Self::Dome(env) => crate::spectrum::luminance(env.mean_radiance()),
            Self::Sphere(s) => crate::spectrum::luminance(s.intensity()),
            Self::Area(a) => crate::spectrum::luminance(a.radiance()),
        }
    }

    /// Whether it delivers no light at all.
    pub fn is_black(&self) -> bool {
        match self {
            Self::Distant(sun) => sun.irradiance().max_element() <= 0.0,
            Self::Dome(env) => env.is_black(),
            Self::Sphere(s) => s.intensity().max_element() <= 0.0,
            Self::Area(a) => {
                a.radiance().max_element() <= 0.0 || a.area().is_nan() || a.area() <= 0.0
            }
        }
    }

    /// Radiance reaching a ray that escapes along `dir` and the density
    /// with which [`sample`](Self::sample) would have drawn `dir`; `None`
    /// where the light is not seen that way (outside a disc, or a delta
    /// light, which no direction hits; a sphere light is met at a distance,
    /// [`SphereLight::hit`], not at infinity).
    #[inline]
    pub fn escaped(&self, dir: Vec3) -> Option<(Vec3, f32)> {
        match self {
            Self::Distant(sun) => sun.hit(dir),
            Self::Dome(env) => Some(env.eval(dir)),
            Self::Sphere(_) | Self::Area(_) => None,
        }
    }
}

/// The most light groups a render keeps (each costs 24 bytes a pixel of
/// film and 12 a sample).
pub const MAX_LIGHT_GROUPS: usize = 8;

/// Radiance per light group, indexed by the group's position in
/// the render's light-group layers.
pub type GroupRadiance = [Vec3; MAX_LIGHT_GROUPS];

/// Layer names of the default light groups: distant lights, domes and
/// the media's emission ([`Lights::new`] tags them so).
pub const DEFAULT_LIGHT_GROUPS: [&str; 3] = ["sun", "sky", "emission"];

/// The light group of each default kind and of the media's emission:
/// indices into [`DEFAULT_LIGHT_GROUPS`].
const DEFAULT_GROUP_DISTANT: u8 = 0;
const DEFAULT_GROUP_DOME: u8 = 1;
const DEFAULT_GROUP_EMISSION: u8 = 2;

/// The light group of `kind`'s lights where none is given: sphere and
/// area lights join the distant lights' (`sun`) layer.
fn default_group(kind: LightKind) -> u8 {
    match kind {
        LightKind::Distant | LightKind::Sphere | LightKind::Area => DEFAULT_GROUP_DISTANT,
        LightKind::Dome => DEFAULT_GROUP_DOME,
    }
}

/// The scene's lights, each with the light group (an index into the
/// render's light-group layers) its light is tagged with.
#[derive(Clone, Debug)]
pub struct Lights {
    list: Vec<Light>,
    groups: Vec<u8>,
    emission_group: u8,
    /// [`Self::at_infinity`], kept so that an escaping ray does not walk
    /// every light of a scene of thousands.
    at_infinity: Vec<u32>,
    /// The same lights over an open shutter, where they change in it.
    shutter: Option<Arc<LightsOverShutter>>,
}

/// The indices of the lights of `list` at infinity.
fn at_infinity(list: &[Light]) -> Vec<u32> {
    (0..list.len() as u32)
        .filter(|&i| list[i as usize].is_at_infinity())
        .collect()
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
    /// ([`DEFAULT_LIGHT_GROUPS`]).
    pub fn new(lights: impl IntoIterator<Item = Light>) -> Self {
        let list: Vec<Light> = lights.into_iter().collect();
        let groups = list.iter().map(|l| default_group(l.kind())).collect();
        Self {
            at_infinity: at_infinity(&list),
            list,
            groups,
            emission_group: DEFAULT_GROUP_EMISSION,
            shutter: None,
        }
    }

    /// `lights` in order, each with the light group (an index into the
    /// render's light-group layers, below
    /// [`MAX_LIGHT_GROUPS`]) it is tagged with, and
    /// the media's emission tagged with `emission_group`.
    pub fn grouped(lights: impl IntoIterator<Item = (Light, u8)>, emission_group: u8) -> Self {
        let (list, groups): (Vec<Light>, _) = lights.into_iter().unzip();
        Self {
            at_infinity: at_infinity(&list),
            list,
            groups,
            emission_group,
            shutter: None,
        }
    }

    /// A sun and a sky, either absent: the usual outdoor pair.
    pub fn sun_and_sky(sun: Option<Sun>, sky: Option<Environment>) -> Self {
        Self::new(sun.map(Light::from).into_iter().chain(sky.map(Light::from)))
    }

    /// The lights with how they change over an open shutter: `shutter`'s
    /// tables hold these lights (the frame's) at times over it.
    pub fn with_shutter(mut self, shutter: LightsOverShutter) -> Self {
        self.shutter = Some(Arc::new(shutter));
        self
    }

    /// The lights over the shutter, where they change while it is open
    /// (the render takes a camera sample's lights from the table nearest
    /// its time); `None` where these lights hold all the while.
    pub fn over_shutter(&self) -> Option<&LightsOverShutter> {
        self.shutter.as_deref()
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
            _ => None,
        })
    }

    /// The domes.
    pub fn domes(&self) -> impl Iterator<Item = &Environment> {
        self.list.iter().filter_map(|l| match l {
            Light::Dome(env) => Some(env),
            _ => None,
        })
    }

    /// Whether any light is a surface rays can meet: a ball (a sphere
    /// light of non-zero radius) or an area light.
    pub fn any_surface(&self) -> bool {
        self.list.iter().any(Light::is_surface)
    }

    /// The indices of the lights at infinity (distant lights and domes):
    /// the ones an escaping ray reaches.
    #[inline]
    pub fn at_infinity(&self) -> &[u32] {
        &self.at_infinity
    }

    /// The lights with positions given relative to `origin` (render space
    /// is world space minus a centre kept in f64, so that f32 stays
    /// precise far from the world's origin); directions are unchanged.
    pub fn relative_to(mut self, origin: glam::DVec3) -> Self {
        if let Some(m) = self.shutter.take() {
            self.shutter = Some(Arc::new(m.map(|l| l.relative_to(origin))));
        }
        for light in &mut self.list {
            match light {
                Light::Sphere(s) => *s = s.moved_to((s.position().as_dvec3() - origin).as_vec3()),
                Light::Area(a) => *a = a.moved_to((a.centre().as_dvec3() - origin).as_vec3()),
                Light::Distant(_) | Light::Dome(_) => {}
            }
        }
        self
    }

    /// Drops lights that deliver nothing (zero irradiance or radiance), so
    /// they cost nothing either; the others keep their order and groups.
    /// A light that changes over the shutter is dropped only where it is
    /// black in every table.
    pub fn pruned(self) -> Self {
        let tables = self.shutter.as_deref().map_or(&[][..], |m| m.tables());
        let keep: Vec<bool> = (0..self.list.len())
            .map(|i| !self.list[i].is_black() || tables.iter().any(|t| !t.list[i].is_black()))
            .collect();
        let shutter = self
            .shutter
            .as_deref()
            .map(|m| Arc::new(m.map(|t| t.kept(&keep))));
        Self {
            shutter,
            ..self.kept(&keep)
        }
    }

    /// The lights whose `keep` is true, in order, with their groups.
    fn kept(self, keep: &[bool]) -> Self {
        let (list, groups): (Vec<Light>, Vec<u8>) = self
            .list
            .into_iter()
            .zip(self.groups)
            .zip(keep)
            .filter_map(|(l, &k)| k.then_some(l))
            .unzip();
        Self {
            at_infinity: at_infinity(&list),
            list,
            groups,
            emission_group: self.emission_group,
            shutter: None,
        }
    }
}
