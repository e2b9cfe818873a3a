//! The cirrus scene model: what to render, read from a scene file, a lone
//! volume file or code, and rendered without the command line.
//!
//! How the parts fit:
//!
//! - [`SceneDescription`] is exactly the TOML format of a scene file (and
//!   the JSON form of a Python dict). [`Overrides`] are the flags of
//!   `cirrus render` as plain optional fields written over it; with the
//!   `clap` feature, [`SceneFlags`] and [`OutputFlags`] are their
//!   command-line form. Every setting is declared once, with its default
//!   (`description.rs`, [`settings`]).
//! - [`Scene`] holds a description and renders it: it resolves the
//!   scene-wide [`SceneSettings`], plans each volume from its file's header,
//!   culls the volumes no path can reach, reads only the grids that can
//!   matter, and renders through `cirrus-render`; [`Scene::prepare`] stops
//!   before rendering, with the [`Prepared`] scene (the benchmarks and the
//!   preview render it many times, a [`VolumeCache`] keeping its grids).
//! - [`Outputs`] writes the EXR, PNG and statistics whole or not at all.
//! - [`frames`] parses frame ranges and replaces frame patterns
//!   (`cloud.####.vdb`) in a scene's paths ([`Scene::for_frame`]).
//! - [`info::file_report`] is the report of `cirrus info --json`;
//!   [`dense::read_dense`] reads a grid into a dense array.
//! - Every failure is an [`Error`] whose kind says whether a file or the
//!   input was at fault, with the message the command line prints.
//!
//! ```
//! use cirrus_scene::{Overrides, Scene};
//!
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cloud.vdb");
//! let mut scene = Scene::load(path.as_ref())?;
//! scene.apply(&Overrides { res: Some((16, 12)), spp: Some(2), ..Default::default() });
//! let rendered = scene.render()?;
//! assert_eq!((rendered.image.width, rendered.image.height), (16, 12));
//! # Ok::<(), cirrus_scene::Error>(())
//! ```

pub mod compositing;
pub mod cull;
mod declare;
mod denoise;
mod denoise_tiles;
pub mod dense;
pub mod description;
mod device;
mod error;
#[cfg(feature = "clap")]
mod flags;
pub mod frames;
pub mod grids;
pub mod info;
mod light_checks;
mod light_keys;
pub mod lights;
mod moving;
mod output;
mod overrides;
pub mod parse;
mod plan;
mod prepare;
mod ranges;
mod scene;
mod settings;
pub mod timeline;
pub mod usd;
mod values;

pub use declare::{SettingInfo, Shown};
pub use denoise::{denoise, denoise_available};
pub use denoise_tiles::merge_tiles;
#[cfg(feature = "clap")]
#[cfg(feature = "clap")]
pub use description::OutputFlags;
pub use description::SceneDescription;
pub use device::{Device, RenderTarget};
pub use error::{Error, ErrorKind, Result};
#[cfg(feature = "clap")]
pub use flags::{settings_table, SceneFlags};
pub use light_keys::LightKey;
pub use output::{has_extension, write_whole, Outputs};
pub use overrides::{examples, settings, Overrides};
pub use plan::{VolumeCache, DENSITY_SCALE_PER_VOXEL};
pub use prepare::{Placement, Prepared};
pub use scene::Scene;
pub use settings::SceneSettings;
