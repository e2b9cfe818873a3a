//! How many lights a vertex's next-event estimation samples: a setting,
//! apart from the light choice (`light_choice.rs`) that carries it out.

use super::per_light::MAX_PICKED_LIGHTS;
use crate::light::Lights;

settings_enum! {
    /// How many lights next-event estimation samples at each vertex.
    pub enum LightSampling {
        /// `one` under a constant sky (with or without a sun), `all` otherwise.
        #[default]
        Auto = "auto",
        /// Every light, one sample each.
        All = "all",
        // Past 8 lights the pick is many_lights.rs's (a light tree).
        /// One light (or, deep in the media, most often none), picked in
        /// proportion to its in-scattered radiance at the vertex seen through
        /// the media (past 8 lights, by a light tree).
        One = "one",
        /// One light picked uniformly at random (the baseline the weighed
        /// pick is measured against).
        Uniform = "uniform",
    }
}

impl LightSampling {
    /// Whether a vertex picks one light under `lights` (pruned of the dark
    /// ones) through a shadow grid: `one`, resolved, with a light to pick
    /// and no more than [`MAX_PICKED_LIGHTS`].
    pub fn picks_one(self, lights: &Lights) -> bool {
        self.resolve(lights) == Self::One && !lights.is_empty() && lights.len() <= MAX_PICKED_LIGHTS
    }

    /// What `self` comes to under `lights`: `All`, `One` or `Uniform`
    /// (`auto` is `One` past [`MAX_PICKED_LIGHTS`] lights).
    pub fn resolve(self, lights: &Lights) -> LightSampling {
        match self {
            Self::Auto if lights.len() > MAX_PICKED_LIGHTS => Self::One,
            Self::Auto
                if lights.domes().next().is_some() && lights.domes().all(|e| e.map.is_none()) =>
            {
                Self::One
            }
            Self::Auto => Self::All,
            other => other,
        }
    }
}
