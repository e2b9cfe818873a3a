//! `cirrus render --device`: a GPU render written through the same
//! outputs as a CPU one, the refusal of what the GPU does not render, and
//! what is said without a Vulkan adapter.

mod common;

use common::cirrus;
use std::path::PathBuf;

/// A scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cirrus-device-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Whether `stderr` says there is no adapter; then CI (which installs
/// lavapipe) fails, and elsewhere the install hint must be named.
fn no_adapter(stderr: &str) -> bool {
    let none = stderr.contains("no Vulkan adapter");
    if none {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI has no Vulkan adapter: {stderr}"
        );
        assert!(stderr.contains("mesa-vulkan-drivers"), "{stderr}");
        eprintln!("SKIPPED: {stderr}");
    }
    none
}

#[test]
fn gpu_renders_write_the_same_outputs() {
    let d = scratch("outputs");
    let exr = d.join("g.exr");
    let png = d.join("g.png");
    let (ok, _, err) = cirrus(&[
        "render",
        "data/cloud.vdb",
        "--device",
        "gpu",
        "--res",
        "16x12",
        "--spp",
        "2",
        "-o",
        exr.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
    ]);
    if no_adapter(&err) {
        assert!(!ok);
        return;
    }
    assert!(ok, "{err}");
    assert!(err.contains("rendering on the GPU"), "{err}");
    assert!(err.contains("16x12 at 2 spp"), "{err}");
    let image = exr::prelude::read_first_rgba_layer_from_file(
        &exr,
        |res, _| vec![[0f32; 4]; res.width() * res.height()],
        |px, pos, (r, g, b, a): (f32, f32, f32, f32)| px[pos.y() * 16 + pos.x()] = [r, g, b, a],
    )
    .expect("the GPU's EXR reads back");
    let pixels = &image.layer_data.channel_data.pixels;
    assert_eq!(pixels.len(), 16 * 12);
    assert!(pixels.iter().flatten().all(|v| v.is_finite()));
    assert!(
        pixels.iter().any(|p| p[3] > 0.0),
        "the cloud is not in view"
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 0);
}

#[test]
fn gpu_refuses_what_it_does_not_render_by_name() {
    let d = scratch("refuse");
    let (ok, _, err) = cirrus(&[
        "render",
        "data/cloud.vdb",
        "--device",
        "gpu",
        "--integrator",
        "raymarch",
        "--res",
        "8x8",
        "-o",
        d.join("r.exr").to_str().unwrap(),
    ]);
    assert!(!ok, "a ray-marched scene rendered on the GPU: {err}");
    if no_adapter(&err) {
        return;
    }
    assert!(err.contains("the raymarch integrator"), "{err}");
    assert!(err.contains("use --device cpu"), "{err}");
    assert!(!d.join("r.exr").exists(), "an image was written");
}

#[test]
fn unknown_devices_are_refused() {
    let (ok, _, err) = cirrus(&["render", "data/cloud.vdb", "--device", "tpu", "-o", "x.exr"]);
    assert!(!ok);
    assert!(err.contains("cpu, auto, gpu"), "{err}");
    // `cirrus preview` takes the same values (refused before it serves).
    let (ok, _, err) = cirrus(&[
        "preview",
        "data/cloud.vdb",
        "--device",
        "tpu",
        "--port",
        "0",
    ]);
    assert!(!ok);
    assert!(err.contains("cpu, auto, gpu"), "{err}");
}

/// `auto` takes a hardware GPU or the CPU, never lavapipe, and says which.
#[test]
fn auto_says_where_it_renders() {
    let d = scratch("auto");
    let (ok, _, err) = cirrus(&[
        "render",
        "data/cloud.vdb",
        "--device",
        "auto",
        "--res",
        "8x6",
        "--spp",
        "1",
        "-o",
        d.join("a.exr").to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let gpu = err.contains("rendering on the GPU");
    let cpu = err.contains("rendering on the CPU");
    assert!(gpu != cpu, "{err}");
    assert!(
        !(gpu && err.contains("(Cpu, ")),
        "auto took a software adapter: {err}"
    );
    assert!(d.join("a.exr").exists());
}

/// A scene file's `[render] device` chooses the device as `--device`
/// does, and the flag overrides it; a device it does not know is refused
/// naming the file.
#[test]
fn a_scene_file_chooses_the_device() {
    let d = scratch("scene");
    let cloud = std::fs::canonicalize("data/cloud.vdb")
        .or_else(|_| std::fs::canonicalize("../../data/cloud.vdb"))
        .unwrap();
    let write = |name: &str, device: &str| {
        let path = d.join(name);
        std::fs::write(
            &path,
            format!(
                "[render]\ndevice = \"{device}\"\nspp = 1\n[camera]\nres = \"8x6\"\n\
                 [[volume]]\nfile = {:?}\n",
                cloud.to_str().unwrap()
            ),
        )
        .unwrap();
        path
    };
    let gpu_scene = write("gpu.toml", "gpu");
    let out = d.join("s.exr");
    let (ok, _, err) = cirrus(&[
        "render",
        gpu_scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    if !no_adapter(&err) {
        assert!(ok, "{err}");
        assert!(err.contains("rendering on the GPU"), "{err}");
    }
    let (ok, _, err) = cirrus(&[
        "render",
        gpu_scene.to_str().unwrap(),
        "--device",
        "cpu",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(!err.contains("GPU"), "--device cpu touched a GPU: {err}");
    let bad = write("bad.toml", "tpu");
    let (ok, _, err) = cirrus(&["render", bad.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("bad.toml") && err.contains("device"), "{err}");
}

/// `cirrus preview --device gpu` without a Vulkan driver (the loader
/// pointed at none) says what to install before it serves anything.
#[test]
fn preview_without_a_vulkan_driver_says_what_to_install() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cirrus"))
        .args([
            "preview",
            "data/cloud.vdb",
            "--device",
            "gpu",
            "--port",
            "0",
        ])
        .current_dir(common::root())
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("no Vulkan adapter"), "{err}");
    assert!(err.contains("apt-get install mesa-vulkan-drivers"), "{err}");
    assert!(String::from_utf8_lossy(&out.stdout).is_empty(), "it served");
}
