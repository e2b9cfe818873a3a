//! What compositors need beyond the beauty: light groups, holdouts, deep
//! samples and ID mattes (Cryptomatte), as production renderers write them.
//!
//! - Light groups: every contribution an integrator adds is tagged with the
//!   group of the light it came from ([`crate::Lights::group`]); a [`Sample`]
//!   carries the per-group radiance beside the total, and the film keeps
//!   one mean per group. The groups are the same estimate split, so they
//!   sum to the beauty to float rounding.
//! - Holdouts: [`DepthHoldout`] ends each camera ray at a depth image's
//!   depth (`Ray::t_max`); a holdout volume ([`Media::holdout`]) ends a
//!   camera path that first collides in it with no light and no alpha.
//! - `film`: the per-tile accumulators of the layers ([`TileLayers`]) and
//!   the resolved [`Layers`].
//! - `deep`: per-pixel bins of the camera ray's first collision depth,
//!   resolved into deep samples whose "over" composite is the flat mean.
//! - `cryptomatte`: the IDs, ranks and manifest of the Cryptomatte
//!   specification.
//!
//! [`Sample`]: crate::Sample
//! [`Media::holdout`]: crate::Media::holdout

pub mod cryptomatte;
pub mod deep;
mod depth_image;
pub(crate) mod film;

pub use deep::DeepSample;
pub use depth_image::{DepthHoldout, DEFAULT_FAR};
pub use film::Layers;
pub(crate) use film::TileLayers;

pub use cirrus_kernel::light::{GroupRadiance, DEFAULT_LIGHT_GROUPS, MAX_LIGHT_GROUPS};

use std::sync::Arc;

/// The longest light-group name, in bytes of UTF-8: OpenEXR channel
/// names hold at most 255 bytes, and a group's channels are `NAME.R`.
pub const MAX_LAYER_NAME_BYTES: usize = 253;

/// Deep samples per pixel when none is given (the background sample
/// comes on top).
pub const DEFAULT_DEEP_SAMPLES: u32 = 16;

/// The compositing outputs a render keeps; the default keeps none.
#[derive(Clone, Debug, Default)]
pub struct Compositing {
    /// Names of the light-group layers, by group index; empty: none kept.
    pub light_groups: Vec<String>,
    /// Keep per-instance coverage of the camera rays' first collisions.
    pub cryptomatte: bool,
    /// Keep deep samples, at most this many per pixel (plus background).
    pub deep_samples: Option<u32>,
    /// End camera rays at these depths.
    pub holdout_depth: Option<Arc<DepthHoldout>>,
}

impl Compositing {
    /// Whether the film keeps anything beyond the beauty and AOVs.
    pub fn keeps_layers(&self) -> bool {
        !self.light_groups.is_empty() || self.cryptomatte || self.deep_samples.is_some()
    }

    /// Checks the group names: at most [`MAX_LIGHT_GROUPS`], each a
    /// non-empty layer name (no `.`), no two alike.
    pub fn validate(&self) -> cirrus_kernel::Result<()> {
        use cirrus_kernel::Error;
        if self.light_groups.len() > MAX_LIGHT_GROUPS {
            return Err(Error::invalid(format!(
                "{} light groups; at most {MAX_LIGHT_GROUPS} are kept",
                self.light_groups.len()
            )));
        }
        for (i, name) in self.light_groups.iter().enumerate() {
            if name.is_empty() || name.contains('.') || name.chars().any(char::is_whitespace) {
                return Err(Error::invalid(format!(
                    "light group {name:?}: a layer name must be non-empty, without '.' or spaces"
                )));
            }
            if name.len() > MAX_LAYER_NAME_BYTES || name.contains('\0') {
                let shown: String = name.chars().take(40).collect();
                return Err(Error::invalid(format!(
                    "light group \"{shown}...\" is {} bytes in UTF-8: OpenEXR channel names \
                     (the layer's `NAME.R`) hold at most 255, so at most {MAX_LAYER_NAME_BYTES} \
                     for the name, and no NUL",
                    name.len()
                )));
            }
            if self.light_groups[..i].contains(name) {
                return Err(Error::invalid(format!(
                    "light group {name:?} is named twice"
                )));
            }
        }
        if self.deep_samples == Some(0) {
            return Err(Error::invalid("deep samples per pixel must be at least 1"));
        }
        Ok(())
    }
}
