//! Reads OpenVDB (`.vdb`) and NanoVDB (`.nvdb`) files into one in-memory
//! sparse tree with its transform.
//!
//! The pipeline is: [`VolumeFile::open`] reads a file's header and grid index
//! (never grid data), [`VolumeFile::read_grid`] seeks to one grid and decodes
//! it into a [`Grid`]: a [`Tree`] of one value type (root table, 32^3 and
//! 16^3 internal nodes, 8^3 leaves, tiles at every level, a background), a
//! [`Transform`] between index and world space, a class and metadata.
//!
//! - `openvdb/` decodes the OpenVDB format: descriptors, node masks, the
//!   seven inactive-value modes, zip and blosc chunks, half floats.
//! - `nanovdb/` decodes NanoVDB file segments and grid buffers.
//! - `tree/` is the shared tree, its accessor and statistics.
//!
//! [`VolumeFile::stream_grid`] reads an OpenVDB grid without building its
//! tree: its topology first ([`Topology`]: tiles, leaf origins, counts,
//! bounds), then [`GridStream::decode_leaves`] decodes the leaf buffers in
//! parallel chunks into a [`LeafSink`] (the brick converter, statistics).
//! [`VolumeFile::grid_header`] reads a grid's metadata, transform and
//! background and nothing else.
//!
//! Every size read from a file is checked against the bytes that remain
//! before it is used, and every failure is an [`Error`] naming the file.

mod bytes;
mod coord;
mod error;
mod file;
mod grid;
mod mask;
mod metadata;
mod nanovdb;
mod openvdb;
mod source;
mod transform;
pub mod tree;
mod value;

pub use coord::{Coord, CoordBBox};
pub use error::{Error, ErrorKind, Result};
pub use file::{Format, GridBounds, GridHeader, VolumeFile};
pub use grid::{Grid, GridClass, GridInfo, GridTree};
pub use mask::BitMask;
pub use metadata::{meta_get, MetaMap, MetaValue};
pub use openvdb::stream::{ActiveTile, DecodeError, GridStream, LeafSink, Topology};
pub use transform::{MapKind, Transform};
pub use tree::{Accessor, Level, NodeCounts, TileCounts, Tree, ValueRange};
pub use value::{Value, ValueType};
