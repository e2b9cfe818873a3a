//! Converting a float grid's tree into bricks: leaves become stored or
//! constant bricks, tiles become constant bricks, then the bounds pyramid is
//! built over what was stored (so it bounds the values the renderer reads,
//! after quantisation). Trees and streamed files share one builder
//! (`build.rs`): stored bricks are numbered in leaf order, constants in
//! map order.

use crate::build::{write_leaves, Builder, Start};
use crate::density_grid::{require_density, require_float};
use crate::layout::Precision;
use crate::volume::BrickVolume;
use crate::BrickError;
use cirrus_vdb::{Grid, Tree};

/// Converts a fog-volume (or unknown-class) float grid into bricks.
///
/// Density policy: inactive voxels are the background, which must be 0;
/// NaN, infinite and negative values are stored as 0 and counted in
/// [`SourceInfo::sanitized_voxels`]. Level sets are refused: their values
/// are distances, not densities.
pub fn convert(grid: &Grid, precision: Precision) -> Result<BrickVolume, BrickError> {
    let tree = grid.float_tree();
    require_float(&grid.name, tree.is_some(), grid.tree.value_type().name())?;
    let tree = tree.expect("checked: a float grid");
    require_density(&grid.name, grid.class, tree.background())?;
    let mut volume = convert_tree(tree, precision)?;
    volume.index_to_world = grid.transform.index_to_world_matrix();
    volume.info.grid_name = grid.name.clone();
    Ok(volume)
}

/// Converts a float tree (any class, background 0) into bricks: the
/// same volume, bit for bit, as [`crate::convert_file`] streams from the
/// tree's file.
pub fn convert_tree(tree: &Tree<f32>, precision: Precision) -> Result<BrickVolume, BrickError> {
    let leaves = tree.leaves();
    let mut b = match Builder::start(
        tree.active_bbox(),
        tree.active_voxel_count(),
        leaves.len(),
        precision,
    )? {
        Start::Empty(v) => return Ok(v),
        Start::Build(b) => b,
    };
    let mut tiles = Ok(());
    tree.for_each_active_tile(|bbox, v, _| {
        if tiles.is_ok() {
            tiles = b.tile(bbox, v);
        }
    });
    tiles?;
    b.place_leaves(leaves.iter().map(|l| l.origin));
    write_leaves(b.sink(), leaves.len(), |i| {
        (&leaves[i].value_mask, &*leaves[i].values)
    })?;
    b.finish()
}
