//! Scene files, crops and merges, and what `--stats` shows a scene costs,
//! through the `cirrus` binary.

mod common;

use common::{cirrus, root};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// A scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cirrus-scenes-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn stats(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn cropped_tiles_merge_bit_for_bit_into_the_full_render() {
    let d = scratch("crop");
    let common = [
        "render",
        "data/sphere_fog.vdb",
        "--res",
        "24x16",
        "--spp",
        "3",
        "--seed",
        "9",
        "--aov",
        "albedo,depth,emission,direct,samples",
    ];
    let full = d.join("full.exr");
    let (ok, _, err) = cirrus(&[&common[..], &["-o", s(&full)]].concat());
    assert!(ok, "{err}");
    // Three tiles of different shapes covering the image once.
    let crops = ["0,0,10,16", "10,0,24,9", "10,9,24,16"];
    let mut tiles = Vec::new();
    for (i, c) in crops.iter().enumerate() {
        let t = d.join(format!("tile{i}.exr"));
        let (ok, _, err) = cirrus(&[&common[..], &["--crop", c, "-o", s(&t)]].concat());
        assert!(ok, "{err}");
        let read = cirrus_render::exr_layers::read_channels(&t).unwrap();
        assert_eq!(read.full, (24, 16), "display window is the full image");
        tiles.push(t);
    }
    let merged = d.join("merged.exr");
    let mut args = vec!["merge", s(&merged)];
    args.extend(tiles.iter().map(|t| s(t)));
    let (ok, _, err) = cirrus(&args);
    assert!(ok, "{err}");
    let a = cirrus_render::exr_layers::read_channels(&full).unwrap();
    let b = cirrus_render::exr_layers::read_channels(&merged).unwrap();
    let names: Vec<&str> = a.channels.iter().map(|(n, _)| n.as_str()).collect();
    for n in [
        "A",
        "B",
        "G",
        "R",
        "albedo.R",
        "depth.Z",
        "direct.G",
        "emission.B",
        "samples.Y",
    ] {
        assert!(names.contains(&n), "channel {n} in {names:?}");
    }
    assert_eq!(a.size, b.size);
    for ((na, va), (nb, vb)) in a.channels.iter().zip(&b.channels) {
        assert_eq!(na, nb);
        let same = va.iter().zip(vb).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "channel {na} differs");
    }
    // Overlapping tiles are refused.
    let (ok, _, err) = cirrus(&["merge", s(&d.join("bad.exr")), s(&tiles[0]), s(&tiles[0])]);
    assert!(!ok && err.contains("two tiles"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn scene_file_errors_name_the_file_key_and_line() {
    let d = scratch("errors");
    let scene = d.join("bad.toml");
    std::fs::write(
        &scene,
        "[camera]\nfov = 30\n\n[[volume]]\nfile = \"x.vdb\"\ndensty = \"d\"\n",
    )
    .unwrap();
    let (ok, _, err) = cirrus(&["render", s(&scene), "-o", s(&d.join("o.exr"))]);
    assert!(!ok);
    assert!(
        err.contains("bad.toml") && err.contains("line 6") && err.contains("densty"),
        "{err}"
    );
    std::fs::write(&scene, "[render]\nspp = -4\n").unwrap();
    let (ok, _, err) = cirrus(&["render", s(&scene), "-o", s(&d.join("o.exr"))]);
    assert!(
        !ok && err.contains("bad.toml") && err.contains("line 2"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `--guiding` (learned path guiding, removed) is refused with why and
/// where its record is, before anything renders.
#[test]
fn guiding_is_refused_with_the_reason() {
    let d = scratch("guiding");
    let out = d.join("g.exr");
    let (ok, _, err) = cirrus(&["render", "data/cloud.vdb", "--guiding", "on", "-o", s(&out)]);
    assert!(!ok);
    assert!(
        err.contains("removed") && err.contains("BENCHMARKS.md") && err.contains("0258f19"),
        "{err}"
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&d);
}

/// Two volumes, flags over the file, and the stats of a scene with only a
/// sun: no environment samples, no emission lookups, the grids named and
/// no others.
#[test]
fn a_scene_file_renders_with_flags_overriding_it() {
    let d = scratch("scene");
    let data = root().join("data");
    let scene = d.join("two.toml");
    std::fs::write(
        &scene,
        format!(
            r#"
[output]
exr = "{out}"
stats = "{stats}"
[render]
spp = 2
[camera]
res = "16x12"
[environment]
radiance = [0, 0, 0]
[[volume]]
file = "{data}/multi_grid.vdb"
density = "density"
[[volume]]
file = "{data}/multi_grid.vdb"
transform = {{ translate = [5, 0, 0], euler = [0, 30, 0] }}
"#,
            out = s(&d.join("two.exr")),
            stats = s(&d.join("two.json")),
            data = s(&data),
        ),
    )
    .unwrap();
    let (ok, _, err) = cirrus(&["render", s(&scene), "--spp", "3"]);
    assert!(ok, "{err}");
    let st = stats(&d.join("two.json"));
    assert_eq!(st["spp"], 3, "the flag wins over the file");
    assert_eq!(st["width"], 16);
    assert_eq!(st["grids_loaded"], 1, "one grid, shared by both instances");
    assert_eq!(st["emission_lookups"], 0);
    assert_eq!(st["dome_samples"], 0);
    assert_eq!(st["nee_rays_dome"], 0);
    assert!(st["nee_rays_distant"].as_u64().unwrap() > 0);
    // Only the density grid's bytes: the file holds four grids.
    let file_len = std::fs::metadata(data.join("multi_grid.vdb"))
        .unwrap()
        .len();
    let read = st["bytes_read"].as_u64().unwrap();
    assert!(read > 0 && read < file_len, "{read} of {file_len} bytes");
    let _ = std::fs::remove_dir_all(&d);
}

/// Single scattering under a sun alone: a volume behind the camera that
/// is not in any visible volume's shadow prism is never read.
#[test]
fn a_volume_nothing_can_reach_is_not_loaded() {
    let d = scratch("cull");
    let data = root().join("data");
    let scene = d.join("cull.toml");
    let write = |far_translate: &str| {
        std::fs::write(
            &scene,
            format!(
                r#"
[output]
exr = "{out}"
stats = "{stats}"
[render]
spp = 1
max_depth = 1
[camera]
res = "8x8"
from = [24, 24, 100]
to = [24, 24, 24]
[sun]
direction = [0, -1, 0]
[environment]
radiance = [0, 0, 0]
[[volume]]
file = "{data}/sphere_fog.vdb"
[[volume]]
file = "{data}/fireball.vdb"
transform = {{ translate = {far_translate} }}
"#,
                out = s(&d.join("cull.exr")),
                stats = s(&d.join("cull.json")),
                data = s(&data),
            ),
        )
        .unwrap()
    };
    // Behind the camera and off to the side: unreachable.
    write("[24, 0, 300]");
    let (ok, _, err) = cirrus(&["render", s(&scene)]);
    assert!(ok, "{err}");
    assert_eq!(stats(&d.join("cull.json"))["grids_loaded"], 1, "{err}");
    // Straight above the visible sphere (toward the sun): it shadows it.
    write("[24, 200, 24]");
    let (ok, _, err) = cirrus(&["render", s(&scene)]);
    assert!(ok, "{err}");
    assert_eq!(stats(&d.join("cull.json"))["grids_loaded"], 2, "{err}");
    let _ = std::fs::remove_dir_all(&d);
}
