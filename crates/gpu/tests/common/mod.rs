//! What the GPU tests share: the adapter (or the reason there is none),
//! scenes over the repository's default cloud, and image statistics.

#![allow(dead_code)]

use std::path::Path;

use cirrus_gpu::Gpu;
use cirrus_render::{Image, Rendered};
use cirrus_scene::{Scene, SceneDescription, VolumeCache};

/// The Vulkan adapter the tests render on (lavapipe in CI). Without one
/// the test fails where `CI` is set (CI installs lavapipe), and is
/// skipped, saying why, elsewhere.
pub fn gpu() -> Option<Gpu> {
    match cirrus_gpu::open(true) {
        Ok(gpu) => Some(gpu),
        Err(e) if std::env::var_os("CI").is_some() => panic!("CI has no Vulkan adapter: {e}"),
        Err(e) => {
            eprintln!("SKIPPED: {e}");
            None
        }
    }
}

/// A scene from scene-file text, its paths relative to `data/`.
pub fn scene(toml: &str) -> Scene {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data");
    let desc = SceneDescription::parse(toml).expect("test scene parses");
    Scene::from_description(desc, &data).expect("test scene loads")
}

/// `scene` rendered on `gpu`.
pub fn render_gpu(gpu: &Gpu, scene: &Scene) -> Result<Rendered, cirrus_gpu::GpuError> {
    let mut cache = VolumeCache::default();
    let prepared = scene.prepare(&mut cache, None).expect("scene prepares");
    cirrus_gpu::render(gpu, &prepared.scene, &prepared.settings)
}

/// `scene` rendered on the CPU.
pub fn render_cpu(scene: &Scene) -> Rendered {
    scene.render().expect("CPU render")
}

/// The mean of channel `c` over the pixels of `[x0, x1) x [y0, y1)` and
/// its standard error (from each pixel's sample variance: pixels are
/// independent).
pub fn block_mean(image: &Image, c: usize, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> (f64, f64) {
    let mut sum = 0.0;
    let mut var = 0.0;
    let mut n = 0.0;
    for y in y0..y1 {
        for x in x0..x1 {
            sum += f64::from(image.pixel(x, y)[c]);
            var += f64::from(image.std_error(x, y)[c]).powi(2);
            n += 1.0;
        }
    }
    (sum / n, var.sqrt() / n)
}
