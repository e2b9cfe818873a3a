//! The GPU path tracer on a Vulkan adapter (lavapipe in CI): the white
//! furnace, agreement with the CPU in distribution, determinism, and the
//! refusal of what it does not render. Small images, a few seconds each.

mod common;

use common::{agrees_with_cpu, bits, block_mean, gpu, render_gpu, scene};

/// Albedo 1 under a uniform sky of radiance 1: every pixel's expectation
/// is exactly 1, at any density, phase function or depth. A thick cloud
/// (density x 20, optical depths in the tens) and a forward phase
/// function (g = 0.8) make the paths long.
#[test]
fn white_furnace_is_one_everywhere() {
    furnace("g = 0.8\n        density_scale = 20.0", 24, 16);
}

/// The same furnace under the approximate Mie fit (an HG lobe and a
/// Draine lobe, the latter drawn by rejection).
#[test]
fn white_furnace_is_one_under_mie_scattering() {
    furnace(
        "phase = \"mie\"\n        droplet_diameter = 12.0\n        density_scale = 20.0",
        16,
        12,
    );
}

/// The same furnace in a chromatic medium (a density scale per channel,
/// tracked spectrally): every channel is 1 too.
#[test]
fn white_furnace_is_one_in_a_chromatic_medium() {
    furnace("g = 0.6\n        density_scale = [20.0, 9.0, 3.0]", 16, 12);
}

/// Renders the furnace with `phase` (the medium's lines: its phase
/// function and density scale) at `res` x `res` and `spp`, and checks
/// every channel's image mean is 1 within 4 standard errors.
fn furnace(phase: &str, res: u32, spp: u32) {
    let Some(gpu) = gpu() else { return };
    let s = scene(&format!(
        r#"
        [render]
        spp = {spp}
        seed = 3
        [camera]
        res = "{res}x{res}"
        [sun]
        enabled = false
        [environment]
        radiance = [1, 1, 1]
        [[volume]]
        file = "cloud.vdb"
        albedo = 1.0
        {phase}
        "#
    ));
    let r = render_gpu(&gpu, &s).expect("GPU render");
    let image = &r.image;
    assert_eq!((image.width, image.height, image.spp), (res, res, spp));
    assert!(
        image.rgba.iter().flatten().all(|v| v.is_finite()),
        "a pixel is not finite"
    );
    assert_eq!(r.stats.counters.nonfinite_samples, 0);
    assert_eq!(
        r.stats.counters.collision_cap_hits, 0,
        "paths were cut short"
    );
    // The cloud must be in view, or the test would prove nothing: a
    // fifth of the camera rays collide in the framed brick grid (alpha is
    // the track-length estimate of 1 - T).
    let (alpha, _) = block_mean(image, 3, (0, 0, res, res));
    assert!(alpha > 0.15, "the cloud covers {alpha} of the image");
    for c in 0..3 {
        let (mean, se) = block_mean(image, c, (0, 0, res, res));
        eprintln!("furnace ({phase}) channel {c}: {mean} +- {se}");
        assert!(se > 0.0, "channel {c}: no noise at all");
        assert!(
            (mean - 1.0).abs() < 4.0 * se,
            "channel {c}: image mean {mean} is {} standard errors ({se}) from 1",
            (mean - 1.0) / se
        );
    }
}

/// The default cloud under sun and sky, albedo 0.9: the GPU's image and
/// the CPU's agree block by block within their standard errors (5 sigma
/// over 16 blocks x 4 channels, RGB and alpha; the estimators differ, the
/// expectation does not).
#[test]
fn gpu_agrees_with_cpu() {
    let stats = agrees_with_cpu(
        r#"
        [sun]
        angle = 0.53
        [environment]
        radiance = [0.16, 0.22, 0.34]
        [[volume]]
        file = "cloud.vdb"
        albedo = 0.9
        g = 0.6
        "#,
    );
    // The CPU's defaults, honoured.
    assert_eq!(
        (stats.majorant.as_str(), stats.transmittance.as_str()),
        ("auto: hierarchy", "residual")
    );
}

/// A delta sun (NEE alone) and paths of at most two scattering events,
/// whose last vertex samples the sky by the phase function and takes no
/// MIS: the same agreement.
#[test]
fn gpu_agrees_with_cpu_with_a_delta_sun_and_two_events() {
    agrees_with_cpu(
        r#"
        [render]
        max_depth = 2
        [sun]
        angle = 0
        direction = [-0.3, -0.8, 0.5]
        [environment]
        radiance = [0.3, 0.3, 0.4]
        [[volume]]
        file = "cloud.vdb"
        albedo = [0.95, 0.8, 0.6]
        g = -0.3
        "#,
    );
}

/// The approximate Mie fit of 8 um droplets (HG g 0.98 and a Draine
/// lobe) under a delta sun, whose NEE sees the phase function's forward
/// peak and glory: the same agreement.
#[test]
fn gpu_agrees_with_cpu_under_mie_scattering() {
    agrees_with_cpu(
        r#"
        [sun]
        angle = 0
        direction = [0.5, -0.3, -0.8]
        [environment]
        radiance = [0.1, 0.12, 0.2]
        [[volume]]
        file = "cloud.vdb"
        albedo = 0.95
        phase = "mie"
        droplet_diameter = 8.0
        "#,
    );
}

/// A chromatic medium (blue extinction a fifth of red's) with a coloured
/// albedo under sun and sky: spectral tracking of free flights, ratio
/// tracking per channel for shadow rays; the same agreement.
#[test]
fn gpu_agrees_with_cpu_in_a_chromatic_medium() {
    agrees_with_cpu(
        r#"
        [sun]
        angle = 0.53
        [environment]
        radiance = [0.16, 0.22, 0.34]
        [[volume]]
        file = "cloud.vdb"
        density_scale = [10.0, 5.0, 2.0]
        albedo = [0.95, 0.9, 0.8]
        g = 0.5
        "#,
    );
}

/// The same medium with shadow rays by track-length estimation (a free
/// flight's spectral weights): the same agreement.
#[test]
fn gpu_agrees_with_cpu_in_a_chromatic_medium_by_track_length() {
    agrees_with_cpu(
        r#"
        [render]
        transmittance = "track-length"
        max_depth = 4
        [sun]
        angle = 0
        direction = [0.4, -0.7, -0.5]
        [environment]
        radiance = [0.2, 0.25, 0.3]
        [[volume]]
        file = "cloud.vdb"
        density_scale = [4.0, 8.0, 2.0]
        albedo = 0.9
        g = 0.3
        "#,
    );
}

/// A tabulated phase function (HG g 0.7 with a backward bump, 121 rows,
/// unnormalised as a table file may be): the same agreement.
#[test]
fn gpu_agrees_with_cpu_under_a_tabulated_phase() {
    let dir = std::env::temp_dir().join(format!("cirrus-gpu-table-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rows: String = (0..121)
        .map(|i| {
            let mu = -1.0 + 2.0 * f64::from(i) / 120.0;
            let hg = (1.0 - 0.49) / (1.0 + 0.49 - 1.4 * mu).powf(1.5);
            let bump = 0.5 * (-((mu + 0.9) / 0.1).powi(2)).exp();
            format!("{mu} {}\n", 3.0 * (hg + bump))
        })
        .collect();
    let table = dir.join("phase.txt");
    std::fs::write(&table, format!("# cos value\n{rows}")).unwrap();
    agrees_with_cpu(&format!(
        r#"
        [render]
        max_depth = 4
        [sun]
        angle = 0
        direction = [0.5, -0.3, -0.8]
        [environment]
        radiance = [0.2, 0.2, 0.25]
        [[volume]]
        file = "cloud.vdb"
        albedo = 0.9
        phase = "table:{}"
        "#,
        table.display()
    ));
    std::fs::remove_dir_all(&dir).ok();
}

/// A backward Draine lobe (g -0.4, alpha 3): the same agreement.
#[test]
fn gpu_agrees_with_cpu_under_a_backward_draine_phase() {
    agrees_with_cpu(
        r#"
        [render]
        max_depth = 3
        [sun]
        angle = 0.53
        [environment]
        radiance = [0.2, 0.2, 0.25]
        [[volume]]
        file = "cloud.vdb"
        albedo = 0.9
        phase = "draine"
        g = -0.4
        draine_alpha = 3.0
        "#,
    );
}

/// One global majorant over the box and plain ratio tracking, both as
/// named (the CPU's defaults are the hierarchy and residual ratio
/// tracking): the same agreement.
#[test]
fn gpu_agrees_with_cpu_over_the_global_bound_by_ratio_tracking() {
    let stats = agrees_with_cpu(
        r#"
        [render]
        majorant = "global"
        transmittance = "ratio"
        [sun]
        angle = 0.53
        [environment]
        radiance = [0.16, 0.22, 0.34]
        [[volume]]
        file = "cloud.vdb"
        albedo = 0.9
        g = 0.6
        "#,
    );
    assert_eq!(
        (stats.majorant.as_str(), stats.transmittance.as_str()),
        ("global", "ratio")
    );
}

/// A dense cloud (density x 40) walked over coarse cells (a cell may waste
/// an optical depth of 6 before it is refined) and, where a finest cell is
/// too thick for its slack, voxel by voxel; shadow rays by track-length
/// estimation: the same agreement. The scene is checked to take both
/// kinds of cell.
#[test]
fn gpu_agrees_with_cpu_on_coarse_and_voxel_cells_by_track_length() {
    let tables = r#"
        [render]
        majorant = "hierarchy"
        transmittance = "track-length"
        refine_optical_depth = 6.0
        [sun]
        angle = 0
        direction = [0.4, -0.7, -0.5]
        [environment]
        radiance = [0.2, 0.25, 0.3]
        [[volume]]
        file = "cloud.vdb"
        density_scale = 40.0
        albedo = 0.8
        g = 0.3
        "#;
    let s = scene(tables);
    let mut cache = cirrus_scene::VolumeCache::default();
    let prepared = s.prepare(&mut cache, None).expect("scene prepares");
    let field = prepared.scene.media.instances()[0].field.still_field();
    let partition = field.partition().expect("a refined partition");
    let coarse = partition
        .codes()
        .iter()
        .filter(|&&c| c & 0x80 == 0 && c > 0)
        .count();
    let level0 = &field.volume().levels[0];
    let thick = level0
        .cells
        .chunks_exact(2)
        .filter(|c| (c[1] - c[0]) * 4.0 > partition.voxel_split())
        .count();
    assert!(
        coarse > 0 && thick > 0,
        "coarse cells {coarse}, thick finest cells {thick}"
    );
    drop(prepared);
    let stats = agrees_with_cpu(tables);
    assert_eq!(
        (stats.majorant.as_str(), stats.transmittance.as_str()),
        ("hierarchy", "track-length")
    );
}

/// Same seed, same settings, same device: the same bytes.
#[test]
fn same_seed_gives_the_same_image() {
    let Some(gpu) = gpu() else { return };
    let text = |seed: u32| {
        format!(
            r#"
            [render]
            spp = 4
            seed = {seed}
            [camera]
            res = "12x10"
            [[volume]]
            file = "cloud.vdb"
            "#
        )
    };
    let a = render_gpu(&gpu, &scene(&text(9))).unwrap().image;
    let b = render_gpu(&gpu, &scene(&text(9))).unwrap().image;
    let c = render_gpu(&gpu, &scene(&text(10))).unwrap().image;
    assert_eq!(bits(&a, true), bits(&b, true));
    assert_ne!(
        bits(&a, true),
        bits(&c, true),
        "another seed gave the same image"
    );
}

/// A crop renders the same pixels as the whole image.
#[test]
fn a_crop_is_the_same_pixels() {
    let Some(gpu) = gpu() else { return };
    let text = |crop: &str| {
        format!(
            r#"
            [output]
            {crop}
            [render]
            spp = 2
            [camera]
            res = "12x10"
            [[volume]]
            file = "cloud.vdb"
            "#
        )
    };
    let full = render_gpu(&gpu, &scene(&text(""))).unwrap().image;
    let part = render_gpu(&gpu, &scene(&text("crop = [3, 2, 9, 7]"))).unwrap();
    assert_eq!((part.window.x0, part.window.y0), (3, 2));
    for y in 0..5 {
        for x in 0..6 {
            assert_eq!(part.image.pixel(x, y), full.pixel(x + 3, y + 2));
        }
    }
}

/// A volume with no density renders the sky alone, exactly: every camera
/// ray escapes with the sky's radiance.
#[test]
fn an_empty_volume_shows_the_sky() {
    let Some(gpu) = gpu() else { return };
    let s = scene(
        r#"
        [render]
        spp = 2
        [camera]
        res = "6x4"
        [sun]
        enabled = false
        [environment]
        radiance = [0.25, 0.5, 1.0]
        [[volume]]
        file = "empty_grid.vdb"
        "#,
    );
    let image = render_gpu(&gpu, &s).expect("GPU render").image;
    for p in &image.rgba {
        assert_eq!(*p, [0.25, 0.5, 1.0, 0.0]);
    }
}

/// An atlas larger than a binding is split over several, whole bricks a
/// chunk: forced here with a binding limit a third of the cloud's atlas,
/// the image is the unsplit one's, bit for bit (the same numbers read from
/// other buffers).
#[test]
fn a_split_atlas_renders_the_same_bytes() {
    let Some(gpu) = gpu() else { return };
    let s = scene(
        r#"
        [render]
        spp = 2
        seed = 4
        [camera]
        res = "16x12"
        [[volume]]
        file = "cloud.vdb"
        "#,
    );
    let whole = render_gpu(&gpu, &s).expect("GPU render").image;
    let mut cache = cirrus_scene::VolumeCache::default();
    let prepared = s.prepare(&mut cache, None).expect("scene prepares");
    let volume = prepared.scene.media.instances()[0]
        .field
        .still_field()
        .volume();
    let atlas_bytes = volume.atlas().bytes() as u64;
    drop(prepared);
    let limit = atlas_bytes / 3 + 1;
    let split = render_gpu(&gpu.with_binding_limit(limit), &s)
        .expect("GPU render, split")
        .image;
    assert!(
        atlas_bytes > 2 * 4096,
        "a tiny atlas ({atlas_bytes} bytes) proves nothing"
    );
    assert_eq!(bits(&whole, false), bits(&split, false));
}

/// A window whose paths exceed a binding is rendered band by band of
/// rows: forced here with the split-atlas test's binding limit and a
/// window three bands tall (the last one short), the image is the
/// unsplit one's, bit for bit, samples and variance.
#[test]
fn a_window_in_bands_renders_the_same_bytes() {
    let Some(gpu) = gpu() else { return };
    let text = |res: &str| {
        format!(
            r#"
            [render]
            spp = 1
            seed = 6
            [camera]
            res = "{res}"
            [[volume]]
            file = "cloud.vdb"
            "#
        )
    };
    let mut cache = cirrus_scene::VolumeCache::default();
    let s = scene(&text("8x8"));
    let prepared = s.prepare(&mut cache, None).expect("scene prepares");
    let volume = prepared.scene.media.instances()[0]
        .field
        .still_field()
        .volume();
    let limit = volume.atlas().bytes() as u64 / 3 + 1;
    drop(prepared);
    // 80 bytes of path a pixel (kernel.rs, PATH_STATE_BYTES).
    let width = 160;
    let rows = (limit / (80 * u64::from(width))) as u32;
    let height = 2 * rows + rows / 2;
    let s = scene(&text(&format!("{width}x{height}")));
    assert_eq!(cirrus_gpu::window_bands(&gpu, width, height).unwrap(), 1);
    let whole = render_gpu(&gpu, &s).expect("GPU render").image;
    let small = gpu.with_binding_limit(limit);
    assert_eq!(cirrus_gpu::window_bands(&small, width, height).unwrap(), 3);
    let banded = render_gpu(&small, &s).expect("GPU render, banded").image;
    let bits = |i: &cirrus_render::Image| -> Vec<u32> {
        i.rgba
            .iter()
            .chain(&i.variance)
            .flatten()
            .map(|v| v.to_bits())
            .collect()
    };
    assert_eq!(bits(&whole), bits(&banded));
}

/// A scene whose buffers exceed the device's memory is refused before
/// anything is uploaded, with the size it needs (forced with a 1 MiB
/// device).
#[test]
fn a_scene_larger_than_the_device_is_refused_with_its_size() {
    let Some(gpu) = gpu() else { return };
    let s = scene(
        r#"
        [camera]
        res = "8x8"
        [[volume]]
        file = "cloud.vdb"
        "#,
    );
    let err = render_gpu(&gpu.with_memory_limit(1 << 20), &s)
        .err()
        .expect("a 1 MiB device renders the cloud")
        .to_string();
    assert!(
        err.contains("the scene needs")
            && err.contains("MiB on the device")
            && err.contains("the device has 1 MiB"),
        "{err}"
    );
}
