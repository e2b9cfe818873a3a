//! What makes a grid a density a conversion accepts, checked once for the
//! tree converter and the file streamer alike: float values, not a level
//! set (whose values are distances), background 0.

use crate::BrickError;
use cirrus_vdb::GridClass;

/// Refuses a grid of another value type than float (`type_name`).
pub(crate) fn require_float(grid: &str, float: bool, type_name: &str) -> Result<(), BrickError> {
    if float {
        return Ok(());
    }
    Err(BrickError::Unsupported(format!(
        "grid {grid:?} holds {type_name} values; only float grids convert"
    )))
}

/// Refuses a level set and a non-zero background.
pub(crate) fn require_density(
    grid: &str,
    class: GridClass,
    background: f32,
) -> Result<(), BrickError> {
    if class == GridClass::LevelSet {
        return Err(BrickError::Unsupported(format!(
            "grid {grid:?} is a level set (signed distances, not density); convert it to a fog volume first"
        )));
    }
    if background != 0.0 {
        return Err(BrickError::Unsupported(format!(
            "grid {grid:?} has background {background}; a density grid needs background 0"
        )));
    }
    Ok(())
}
