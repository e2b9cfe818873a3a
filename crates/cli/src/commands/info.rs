//! `cirrus info FILE [--json] [--stats]`: the grids of a file, as a table
//! or JSON; from the headers alone unless `--stats` reads the voxels.

use super::CliResult;
use cirrus_scene::info::file_report_with;
use serde_json::Value as Json;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct InfoArgs {
    /// A .vdb or .nvdb file.
    pub file: PathBuf,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Read the voxels for the value range, NaN count, leaf and tile
    /// counts and memory (without it: the headers alone, nothing decoded).
    #[arg(long)]
    pub stats: bool,
}

pub fn run(args: &InfoArgs) -> CliResult {
    let report = file_report_with(&args.file, args.stats)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else if report["format"] == "cbrk" {
        print_cbrk(&report);
    } else {
        print_table(&report);
    }
    Ok(())
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
        // Fields only the data gives are null without --stats.
        let or_stats = |v: String| {
            if v.contains("null") {
                "(--stats)".to_string()
            } else {
                v
            }
        };
        let rows = [
            (
                "type",
                format!(
                    "{}{}",
                    g["value_type"],
                    if g["half_float"] == true {
                        " (stored as half floats)"
                    } else {
                        ""
                    }
                ),
            ),
            ("class", class_of(&g["class"])),
            ("active voxels", g["active_voxels"].to_string()),
            (
                "leaves / tiles",
                or_stats(format!("{} / {}", g["leaf_count"], g["tile_count"])),
            ),
            ("index bbox", g["index_bbox"].to_string()),
            ("voxel size", g["voxel_size"].to_string()),
            ("transform", g["transform"].to_string()),
            (
                "min / max",
                or_stats(format!("{} / {}", g["min"], g["max"])),
            ),
            (
                "memory",
                if g["memory_bytes"].is_null() {
                    format!("{} bytes in the file", g["file_bytes"])
                } else {
                    format!(
                        "{} bytes in memory, {} in the file",
                        g["memory_bytes"], g["file_bytes"]
                    )
                },
            ),
        ];
        for (k, v) in rows {
            println!("  {k:<15} {}", v.replace('"', ""));
        }
    }
}

/// A grid's class as OpenVDB's `class` metadata says, or that it says none.
fn class_of(class: &Json) -> String {
    match class.as_str() {
        Some("unknown") | None => "not set (OpenVDB's GRID_UNKNOWN)".into(),
        Some(c) => c.into(),
    }
}

/// The largest absolute difference from the source's values.
fn max_error(e: &Json) -> String {
    match e.as_f64() {
        Some(0.0) => "0 (exact)".into(),
        Some(e) => format!("{e:.3e}"),
        None => e.to_string(),
    }
}

/// `cirrus info OUT.cbrk`: what the conversion kept and what it costs.
fn print_cbrk(r: &Json) {
    let b = &r["bytes"];
    println!(
        "{} (cbrk, grid {}, {} precision)",
        r["file"].as_str().unwrap_or(""),
        r["grid"],
        r["precision"].as_str().unwrap_or("")
    );
    println!("  active voxels    {}", r["active_voxels"]);
    println!(
        "  bricks           {} stored, {} constant, {} skipped (empty)",
        r["bricks_stored"], r["bricks_constant"], r["bricks_skipped"]
    );
    println!("  max error        {}", max_error(&r["max_error"]));
    println!(
        "  bytes            map {}, tables {}, atlas {}, levels {}, total {}",
        b["map"], b["constants_and_ranges"], b["atlas"], b["levels"], b["total"]
    );
}
