//! A grid straight from its file into bricks, never holding the reader's
//! tree: `.vdb` grids stream (topology, then leaf buffers decoded in
//! parallel chunks into their atlas slots, see `build.rs`); `.nvdb` grids
//! are read whole and converted.

use crate::build::{Builder, Start};
use crate::convert::convert;
use crate::density_grid::{require_density, require_float};
use crate::layout::Precision;
use crate::stages::Stages;
use crate::volume::BrickVolume;
use crate::BrickError;
use cirrus_vdb::{DecodeError, Format, ValueType, VolumeFile};

/// The precision a render straight from a `.vdb` or `.nvdb` keeps its
/// stored bricks at. f16 halves the atlas against f32; its rounding error
/// is at most 2^-11 of a density (2^-25 absolute below 2^-14), so the
/// extinction it renders is within 0.05% of the file's everywhere, far
/// below the noise of any render (BENCHMARKS.md, "Production scale").
/// A volume whose stored densities exceed f16's range (65504) falls back
/// to f32 ([`BrickError::F16Overflow`]).
pub const RENDER_PRECISION: Precision = Precision::F16;

/// Converts grid `index` of an open file into bricks at `precision`: the
/// same volume, bit for bit, as [`convert`] of the grid read whole, without
/// building the reader's tree for an OpenVDB file. Refuses what `convert`
/// refuses (grids that are not float, level sets, a background other
/// than 0) before reading any voxel.
pub fn convert_file(
    file: &VolumeFile,
    index: usize,
    precision: Precision,
) -> Result<BrickVolume, BrickError> {
    let info = file.grids().get(index).map(|g| (*g).clone());
    let Some(info) = info.filter(|_| file.format() == Format::OpenVdb) else {
        // NanoVDB (or an index the reader refuses with its own error).
        return convert(&file.read_grid(index)?, precision);
    };
    require_float(
        &info.name,
        info.value_type == Some(ValueType::Float),
        info.value_type
            .map_or(info.type_name.as_str(), |t| t.name()),
    )?;
    let clock = Stages::start();
    let mut stream = file.stream_grid::<f32>(index)?;
    clock.lap("topology");
    require_density(&stream.name, stream.class, stream.topology.background)?;
    let (name, transform) = (stream.name.clone(), stream.transform);
    let topo = &mut stream.topology;
    let mut volume = match Builder::start(
        topo.active_bbox,
        topo.active_voxels,
        topo.leaf_origins.len(),
        precision,
    )? {
        Start::Empty(v) => v,
        Start::Build(mut b) => {
            for t in &topo.tiles {
                b.tile(t.bbox, t.value)?;
            }
            b.place_leaves(topo.leaf_origins.iter().copied());
            // The map holds where every leaf goes now.
            topo.tiles = Vec::new();
            topo.leaf_origins = Vec::new();
            clock.lap("tiles and leaf places");
            stream.decode_leaves(b.sink()).map_err(|e| match e {
                DecodeError::File(e) => BrickError::Vdb(e),
                DecodeError::Sink(e) => e,
            })?;
            clock.lap("leaves decoded and written");
            b.finish_timed(&clock)?
        }
    };
    volume.index_to_world = transform.index_to_world_matrix();
    volume.info.grid_name = name;
    Ok(volume)
}
