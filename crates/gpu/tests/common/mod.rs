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

/// Renders the scene of `tables` (with a 16x16 camera at 64 spp) on both
/// devices and compares 4x4-pixel blocks (5 sigma over 16 blocks x 4
/// channels, RGB and alpha; the estimators differ, the expectation does
/// not); the GPU render's statistics.
pub fn agrees_with_cpu(tables: &str) -> cirrus_render::RenderStats {
    let Some(gpu) = gpu() else {
        return Default::default();
    };
    let s = scene(&format!(
        r#"
        [camera]
        res = "16x16"
        {tables}
        "#
    ));
    let mut s = s;
    s.apply(&cirrus_scene::Overrides {
        spp: Some(64),
        seed: Some(5),
        ..Default::default()
    });
    let gr = render_gpu(&gpu, &s).expect("GPU render");
    let c = render_cpu(&s).image;
    let counted = &gr.stats.counters;
    // Track-length shadow rays are free flights: no shadow collisions.
    assert!(counted.real_collisions > 0);
    assert!(counted.shadow_collisions > 0 || gr.stats.transmittance == "track-length");
    assert_eq!(counted.paths, 16 * 16 * 64);
    let stats = gr.stats;
    let g = gr.image;
    let mut worst: f64 = 0.0;
    for by in 0..4 {
        for bx in 0..4 {
            let block = (4 * bx, 4 * by, 4 * bx + 4, 4 * by + 4);
            for ch in 0..4 {
                let (mg, sg) = block_mean(&g, ch, block);
                let (mc, sc) = block_mean(&c, ch, block);
                let se = (sg * sg + sc * sc).sqrt().max(1e-6);
                let z = (mg - mc) / se;
                worst = worst.max(z.abs());
                assert!(
                    z.abs() < 5.0,
                    "block ({bx}, {by}) channel {ch}: GPU {mg} CPU {mc}, {z} standard errors"
                );
            }
        }
    }
    // Not a trivially empty scene: the cloud lights up.
    let (mean, _) = block_mean(&c, 1, (0, 0, 16, 16));
    assert!(mean > 0.05, "CPU image mean {mean}");
    eprintln!("largest block difference: {worst:.2} standard errors (CPU image mean {mean})");
    stats
}

/// The image's values (and, where `variance`, its variances) as bits,
/// for comparisons to the bit.
pub fn bits(image: &Image, variance: bool) -> Vec<u32> {
    let variances = if variance { &image.variance[..] } else { &[] };
    image
        .rgba
        .iter()
        .chain(variances)
        .flatten()
        .map(|v| v.to_bits())
        .collect()
}
