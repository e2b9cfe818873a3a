//! The report of `cirrus info --json` (and of Python's `cirrus.open`): a
//! file's grids with their types, counts, boxes, transforms and value
//! ranges; for a `.cbrk`, what the conversion kept and what it costs.
//!
//! Without statistics the report reads only headers: for an OpenVDB file
//! the grid descriptors and each grid's metadata, transform and background
//! (`file_voxel_count`, `file_bbox_min`/`max`, `class`, ... as OpenVDB
//! writes them), never a voxel; the fields only the data can give (`min`,
//! `max`, `nan_voxels`, `leaf_count`, `tile_count`, `tile_counts`,
//! `memory_bytes`) are null. With statistics every grid is read: OpenVDB
//! grids are streamed (topology, then leaf buffers decoded in parallel)
//! without building the reader's tree.

use std::path::Path;
use std::sync::Mutex;

use cirrus_vdb::{
    meta_get, BitMask, DecodeError, Format, Grid, GridInfo, LeafSink, MetaValue, Value, ValueRange,
    ValueType, VolumeFile,
};
use serde_json::{json, Value as Json};

use crate::error::{Error, Result};
use crate::grids::is_cbrk;

/// The report of a `.vdb`, `.nvdb` or `.cbrk` file, statistics included.
pub fn file_report(path: &Path) -> Result<Json> {
    file_report_with(path, true)
}

/// The report of a file; `stats` computes the fields only the grid data
/// can give (null without it). See the module doc.
pub fn file_report_with(path: &Path, stats: bool) -> Result<Json> {
    if is_cbrk(path) {
        return cbrk_report(path);
    }
    let file = VolumeFile::open(path)?;
    let mut grids = Vec::new();
    for (i, info) in file.grids().into_iter().enumerate() {
        // A grid of a type the reader does not decode is listed with its error.
        let report = if file.format() == Format::OpenVdb && info.value_type.is_none() {
            Err(format!("unsupported grid type {}", info.type_name))
        } else if file.format() == Format::OpenVdb && !stats {
            header_json(&file, i, info)
        } else if file.format() == Format::OpenVdb && info.value_type.is_some_and(streams) {
            streamed_json(&file, i, info)
        } else {
            file.read_grid(i)
                .map(|grid| grid_json(info, &grid, stats))
                .map_err(|e| e.kind.to_string())
        };
        grids.push(report.unwrap_or_else(
            |e| json!({"name": info.name, "type_name": info.type_name, "error": e}),
        ));
    }
    Ok(json!({
        "file": path.display().to_string(),
        "format": file.format().name(),
        "file_version": file.file_version(),
        "library_version": file.library_version().map(|(a, b)| format!("{a}.{b}")),
        "stats": stats,
        "metadata": metadata_json(file.metadata()),
        "grids": grids,
    }))
}

/// Value types whose OpenVDB leaves stream (bool and mask leaves do not).
fn streams(t: ValueType) -> bool {
    !matches!(t, ValueType::Bool | ValueType::Mask)
}

/// What a grid's header says: the report without statistics.
fn header_json(file: &VolumeFile, i: usize, info: &GridInfo) -> std::result::Result<Json, String> {
    let h = file
        .grid_header(i)
        .map_err(|e| e.kind.to_string())?
        .ok_or("no grid header")?;
    let int = |key| meta_int(&h.metadata, key);
    let vec3i = |key| match meta_get(&h.metadata, key) {
        Some(MetaValue::Vec3i(v)) => Some(*v),
        _ => None,
    };
    // OpenVDB writes an empty grid's box inside out (min > max).
    let bbox = vec3i("file_bbox_min")
        .zip(vec3i("file_bbox_max"))
        .filter(|(lo, hi)| (0..3).all(|k| lo[k] <= hi[k]))
        .map(|(lo, hi)| json!([lo, hi]));
    let t = &h.transform;
    Ok(json!({
        "name": info.name,
        "value_type": info.value_type.map(|v| v.name()).unwrap_or_default(),
        "class": h.class.name(),
        "half_float": info.half_float,
        "active_voxels": int("file_voxel_count"),
        "leaf_count": null,
        "tile_count": null,
        "tile_counts": null,
        "index_bbox": bbox,
        "voxel_size": t.voxel_size().to_array(),
        "transform": t.kind.name(),
        "index_to_world": t.index_to_world_matrix().transpose().to_cols_array_2d(),
        "background": h.background.map(|(c, n)| components(c, n)),
        "min": null,
        "max": null,
        "nan_voxels": null,
        "memory_bytes": null,
        "file_mem_bytes": int("file_mem_bytes"),
        "file_bytes": info.byte_len,
    }))
}

/// An integer metadata value.
fn meta_int(meta: &cirrus_vdb::MetaMap, key: &str) -> Option<i64> {
    match meta_get(meta, key) {
        Some(MetaValue::Int64(v)) => Some(*v),
        Some(MetaValue::Int32(v)) => Some(*v as i64),
        _ => None,
    }
}

/// Statistics of one streamed grid, whatever its value type.
fn streamed_json(
    file: &VolumeFile,
    i: usize,
    info: &GridInfo,
) -> std::result::Result<Json, String> {
    match info.value_type {
        Some(ValueType::Float) => stream_stats::<f32>(file, i, info),
        Some(ValueType::Double) => stream_stats::<f64>(file, i, info),
        Some(ValueType::Int32) => stream_stats::<i32>(file, i, info),
        Some(ValueType::Int64) => stream_stats::<i64>(file, i, info),
        Some(ValueType::Vec3f) => stream_stats::<[f32; 3]>(file, i, info),
        Some(ValueType::Vec3d) => stream_stats::<[f64; 3]>(file, i, info),
        _ => Err("grid type does not stream".into()),
    }
}

/// Minimum, maximum and NaN count of active values, as
/// `Tree::value_range` computes them, over the leaves of one chunk.
struct RangeSink<'a> {
    range: Option<ValueRange>,
    nan: u64,
    out: &'a Mutex<Vec<(Option<ValueRange>, u64)>>,
}

impl RangeSink<'_> {
    #[inline]
    fn add(&mut self, c: [f64; 3], k: usize) {
        if !ValueRange::include(&mut self.range, c, k) {
            self.nan += 1;
        }
    }
}

impl<V: Value> LeafSink<V> for RangeSink<'_> {
    type Error = std::convert::Infallible;
    fn split_front(&mut self, _: usize) -> Self {
        RangeSink {
            range: None,
            nan: 0,
            out: self.out,
        }
    }
    fn leaf(
        &mut self,
        _: usize,
        mask: &BitMask<8>,
        values: &[V; 512],
    ) -> std::result::Result<(), Self::Error> {
        for n in mask.iter_on() {
            let (c, k) = values[n].components();
            self.add(c, k);
        }
        Ok(())
    }
    fn finish(self) {
        let mut out = self.out.lock().unwrap_or_else(|e| e.into_inner());
        out.push((self.range, self.nan));
    }
}

fn stream_stats<V: Value>(
    file: &VolumeFile,
    i: usize,
    info: &GridInfo,
) -> std::result::Result<Json, String> {
    let stream = file.stream_grid::<V>(i).map_err(|e| e.kind.to_string())?;
    let (class, transform) = (stream.class, stream.transform);
    let file_mem_bytes = meta_int(&stream.metadata, "file_mem_bytes");
    let topo = &stream.topology;
    let tiles = topo.tile_counts();
    let (bbox, active, memory) = (topo.active_bbox, topo.active_voxels, topo.memory_bytes());
    let (bg, bgn) = topo.background.components();
    let leaf_count = topo.leaf_origins.len();
    let parts = Mutex::new(Vec::new());
    let mut tile_range = RangeSink {
        range: None,
        nan: 0,
        out: &parts,
    };
    for t in &topo.tiles {
        let (c, k) = t.value.components();
        tile_range.add(c, k);
    }
    <RangeSink as LeafSink<V>>::finish(tile_range);
    let sink = RangeSink {
        range: None,
        nan: 0,
        out: &parts,
    };
    stream.decode_leaves(sink).map_err(|e| match e {
        DecodeError::File(e) => e.kind.to_string(),
        DecodeError::Sink(e) => match e {},
    })?;
    let (mut range, mut nan) = (None::<ValueRange>, 0);
    for (r, n) in parts.into_inner().unwrap_or_else(|e| e.into_inner()) {
        nan += n;
        range = match (range, r) {
            (Some(mut a), Some(b)) => {
                for k in 0..a.components {
                    a.min[k] = a.min[k].min(b.min[k]);
                    a.max[k] = a.max[k].max(b.max[k]);
                }
                Some(a)
            }
            (a, b) => a.or(b),
        };
    }
    Ok(json!({
        "name": info.name,
        "value_type": V::VALUE_TYPE.name(),
        "class": class.name(),
        "half_float": info.half_float,
        "active_voxels": active,
        "leaf_count": leaf_count,
        "tile_count": tiles.total(),
        "tile_counts": {"lower": tiles.lower, "upper": tiles.upper, "root": tiles.root},
        "index_bbox": bbox.map(|b| json!([b.min.to_array(), b.max.to_array()])),
        "voxel_size": transform.voxel_size().to_array(),
        "transform": transform.kind.name(),
        "index_to_world": transform.index_to_world_matrix().transpose().to_cols_array_2d(),
        "background": components(bg, bgn),
        "min": range.map(|r| components(r.min, r.components)),
        "max": range.map(|r| components(r.max, r.components)),
        // As Tree::value_range: counted beside a range of other values.
        "nan_voxels": if range.is_some() { nan } else { 0 },
        "memory_bytes": memory,
        "file_mem_bytes": file_mem_bytes,
        "file_bytes": info.byte_len,
    }))
}

/// A float for JSON: NaN and infinities as the strings "nan", "inf", "-inf".
pub fn num(v: f64) -> Json {
    if v.is_nan() {
        json!("nan")
    } else if v.is_infinite() {
        json!(if v > 0.0 { "inf" } else { "-inf" })
    } else {
        json!(v)
    }
}

fn components(c: [f64; 3], n: usize) -> Json {
    if n == 1 {
        num(c[0])
    } else {
        Json::Array(c[..n].iter().map(|&v| num(v)).collect())
    }
}

/// The report of a grid read whole (NanoVDB grids, bool and mask grids);
/// without `stats`, only its active voxel count and box come from the data.
fn grid_json(info: &GridInfo, grid: &Grid, stats: bool) -> Json {
    let tree = &grid.tree;
    let (bg, bgn) = tree.background_components();
    let base = json!({
        "name": grid.name,
        "value_type": tree.value_type().name(),
        "class": grid.class.name(),
        "half_float": grid.half_float,
        "active_voxels": tree.active_voxel_count(),
        "leaf_count": null,
        "tile_count": null,
        "tile_counts": null,
        "index_bbox": tree.active_bbox().map(|b| json!([b.min.to_array(), b.max.to_array()])),
        "voxel_size": grid.transform.voxel_size().to_array(),
        "transform": grid.transform.kind.name(),
        "index_to_world": grid.transform.index_to_world_matrix().transpose().to_cols_array_2d(),
        "background": components(bg, bgn),
        "min": null,
        "max": null,
        "nan_voxels": null,
        "memory_bytes": null,
        "file_mem_bytes": meta_int(&grid.metadata, "file_mem_bytes"),
        "file_bytes": info.byte_len,
    });
    if !stats {
        return base;
    }
    let range = tree.value_range();
    let tiles = tree.active_tile_counts();
    json!({
        "name": grid.name,
        "value_type": tree.value_type().name(),
        "class": grid.class.name(),
        "half_float": grid.half_float,
        "active_voxels": tree.active_voxel_count(),
        "leaf_count": tree.leaf_count(),
        "tile_count": tiles.total(),
        "tile_counts": {"lower": tiles.lower, "upper": tiles.upper, "root": tiles.root},
        "index_bbox": tree.active_bbox().map(|b| json!([b.min.to_array(), b.max.to_array()])),
        "voxel_size": grid.transform.voxel_size().to_array(),
        "transform": grid.transform.kind.name(),
        "index_to_world": grid.transform.index_to_world_matrix().transpose().to_cols_array_2d(),
        "background": components(bg, bgn),
        "min": range.map(|r| components(r.min, r.components)),
        "max": range.map(|r| components(r.max, r.components)),
        "nan_voxels": range.map_or(0, |r| r.nan_count),
        "memory_bytes": tree.memory_bytes(),
        "file_mem_bytes": base["file_mem_bytes"],
        "file_bytes": info.byte_len,
    })
}

fn metadata_json(meta: &cirrus_vdb::MetaMap) -> Json {
    use cirrus_vdb::MetaValue::*;
    let mut m = serde_json::Map::new();
    for (k, v) in meta {
        let j = match v {
            String(s) => json!(s),
            Bool(b) => json!(b),
            Int32(i) => json!(i),
            Int64(i) => json!(i),
            Float(f) => num(*f as f64),
            Double(f) => num(*f),
            Vec3i(a) => json!(a),
            Vec3s(a) => json!(a.map(|x| x as f64)),
            Vec3d(a) => json!(a),
            Other { type_name, len } => json!(format!("<{type_name}, {len} bytes>")),
        };
        m.insert(k.clone(), j);
    }
    Json::Object(m)
}

/// What a `.cbrk` holds.
fn cbrk_report(path: &Path) -> Result<Json> {
    let v = cirrus_bricks::read_cbrk(path).map_err(|e| Error::file(e.to_string()))?;
    let (map, tables, atlas, levels) = v.memory_bytes();
    let i = &v.info;
    Ok(json!({
        "file": path.display().to_string(),
        "format": "cbrk",
        "grid": i.grid_name,
        "precision": v.precision().name(),
        "active_voxels": i.active_voxels,
        "bricks_stored": i.bricks_stored,
        "bricks_constant": i.bricks_constant,
        "bricks_skipped": i.bricks_empty,
        "brick_dims": v.dims,
        "index_origin": v.origin.to_array(),
        "max_error": num(i.max_error as f64),
        "sanitized_voxels": i.sanitized_voxels,
        "max_density": num(v.max_density() as f64),
        "bytes": {"map": map, "constants_and_ranges": tables, "atlas": atlas, "levels": levels, "total": v.total_bytes()},
    }))
}
