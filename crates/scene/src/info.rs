//! The report of `cirrus info --json` (and of Python's `cirrus.open`): a
//! file's grids with their types, counts, boxes, transforms and value
//! ranges, computed from the grid data; for a `.cbrk`, what the
//! conversion kept and what it costs.

use std::path::Path;

use cirrus_vdb::{Grid, GridInfo, VolumeFile};
use serde_json::{json, Value as Json};

use crate::error::{Error, Result};
use crate::grids::is_cbrk;

/// The report of a `.vdb`, `.nvdb` or `.cbrk` file.
pub fn file_report(path: &Path) -> Result<Json> {
    if is_cbrk(path) {
        return cbrk_report(path);
    }
    let file = VolumeFile::open(path)?;
    let mut grids = Vec::new();
    for (i, info) in file.grids().into_iter().enumerate() {
        // A grid of a type the reader does not decode is listed with its error.
        grids.push(match file.read_grid(i) {
            Ok(grid) => grid_json(info, &grid),
            Err(e) => {
                json!({"name": info.name, "type_name": info.type_name, "error": e.kind.to_string()})
            }
        });
    }
    Ok(json!({
        "file": path.display().to_string(),
        "format": file.format().name(),
        "file_version": file.file_version(),
        "library_version": file.library_version().map(|(a, b)| format!("{a}.{b}")),
        "metadata": metadata_json(file.metadata()),
        "grids": grids,
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

fn grid_json(info: &GridInfo, grid: &Grid) -> Json {
    let tree = &grid.tree;
    let range = tree.value_range();
    let tiles = tree.active_tile_counts();
    let (bg, bgn) = tree.background_components();
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
