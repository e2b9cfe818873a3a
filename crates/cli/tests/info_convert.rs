//! The `cirrus` binary end to end: `info --json` against the manifest the
//! Debian tools wrote, `convert` and `info` of the result, and bad input.

mod common;

use common::{cirrus, root};
use serde_json::Value;
use std::path::Path;
use std::process::Command;

#[test]
fn info_json_agrees_with_the_manifest() {
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("data/manifest.json")).unwrap())
            .unwrap();
    let mut compared = 0;
    for name in [
        "cloud.vdb",
        "multi_grid.vdb",
        "leaf_tiles.vdb",
        "sphere_fog.nvdb",
        "empty_grid.vdb",
    ] {
        let entry = manifest["files"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["file"] == name)
            .unwrap();
        let (ok, stdout, stderr) = cirrus(&["info", &format!("data/{name}"), "--json", "--stats"]);
        assert!(ok, "{name}: {stderr}");
        let info: Value = serde_json::from_str(&stdout).unwrap();
        assert_eq!(info["format"], entry["format"], "{name}");
        let grids = info["grids"].as_array().unwrap();
        for (ours, theirs) in grids.iter().zip(entry["grids"].as_array().unwrap()) {
            for key in [
                "name",
                "active_voxels",
                "leaf_count",
                "index_bbox",
                "value_type",
                "class",
            ] {
                assert_eq!(ours[key], theirs[key], "{name} {key}");
            }
            let tiles: u64 = theirs["active_tile_count"]
                .as_array()
                .unwrap()
                .iter()
                .map(|t| t.as_u64().unwrap())
                .sum();
            assert_eq!(
                ours["tile_count"].as_u64(),
                Some(tiles),
                "{name} tile_count"
            );
            compared += 1;
        }
    }
    assert!(compared >= 8);
}

#[test]
fn convert_writes_a_cbrk_that_info_reads() {
    let out = std::env::temp_dir().join(format!("cirrus-cli-{}.cbrk", std::process::id()));
    let out_s = out.to_str().unwrap();
    let (ok, _, stderr) = cirrus(&[
        "convert",
        "data/multi_grid.vdb",
        "--grid",
        "density",
        "--precision",
        "u8",
        "-o",
        out_s,
    ]);
    assert!(ok, "{stderr}");
    let (ok, stdout, stderr) = cirrus(&["info", out_s, "--json"]);
    assert!(ok, "{stderr}");
    let info: Value = serde_json::from_str(&stdout).unwrap();
    std::fs::remove_file(&out).unwrap();
    assert_eq!(info["precision"], "u8");
    assert_eq!(info["grid"], "density");
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(root().join("data/manifest.json")).unwrap())
            .unwrap();
    let entry = manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["file"] == "multi_grid.vdb")
        .unwrap();
    let density = entry["grids"]
        .as_array()
        .unwrap()
        .iter()
        .find(|g| g["name"] == "density")
        .unwrap();
    assert_eq!(info["active_voxels"], density["active_voxels"]);
    let stored = info["bricks_stored"].as_u64().unwrap();
    assert!(stored > 0 && stored <= density["leaf_count"].as_u64().unwrap());
}

#[test]
fn bad_input_is_a_clear_error_naming_the_file() {
    let (ok, _, stderr) = cirrus(&["info", "data/manifest.json"]);
    assert!(
        !ok && stderr.contains("manifest.json")
            && stderr.contains("not an OpenVDB or NanoVDB file"),
        "{stderr}"
    );
    let (ok, _, stderr) = cirrus(&["info", "data/no_such_file.vdb"]);
    assert!(!ok && stderr.contains("no_such_file.vdb"), "{stderr}");
    let (ok, _, stderr) = cirrus(&[
        "convert",
        "data/level_set_sphere.vdb",
        "-o",
        "/tmp/never.cbrk",
    ]);
    assert!(!ok && stderr.contains("level set"), "{stderr}");
    assert!(!Path::new("/tmp/never.cbrk").exists());
    let (ok, _, stderr) = cirrus(&["info", "data/multi_grid.vdb", "--json", "--no-such-flag"]);
    assert!(!ok && stderr.contains("--no-such-flag"), "{stderr}");
}

#[test]
fn a_reader_that_closes_stdout_early_gets_a_quiet_exit_not_a_panic() {
    // The pipe's read end is closed before cirrus writes its first line,
    // as `cirrus info FILE | head -0` would.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_cirrus"))
        .args(["info", "data/multi_grid.vdb"])
        .current_dir(root())
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
        .wait_with_output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(141), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn info_speaks_plainly_and_a_missing_grid_lists_the_grids() {
    let (ok, out, err) = cirrus(&["info", "data/special_values.vdb"]);
    assert!(ok, "{err}");
    assert!(out.contains("  type            float\n"), "{out}");
    assert!(out.contains("  class           not set"), "{out}");
    assert!(
        !out.contains("unknown\n") || out.contains("GRID_UNKNOWN"),
        "{out}"
    );
    let (ok, out, _) = cirrus(&["info", "data/cloud.vdb"]);
    assert!(ok && out.contains("  class           fog volume"), "{out}");

    let cbrk = std::env::temp_dir().join(format!("cirrus-info-exact-{}.cbrk", std::process::id()));
    let c = cbrk.to_str().unwrap();
    let (ok, _, err) = cirrus(&["convert", "data/sphere_fog.vdb", "-o", c]);
    assert!(ok, "{err}");
    assert!(err.contains("max error 0, exact"), "{err}");
    let (ok, out, err) = cirrus(&["info", c]);
    assert!(ok, "{err}");
    assert!(out.contains("max error        0 (exact)"), "{out}");
    assert!(!out.contains("0e0"), "{out}");
    std::fs::remove_file(&cbrk).unwrap();

    for args in [
        &[
            "render",
            "data/multi_grid.vdb",
            "--grid",
            "smoke",
            "-o",
            "never.exr",
        ][..],
        &[
            "convert",
            "data/multi_grid.vdb",
            "--grid",
            "smoke",
            "-o",
            "never.cbrk",
        ],
    ] {
        let (ok, _, err) = cirrus(args);
        assert!(!ok, "{args:?}");
        assert!(
            err.contains(
                "multi_grid.vdb: no grid named \"smoke\" (grids: \"velocity\", \"density\""
            ),
            "{err}"
        );
    }
}
