//! Denoised crops merge into the denoised full render: the tiles keep the
//! denoiser's inputs and `cirrus merge` denoises the whole image. Runs with
//! the real Open Image Denoise library (found through `CIRRUS_OIDN`, or
//! the `target/venv` that `tools/oidn.sh` fills); skipped, and said so,
//! only where neither is there.

mod common;

use common::cirrus;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cirrus-dntiles-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn denoised_crops_merge_bit_for_bit_into_the_denoised_full_render() {
    let d = scratch("merge");
    let common = [
        "render",
        "data/cloud.vdb",
        "--res",
        "40x24",
        "--spp",
        "4",
        "--seed",
        "9",
        "--denoise",
        "--aov",
        "lights,albedo",
    ];
    let full = d.join("full.exr");
    let (ok, _, err) = cirrus(&[&common[..], &["-o", s(&full)]].concat());
    if !ok && err.contains("could not be loaded") && std::env::var_os("CIRRUS_OIDN").is_none() {
        eprintln!("SKIPPED: no Open Image Denoise library: {err}");
        return;
    }
    assert!(ok, "{err}");
    let mut tiles = Vec::new();
    for (i, crop) in ["0,0,17,24", "17,0,40,11", "17,11,40,24"]
        .iter()
        .enumerate()
    {
        let (t, json) = (d.join(format!("t{i}.exr")), d.join(format!("t{i}.json")));
        let args = ["--crop", crop, "-o", s(&t), "--stats", s(&json)];
        let (ok, _, err) = cirrus(&[&common[..], &args].concat());
        assert!(ok, "{err}");
        assert!(
            err.contains("cirrus merge"),
            "the tile says where it is denoised: {err}"
        );
        let stats = std::fs::read_to_string(&json).unwrap();
        assert!(stats.contains("a crop is not denoised alone"), "{stats}");
        tiles.push(t);
    }
    let tile = cirrus_render::exr_layers::read_channels(&tiles[0]).unwrap();
    assert!(tile
        .channels
        .iter()
        .any(|(n, _)| n == "denoise_input.half_a.R"));
    let merged = d.join("merged.exr");
    let mut args = vec!["merge", s(&merged)];
    args.extend(tiles.iter().map(|t| s(t)));
    let (ok, _, err) = cirrus(&args);
    assert!(ok, "{err}");
    assert!(err.contains("denoised"), "{err}");

    let a = cirrus_render::exr_layers::read_channels(&full).unwrap();
    let b = cirrus_render::exr_layers::read_channels(&merged).unwrap();
    let names = |c: &cirrus_render::exr_layers::ExrChannels| -> Vec<String> {
        c.channels.iter().map(|(n, _)| n.clone()).collect()
    };
    assert_eq!(names(&a), names(&b), "the same layers, inputs dropped");
    assert_eq!(a.attributes, b.attributes);
    for n in ["blend.weight", "noisy.R", "denoised.G", "sun.B", "sky.R"] {
        assert!(names(&a).iter().any(|m| m == n), "{n} in {:?}", names(&a));
    }
    for ((n, va), (_, vb)) in a.channels.iter().zip(&b.channels) {
        let differing = va
            .iter()
            .zip(vb)
            .filter(|(x, y)| x.to_bits() != y.to_bits())
            .count();
        assert_eq!(
            differing,
            0,
            "{n}: {differing} of {} pixels differ",
            va.len()
        );
    }
    // The blend did something: some pixels lean on the denoised image.
    let (_, weight) = a
        .channels
        .iter()
        .find(|(n, _)| n == "blend.weight")
        .unwrap();
    assert!(weight.iter().any(|&w| w < 0.99), "{weight:?}");
    std::fs::remove_dir_all(&d).unwrap();
}
