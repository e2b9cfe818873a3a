//! cirrus: path tracing of sparse production volumes on the CPU.
//!
//! The workspace is a pipeline of small crates, re-exported here:
//! [`vdb`] reads `.vdb` and `.nvdb` files into a sparse tree, [`bricks`]
//! converts a density tree into 8^3 bricks with a majorant/minorant
//! hierarchy and walks rays through it, [`kernel`] (camera, lights,
//! media, trackers, integrators) traces light paths through it,
//! [`render`] runs them over tiles into a film and writes images, and
//! [`scene`]
//! reads scene files, applies overrides and defaults, loads only what can
//! be seen and renders it. The `cirrus` binary (`crates/cli`) is a thin
//! command line over them; the Python module (`crates/python`) another.
//!
//! Render the corpus cloud in a few lines:
//!
//! ```
//! use cirrus::{Overrides, Scene};
//!
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/cloud.vdb");
//! let mut scene = Scene::load(path.as_ref())?;
//! scene.apply(&Overrides { res: Some((24, 16)), spp: Some(4), seed: Some(7), ..Default::default() });
//! let rendered = scene.render()?;
//! let [r, g, b, alpha] = rendered.image.pixel(12, 8);
//! assert!(alpha > 0.0 && r.is_finite() && g.is_finite() && b.is_finite(), "the cloud covers the centre");
//! # Ok::<(), cirrus::Error>(())
//! ```
//!
//! This package also holds the end-to-end tests (`tests/`) and benchmarks
//! (`benches/`) that span the crates.

pub use cirrus_bricks as bricks;
pub use cirrus_kernel as kernel;
pub use cirrus_render as render;
pub use cirrus_scene as scene;
pub use cirrus_vdb as vdb;

pub use cirrus_scene::{Error, ErrorKind, Outputs, Overrides, Scene, SceneDescription};
