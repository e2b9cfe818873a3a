//! The compositing outputs through the `cirrus` binary: crops of every new
//! layer (deep included) merge bit for bit, volumes are named in the
//! Cryptomatte manifest, and bad inputs are refused by file and field
//! before anything is written.

mod common;

use common::cirrus;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cirrus-comp-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Two overlapping instances of one file, the second named, the first
/// named after its file.
fn two_spheres(dir: &Path) -> PathBuf {
    let sphere = common::root().join("data/sphere_fog.vdb");
    let scene = dir.join("two.toml");
    let text = format!(
        "[camera]\nres = \"24x16\"\n\
         [[volume]]\nfile = {sphere:?}\n\
         [[volume]]\nfile = {sphere:?}\nname = \"right\"\ntransform = {{ translate = [6, 0, 0] }}\n"
    );
    std::fs::write(&scene, text).unwrap();
    scene
}

fn depth_exr(path: &Path, size: (usize, usize), channel: &str, value: f32) {
    use exr::prelude::*;
    let ch = AnyChannel::new(channel, FlatSamples::F32(vec![value; size.0 * size.1]));
    let layer = Layer::new(
        size,
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(vec![ch].into()),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

#[test]
fn crops_of_every_layer_merge_bit_for_bit() {
    let d = scratch("merge");
    let scene = two_spheres(&d);
    let common = [
        "render",
        s(&scene),
        "--spp",
        "4",
        "--seed",
        "5",
        "--aov",
        "lights,cryptomatte,depth",
    ];
    let (full, full_deep) = (d.join("full.exr"), d.join("full.deep.exr"));
    let (ok, _, err) = cirrus(&[&common[..], &["-o", s(&full), "--deep", s(&full_deep)]].concat());
    assert!(ok, "{err}");
    let crops = ["0,0,10,16", "10,0,24,9", "10,9,24,16"];
    let (mut tiles, mut deep_tiles) = (Vec::new(), Vec::new());
    for (i, c) in crops.iter().enumerate() {
        let (t, dt) = (
            d.join(format!("t{i}.exr")),
            d.join(format!("t{i}.deep.exr")),
        );
        let args = ["--crop", c, "-o", s(&t), "--deep", s(&dt)];
        let (ok, _, err) = cirrus(&[&common[..], &args].concat());
        assert!(ok, "{err}");
        tiles.push(t);
        deep_tiles.push(dt);
    }
    for (out, parts) in [
        (d.join("m.exr"), &tiles),
        (d.join("m.deep.exr"), &deep_tiles),
    ] {
        let mut args = vec!["merge", s(&out)];
        args.extend(parts.iter().map(|t| s(t)));
        let (ok, _, err) = cirrus(&args);
        assert!(ok, "{err}");
    }
    let a = cirrus_render::exr_layers::read_channels(&full).unwrap();
    let b = cirrus_render::exr_layers::read_channels(&d.join("m.exr")).unwrap();
    let names: Vec<&str> = a.channels.iter().map(|(n, _)| n.as_str()).collect();
    for n in [
        "sun.R",
        "sky.G",
        "emission.B",
        "CryptoObject00.R",
        "CryptoAsset02.A",
    ] {
        assert!(names.contains(&n), "{n} in {names:?}");
    }
    assert_eq!(
        a.attributes, b.attributes,
        "the manifest survives the merge"
    );
    for ((na, va), (nb, vb)) in a.channels.iter().zip(&b.channels) {
        assert_eq!(na, nb);
        assert!(
            va.iter().zip(vb).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{na} differs"
        );
    }
    let deep_a = cirrus_deep_exr::read(&full_deep).unwrap();
    let deep_b = cirrus_deep_exr::read(&d.join("m.deep.exr")).unwrap();
    let samples: u32 = deep_a.counts.iter().sum();
    assert!(samples > 24 * 16, "{samples} deep samples");
    assert_eq!(deep_a, deep_b, "deep tiles merge value for value");
    // The manifest names both instances and the one file.
    let manifest = |layer: &str| {
        let key = cirrus_render::compositing::cryptomatte::layer_key(layer);
        let k = format!("cryptomatte/{key}/manifest");
        a.attributes
            .iter()
            .find(|(n, _)| *n == k)
            .unwrap()
            .1
            .clone()
    };
    let objects = manifest("CryptoObject");
    assert!(
        objects.contains("\"sphere_fog\"") && objects.contains("\"right\""),
        "{objects}"
    );
    assert!(manifest("CryptoAsset").contains("\"sphere_fog.vdb\""));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_compositing_inputs_name_the_file_and_write_nothing() {
    let d = scratch("bad");
    let out = d.join("out.exr");
    let render = |extra: &[&str]| {
        let base = [
            "render",
            "data/sphere_fog.vdb",
            "--res",
            "16x12",
            "--spp",
            "1",
            "-o",
            s(&out),
        ];
        let (ok, _, err) = cirrus(&[&base[..], extra].concat());
        assert!(!ok, "{extra:?} should fail");
        assert!(!out.exists(), "{extra:?}: nothing is written");
        err
    };
    let missing = d.join("none.exr");
    let e = render(&["--holdout-depth", s(&missing)]);
    assert!(e.contains("none.exr") && e.contains("not found"), "{e}");
    let small = d.join("small.exr");
    depth_exr(&small, (8, 6), "Z", 3.0);
    let e = render(&["--holdout-depth", s(&small)]);
    assert!(
        e.contains("small.exr") && e.contains("8x6") && e.contains("16x12"),
        "{e}"
    );
    let right = d.join("right.exr");
    depth_exr(&right, (16, 12), "depth.Z", 3.0);
    let e = render(&["--holdout-depth", &format!("{}:Depth.Z", s(&right))]);
    assert!(
        e.contains("right.exr") && e.contains("Depth.Z") && e.contains("depth.Z"),
        "{e}"
    );
    let nan = d.join("nan.exr");
    depth_exr(&nan, (16, 12), "Z", f32::NAN);
    let e = render(&["--holdout-depth", s(&nan)]);
    assert!(e.contains("nan.exr") && e.contains("pixel (0, 0)"), "{e}");
    let e = render(&["--aov", "lights,beauty"]);
    assert!(e.contains("beauty"), "{e}");
    let e = render(&["--deep", s(&d.join("deep.exr")), "--integrator", "raymarch"]);
    assert!(e.contains("raymarch") && e.contains("deep"), "{e}");
    assert!(!d.join("deep.exr").exists());
    // Two volumes given one name.
    let sphere = common::root().join("data/sphere_fog.vdb");
    let scene = d.join("clash.toml");
    let text = format!(
        "[[volume]]\nfile = {sphere:?}\nname = \"a\"\n[[volume]]\nfile = {sphere:?}\nname = \"a\"\n"
    );
    std::fs::write(&scene, text).unwrap();
    let (ok, _, e) = cirrus(&[
        "render",
        s(&scene),
        "--res",
        "8x8",
        "--spp",
        "1",
        "-o",
        s(&out),
    ]);
    assert!(
        !ok && e.contains("clash.toml") && e.contains("\"a\""),
        "{e}"
    );
    let leftovers: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    let _ = std::fs::remove_dir_all(&d);
}
