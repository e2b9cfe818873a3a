//! cirrus: path tracing of sparse production volumes on the CPU.
//!
//! The workspace is a pipeline of small crates, re-exported here:
//! [`vdb`] reads `.vdb` and `.nvdb` files into a sparse tree, [`bricks`]
//! converts a density tree into 8^3 bricks with a majorant/minorant
//! hierarchy and walks rays through it, and `cirrus-render` (camera,
//! lights, trackers, integrators, film) turns that into images. The
//! `cirrus` binary (`crates/cli`) is the command line over all three.
//!
//! This package holds the end-to-end tests (`tests/`) and benchmarks
//! (`benches/`) that span the crates.

pub use cirrus_bricks as bricks;
pub use cirrus_vdb as vdb;
