//! Settings are used or refused, never ignored in silence: the framed
//! camera takes `--fov` and is printed and recorded, out-of-range values
//! are errors naming the flag, an open shutter without a velocity grid and
//! bad voxels are warned about, and adaptive sampling reports its mean.

mod common;

use common::cirrus;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cirrus-said-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stats(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn alpha_coverage(path: &Path) -> f64 {
    let exr = cirrus_render::exr_layers::read_channels(path).unwrap();
    let (_, a) = exr.channels.iter().find(|(n, _)| n == "A").unwrap();
    a.iter().map(|&x| f64::from(x)).sum::<f64>() / a.len() as f64
}

#[test]
fn the_framed_camera_takes_the_field_of_view_and_is_reported() {
    let d = scratch("fov");
    let mut coverage = Vec::new();
    let mut distance = Vec::new();
    for fov in ["20", "40", "80"] {
        let (exr, json) = (d.join(format!("{fov}.exr")), d.join(format!("{fov}.json")));
        let (ok, _, err) = cirrus(&[
            "render",
            "data/cloud.vdb",
            "--res",
            "24x24",
            "--spp",
            "2",
            "--fov",
            fov,
            "-o",
            s(&exr),
            "--stats",
            s(&json),
        ]);
        assert!(ok, "{err}");
        assert!(
            err.contains("camera framed on the volumes: --camera-from ")
                && err.contains(&format!("--fov {fov}")),
            "{err}"
        );
        let camera = &stats(&json)["camera"];
        assert_eq!(camera["framed"], true);
        assert_eq!(camera["fov"].as_f64().unwrap().to_string(), fov);
        let from: Vec<f64> = serde_json::from_value(camera["from"].clone()).unwrap();
        let to: Vec<f64> = serde_json::from_value(camera["to"].clone()).unwrap();
        distance.push(
            from.iter()
                .zip(&to)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt(),
        );
        coverage.push(alpha_coverage(&exr));
    }
    // Framing keeps the cloud filling the frame: a narrower field of view
    // puts the camera farther away, by about tan(40)/tan(10) = 4.8x from 80
    // to 20 degrees.
    assert!(
        distance[0] > distance[1] && distance[1] > distance[2],
        "{distance:?}"
    );
    let ratio = distance[0] / distance[2];
    assert!((3.5..6.0).contains(&ratio), "{ratio}");
    // The cloud covers a similar share of each frame (perspective aside).
    for c in &coverage {
        assert!((c / coverage[1] - 1.0).abs() < 0.35, "{coverage:?}");
    }
    // An explicit camera is not framed, and says nothing of it.
    let exr = d.join("placed.exr");
    let (ok, _, err) = cirrus(&[
        "render",
        "data/cloud.vdb",
        "--res",
        "8x8",
        "--spp",
        "1",
        "--camera-from",
        "150,83,-250",
        "--camera-to",
        "150,83,100",
        "-o",
        s(&exr),
    ]);
    assert!(ok, "{err}");
    assert!(!err.contains("framed"), "{err}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn out_of_range_flags_are_refused_by_name() {
    let d = scratch("ranges");
    let out = d.join("x.exr");
    for (flags, said) in [
        (&["--fov", "0"][..], "--fov"),
        (
            &[
                "--fov",
                "200",
                "--camera-from",
                "0,0,0",
                "--camera-to",
                "1,0,0",
            ],
            "--fov",
        ),
        (&["--g", "1.2"], "--g "),
        (&["--g", "-3"], "--g "),
        (&["--sun-dir", "0,0,0"], "--sun-dir"),
        (&["--sun-irradiance", "1,-1,1"], "--sun-irradiance"),
        (&["--env-radiance", "nan,0,0"], "--env-radiance"),
        (
            &["--spp", "8", "--noise-threshold", "0.05"],
            "--min-spp 16 is above --spp 8",
        ),
        (&["--albedo", "1.5"], "albedo"),
        (&["--phase", "mie", "--droplet-diameter", "80"], "diameter"),
    ] {
        // No --spp: every case fails before rendering.
        let base = ["render", "data/cloud.vdb", "--res", "8x8", "-o", s(&out)];
        let (ok, _, err) = cirrus(&[&base[..], flags].concat());
        assert!(!ok, "{flags:?} accepted");
        assert!(err.contains(said), "{flags:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "{flags:?} wrote an image");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn velocity_grids_are_found_by_their_common_names_or_warned_about() {
    let d = scratch("velocity");
    let (exr, json) = (d.join("v.exr"), d.join("v.json"));
    let render = |file: &str, flags: &[&str]| {
        let base = [
            "render",
            file,
            "--res",
            "8x8",
            "--spp",
            "1",
            "-o",
            s(&exr),
            "--stats",
        ];
        cirrus(&[&base[..], &[s(&json)], flags].concat())
    };
    // multi_grid.vdb's vec3 grid is called "velocity": found, no warning.
    let (ok, _, err) = render("data/multi_grid.vdb", &["--shutter", "-0.25,0.25"]);
    assert!(ok, "{err}");
    assert!(!err.contains("warning"), "{err}");
    assert_eq!(stats(&json)["warnings"].as_array().unwrap().len(), 0);
    // An open shutter over a file with no vector grid: said, and recorded.
    let (ok, _, err) = render("data/cloud.vdb", &["--shutter", "-0.25,0.25"]);
    assert!(ok, "{err}");
    assert!(
        err.contains("warning")
            && err.contains("no velocity grid")
            && err.contains("does not move"),
        "{err}"
    );
    let warnings = stats(&json)["warnings"].as_array().unwrap().clone();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    // A velocity named with the shutter closed is unused, and said so.
    let (ok, _, err) = render("data/multi_grid.vdb", &["--velocity", "velocity"]);
    assert!(ok, "{err}");
    assert!(
        err.contains("--velocity velocity: unused while the shutter is closed"),
        "{err}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn bad_voxels_are_warned_about_at_load() {
    let d = scratch("voxels");
    let (exr, json) = (d.join("v.exr"), d.join("v.json"));
    let (ok, _, err) = cirrus(&[
        "render",
        "data/special_values.vdb",
        "--res",
        "16x16",
        "--spp",
        "2",
        "-o",
        s(&exr),
        "--stats",
        s(&json),
    ]);
    assert!(ok, "{err}");
    // 517: the file's NaN, infinite and negative voxels (the +inf tile's
    // 512 among them), as `cirrus convert` counts them.
    let said = "517 voxels are NaN, infinite or negative; they render as density 0";
    assert!(err.contains(said), "{err}");
    // Said before the render's summary, at load.
    assert!(
        err.find(said).unwrap() < err.find(" at 2 spp").unwrap(),
        "{err}"
    );
    let st = stats(&json);
    let warnings = st["warnings"].to_string();
    assert!(warnings.contains(said), "{warnings}");
    // Its 1e30 and FLT_MAX voxels (finite, kept) stop some trackers at
    // their collision cap: said with the count the statistics hold.
    let capped = st["collision_cap_hits"].as_u64().unwrap();
    assert!(capped > 0, "{st}");
    assert!(
        err.contains(&format!("warning: {capped} tracking calls hit the cap")),
        "{err}"
    );
    let (ok, _, err) = cirrus(&[
        "render",
        "data/cloud.vdb",
        "--res",
        "8x8",
        "--spp",
        "1",
        "-o",
        s(&exr),
    ]);
    assert!(ok && !err.contains("warning"), "{err}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn adaptive_sampling_reports_its_mean_and_range() {
    let d = scratch("adaptive");
    let (exr, json) = (d.join("a.exr"), d.join("a.json"));
    let (ok, _, err) = cirrus(&[
        "render",
        "data/cloud.vdb",
        "--res",
        "24x24",
        "--spp",
        "64",
        "--min-spp",
        "4",
        "--noise-threshold",
        "0.2",
        "--aov",
        "samples",
        "-o",
        s(&exr),
        "--stats",
        s(&json),
    ]);
    assert!(ok, "{err}");
    let st = stats(&json);
    let (mean, min, max) = (
        st["spp_mean"].as_f64().unwrap(),
        st["spp_min"].as_u64().unwrap(),
        st["spp_max"].as_u64().unwrap(),
    );
    // The samples layer is the truth the summary reports.
    let layers = cirrus_render::exr_layers::read_channels(&exr).unwrap();
    let (_, samples) = layers
        .channels
        .iter()
        .find(|(n, _)| n == "samples.Y")
        .unwrap();
    let true_mean = samples.iter().map(|&x| f64::from(x)).sum::<f64>() / samples.len() as f64;
    assert!((mean - true_mean).abs() < 1e-9, "{mean} vs {true_mean}");
    assert_eq!(min as f32, samples.iter().copied().fold(f32::MAX, f32::min));
    assert_eq!(max as f32, samples.iter().copied().fold(0.0, f32::max));
    assert!(min >= 4 && min < max && max <= 64, "{min}-{max}");
    let said = format!("at {mean:.1} spp on average ({min}-{max})");
    assert!(err.contains(&said), "{said:?} in {err}");
    std::fs::remove_dir_all(&d).unwrap();
}
