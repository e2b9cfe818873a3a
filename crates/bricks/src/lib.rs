//! Sparse bricks of density with a hierarchy of majorants and minorants:
//! what the renderer's trackers walk.
//!
//! The pipeline: [`convert_file`] streams a float grid from its file (or
//! [`convert`] takes a grid's tree from `cirrus-vdb`) into a
//! [`BrickVolume`], both through one builder (`build.rs`, `stream.rs`): a
//! dense map of 8^3 bricks (`layout.rs`: empty,
//! constant, or stored at f32, f16 or u8), a voxel atlas, and a pyramid of
//! (min, max) bounds per brick and per coarser cell (`bounds.rs`) that bound
//! the trilinearly interpolated density. [`SegmentIter`] (`dda.rs`) walks a
//! ray through the pyramid front to back, skipping empty space at the
//! coarsest level and yielding [`MajorantSegment`]s with tight bounds, over the
//! cells of a [`CellPartition`] (`partition.rs`) fixed once per refinement rule;
//! [`BrickVolume::trilinear`] is the density lookup. A ray march needs
//! no bounds, only where density is: [`BrickVolume::march_occupied`]
//! (`lattice.rs`) visits the points of a jittered [`Lattice`] cell by cell
//! over a partition's occupied cells. `format.rs` writes and
//! memory-maps the `.cbrk` file of a converted volume. For motion blur,
//! [`VelocityGrid`] (`velocity.rs`) stores a vec3 velocity grid and
//! [`BrickVolume::motion_shell`] (`dilate.rs`) dilates the bounds pyramid
//! so it bounds the density over a whole shutter. [`Bounds3`] and
//! [`DBounds3`] (`aabb.rs`) are the box types of the whole workspace.

mod aabb;
mod bounds;
mod build;
mod cell_bounds;
mod convert;
mod dda;
mod density_grid;
mod dilate;
mod f16;
mod format;
mod lattice;
mod layout;
mod partition;
mod section;
mod segment;
mod stages;
mod stream;
mod velocity;
mod volume;
mod voxel_of;

pub use aabb::{Bounds3, DBounds3};
pub use bounds::{BoundsLevel, CELL_LOG2, MAX_LEVELS};
pub use convert::{convert, convert_tree};
pub use dda::SegmentIter;
pub use format::{read_cbrk, write_cbrk};
pub use lattice::Lattice;
pub use layout::{BrickRef, Precision, BRICK, BRICK_LOG2, BRICK_VOXELS, MAX_MAP_BRICKS};
pub use partition::{Cell, CellPartition, TIGHT_ENOUGH};
pub use section::Section;
pub use segment::MajorantSegment;
pub use stream::{convert_file, RENDER_PRECISION};
pub use velocity::VelocityGrid;
pub use volume::{Atlas, BrickVolume, SourceInfo};

/// Why a conversion or a `.cbrk` load failed.
#[derive(Debug, thiserror::Error)]
pub enum BrickError {
    #[error("unsupported: {0}")]
    Unsupported(String),
    #[error("too large: {0}")]
    TooLarge(String),
    /// A stored brick's density exceeds f16's largest value.
    #[error("density {0} does not fit in f16 (max 65504); use f32")]
    F16Overflow(f32),
    #[error("{path}: {msg}")]
    File {
        path: std::path::PathBuf,
        msg: String,
    },
    #[error(transparent)]
    Vdb(#[from] cirrus_vdb::Error),
}
