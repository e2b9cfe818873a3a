//! Which grid of a file is the density (or the velocity), and reading
//! one into bricks.

use std::path::Path;

use cirrus_bricks::{
    convert_file, read_cbrk, BrickError, BrickVolume, Precision, VelocityGrid, RENDER_PRECISION,
};
use cirrus_vdb::{GridInfo, GridTree, ValueType, VolumeFile};

use crate::error::{Error, Result};

/// The grid name looked for when none is given.
pub const DENSITY_GRID: &str = "density";
/// Velocity grids used when the shutter is open and none is named: the
/// first vec3 grid with one of these names (Houdini writes `vel` or
/// `velocity`, Blender's fluids `velocity`).
pub const VELOCITY_GRIDS: [&str; 3] = ["vel", "v", "velocity"];

/// The grid to render or convert: the one named, else "density", else
/// the first float grid.
pub fn choose_grid(file: &VolumeFile, name: Option<&str>) -> Result<usize> {
    if let Some(name) = name {
        return file
            .find_grid(name)
            .map_err(|e| Error::input(e.to_string()));
    }
    let grids = file.grids();
    let float = |g: &&GridInfo| g.value_type == Some(ValueType::Float);
    grids
        .iter()
        .position(|g| g.name == DENSITY_GRID && float(g))
        .or_else(|| grids.iter().position(float))
        .ok_or_else(|| {
            let names: Vec<String> = grids
                .iter()
                .map(|g| format!("{} ({})", g.name, g.type_name))
                .collect();
            Error::input(format!(
                "{}: no float grid to use (grids: {})",
                file.path().display(),
                names.join(", ")
            ))
        })
}

/// Grid `index` of an open file as f32 bricks, streamed from the file
/// (never into the reader's tree).
pub fn read_bricks(file: &VolumeFile, index: usize) -> Result<BrickVolume> {
    read_bricks_at(file, index, Precision::F32)
}

/// Grid `index` of an open file as bricks at `precision`, streamed.
pub fn read_bricks_at(
    file: &VolumeFile,
    index: usize,
    precision: Precision,
) -> Result<BrickVolume> {
    convert_file(file, index, precision).map_err(|e| brick_error(file, e))
}

/// Grid `index` as a render keeps it: [`RENDER_PRECISION`] (f16), or f32
/// when its densities do not fit in f16.
pub fn read_render_bricks(file: &VolumeFile, index: usize) -> Result<BrickVolume> {
    match convert_file(file, index, RENDER_PRECISION) {
        Err(BrickError::F16Overflow(_)) => convert_file(file, index, Precision::F32),
        r => r,
    }
    .map_err(|e| brick_error(file, e))
}

/// The reader's errors name the file already; the converter's get its name.
fn brick_error(file: &VolumeFile, e: BrickError) -> Error {
    match e {
        BrickError::Vdb(e) => e.into(),
        e => Error::input(format!("{}: {e}", file.path().display())),
    }
}

/// A `.cbrk` file, whole.
pub fn read_cbrk_file(path: &Path) -> Result<BrickVolume> {
    // The format's errors name the file already.
    read_cbrk(path).map_err(|e| Error::file(e.to_string()))
}

/// The density volume of a `.vdb`/`.nvdb` (streamed into bricks at
/// [`RENDER_PRECISION`], f16, see [`read_render_bricks`]) or a `.cbrk` (at
/// the precision it was converted at), and the bytes read from disk for it
/// (a `.cbrk` counts whole).
pub fn load_volume(path: &Path, grid: Option<&str>) -> Result<(BrickVolume, u64)> {
    if is_cbrk(path) {
        let bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
        return Ok((read_cbrk_file(path)?, bytes));
    }
    let f = VolumeFile::open(path)?;
    let index = choose_grid(&f, grid)?;
    let volume = read_render_bricks(&f, index)?;
    Ok((volume, f.bytes_read()))
}

pub fn is_cbrk(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "cbrk")
}

/// The velocity grid of a moving volume: the one named (which must be a
/// vec3 grid), else the first vec3 grid named `vel`, `v` or `velocity`
/// ([`VELOCITY_GRIDS`]), else none.
pub fn choose_velocity(file: &VolumeFile, name: Option<&str>) -> Result<Option<usize>> {
    let grids = file.grids();
    let vec3 = |g: &GridInfo| matches!(g.value_type, Some(ValueType::Vec3f | ValueType::Vec3d));
    let Some(name) = name else {
        let by_name = |n: &str| grids.iter().position(|g| g.name == n && vec3(g));
        return Ok(VELOCITY_GRIDS.iter().find_map(|n| by_name(n)));
    };
    let index = file
        .find_grid(name)
        .map_err(|e| Error::input(e.to_string()))?;
    let g = grids[index];
    if !vec3(g) {
        return Err(Error::input(format!(
            "{}: grid {name:?} is {} ({}); a velocity grid must be vec3 (vec3s or vec3d)",
            file.path().display(),
            g.value_type.map_or("unsupported", |t| t.name()),
            g.type_name
        )));
    }
    Ok(Some(index))
}

/// Grid `index` of an open file (a vec3 grid) as a [`VelocityGrid`].
pub fn read_velocity(file: &VolumeFile, index: usize) -> Result<VelocityGrid> {
    let grid = file.read_grid(index)?;
    let m = grid.transform.index_to_world_matrix();
    let built = match &grid.tree {
        GridTree::Vec3f(t) => VelocityGrid::from_tree(&grid.name, t, m, |v| v),
        GridTree::Vec3d(t) => VelocityGrid::from_tree(&grid.name, t, m, |v| v.map(|c| c as f32)),
        other => {
            return Err(Error::input(format!(
                "{}: grid {:?} is {}; a velocity grid must be vec3 (vec3s or vec3d)",
                file.path().display(),
                grid.name,
                other.value_type().name()
            )))
        }
    };
    built.map_err(|e| {
        Error::input(format!(
            "{}: grid {:?}: {e}",
            file.path().display(),
            grid.name
        ))
    })
}
