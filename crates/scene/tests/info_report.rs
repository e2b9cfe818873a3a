//! `cirrus info` from the headers alone agrees with the data, and the
//! streamed statistics equal the reader's tree statistics, on every grid
//! of the corpus.

use cirrus_scene::info::file_report_with;
use cirrus_vdb::{GridTree, VolumeFile};
use serde_json::{json, Value as Json};
use std::path::PathBuf;

fn corpus() -> Vec<PathBuf> {
    cirrus_testkit::corpus(&["vdb", "nvdb"], None)
}

fn num(v: f64) -> Json {
    cirrus_scene::info::num(v)
}

fn comps(c: [f64; 3], n: usize) -> Json {
    if n == 1 {
        num(c[0])
    } else {
        Json::Array(c[..n].iter().map(|&v| num(v)).collect())
    }
}

#[test]
fn header_reports_agree_with_statistics_and_the_tree() {
    let mut grids = 0;
    for path in corpus() {
        let Ok(file) = VolumeFile::open(&path) else {
            continue;
        };
        let fast = file_report_with(&path, false).unwrap();
        let full = file_report_with(&path, true).unwrap();
        assert_eq!(fast["stats"], false);
        assert_eq!(full["stats"], true);
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let (fg, sg) = (
            fast["grids"].as_array().unwrap(),
            full["grids"].as_array().unwrap(),
        );
        assert_eq!(fg.len(), sg.len(), "{name}");
        for (i, (f, s)) in fg.iter().zip(sg).enumerate() {
            let at = format!("{name}:{}", f["name"]);
            let Ok(grid) = file.read_grid(i) else {
                assert!(f.get("error").is_some() && s.get("error").is_some(), "{at}");
                continue;
            };
            // What the headers say equals what the data says.
            for key in [
                "name",
                "value_type",
                "class",
                "half_float",
                "active_voxels",
                "index_bbox",
                "voxel_size",
                "transform",
                "index_to_world",
                "background",
                "file_bytes",
                "file_mem_bytes",
            ] {
                assert_eq!(f[key], s[key], "{at}: {key}");
            }
            for key in [
                "min",
                "max",
                "nan_voxels",
                "leaf_count",
                "tile_count",
                "tile_counts",
                "memory_bytes",
            ] {
                assert!(f[key].is_null(), "{at}: {key} without --stats");
            }
            // The statistics (streamed for OpenVDB) equal the tree's.
            let t = &grid.tree;
            let range = t.value_range();
            let tiles = t.active_tile_counts();
            assert_eq!(s["active_voxels"], json!(t.active_voxel_count()), "{at}");
            assert_eq!(s["leaf_count"], json!(t.leaf_count()), "{at}");
            assert_eq!(s["tile_count"], json!(tiles.total()), "{at}");
            assert_eq!(
                s["tile_counts"],
                json!({"lower": tiles.lower, "upper": tiles.upper, "root": tiles.root}),
                "{at}"
            );
            assert_eq!(
                s["min"],
                range.map_or(Json::Null, |r| comps(r.min, r.components)),
                "{at}"
            );
            assert_eq!(
                s["max"],
                range.map_or(Json::Null, |r| comps(r.max, r.components)),
                "{at}"
            );
            assert_eq!(
                s["nan_voxels"],
                json!(range.map_or(0, |r| r.nan_count)),
                "{at}"
            );
            assert_eq!(s["memory_bytes"], json!(t.memory_bytes()), "{at}");
            let (bg, n) = t.background_components();
            assert_eq!(s["background"], comps(bg, n), "{at}");
            if !matches!(t, GridTree::Bool(_) | GridTree::Mask(_)) {
                grids += 1;
            }
        }
    }
    assert!(grids >= 40, "{grids} grids");
}
