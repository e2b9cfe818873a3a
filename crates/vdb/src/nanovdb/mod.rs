//! The NanoVDB file format (`.nvdb`). Placeholder until the reader lands.

use crate::error::{unsupported, KindResult};
use crate::grid::{Grid, GridInfo};
use crate::source::FileSource;

/// The first eight bytes of NanoVDB file segments: "NanoVDB0" (NanoVDB
/// 32.x up to 32.5) and "NanoVDB2" (32.6 and later, OpenVDB 11+).
pub const MAGICS: [&[u8; 8]; 2] = [b"NanoVDB0", b"NanoVDB2"];

/// The grids of a NanoVDB file and where each one's data sits.
#[derive(Clone, Debug)]
pub struct NanoIndex {
    pub grids: Vec<GridInfo>,
}

impl NanoIndex {
    pub fn open(_src: &FileSource) -> KindResult<NanoIndex> {
        Err(unsupported("NanoVDB files (reader not built yet)"))
    }

    pub fn read_grid(&self, _src: &FileSource, _index: usize) -> KindResult<Grid> {
        Err(unsupported("NanoVDB files (reader not built yet)"))
    }
}
