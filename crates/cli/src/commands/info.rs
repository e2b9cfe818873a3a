//! `cirrus info FILE [--json]`: the grids of a file, as a table or JSON.

use super::CliResult;
use cirrus_vdb::{Grid, GridInfo, VolumeFile};
use serde_json::{json, Value as Json};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct InfoArgs {
    /// A .vdb or .nvdb file.
    pub file: PathBuf,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &InfoArgs) -> CliResult {
    if args.file.extension().is_some_and(|e| e == "cbrk") {
        return run_cbrk(args);
    }
    let file = VolumeFile::open(&args.file)?;
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
    let report = json!({
        "file": args.file.display().to_string(),
        "format": file.format().name(),
        "file_version": file.file_version(),
        "library_version": file.library_version().map(|(a, b)| format!("{a}.{b}")),
        "metadata": metadata_json(file.metadata()),
        "grids": grids,
    });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_table(&report);
    }
    Ok(())
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

fn print_table(r: &Json) {
    println!(
        "{} ({}{})",
        r["file"].as_str().unwrap_or(""),
        r["format"].as_str().unwrap_or(""),
        r["file_version"]
            .as_u64()
            .map_or(String::new(), |v| format!(" version {v}"))
    );
    for (k, v) in r["metadata"].as_object().into_iter().flatten() {
        println!("  {k}: {v}");
    }
    for g in r["grids"].as_array().into_iter().flatten() {
        println!();
        if let Some(e) = g.get("error") {
            println!("{}  ({})  error: {}", g["name"], g["type_name"], e);
            continue;
        }
        println!("{}", g["name"].as_str().unwrap_or(""));
        let rows = [
            (
                "type",
                format!(
                    "{} {}{}",
                    g["value_type"],
                    g["class"],
                    if g["half_float"] == true {
                        " (half)"
                    } else {
                        ""
                    }
                ),
            ),
            ("active voxels", g["active_voxels"].to_string()),
            (
                "leaves / tiles",
                format!("{} / {}", g["leaf_count"], g["tile_count"]),
            ),
            ("index bbox", g["index_bbox"].to_string()),
            ("voxel size", g["voxel_size"].to_string()),
            ("transform", g["transform"].to_string()),
            ("min / max", format!("{} / {}", g["min"], g["max"])),
            (
                "memory",
                format!(
                    "{} bytes in memory, {} in the file",
                    g["memory_bytes"], g["file_bytes"]
                ),
            ),
        ];
        for (k, v) in rows {
            println!("  {k:<15} {}", v.replace('"', ""));
        }
    }
}

/// `cirrus info OUT.cbrk`: what the conversion kept and what it costs.
fn run_cbrk(args: &InfoArgs) -> CliResult {
    let v = cirrus_bricks::read_cbrk(&args.file)?;
    let (map, tables, atlas, levels) = v.memory_bytes();
    let i = &v.info;
    let report = json!({
        "file": args.file.display().to_string(),
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
    });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!(
            "{} (cbrk, grid {:?}, {} precision)",
            args.file.display(),
            i.grid_name,
            v.precision().name()
        );
        println!("  active voxels    {}", i.active_voxels);
        println!(
            "  bricks           {} stored, {} constant, {} skipped (empty)",
            i.bricks_stored, i.bricks_constant, i.bricks_empty
        );
        println!("  max error        {:e}", i.max_error);
        println!("  bytes            map {map}, tables {tables}, atlas {atlas}, levels {levels:?}, total {}", v.total_bytes());
    }
    Ok(())
}
