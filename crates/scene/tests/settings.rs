//! Every setting is declared once (`description.rs`); these tests hold its
//! forms to that declaration:
//!
//! - each setting with a flag has one, under its keyword, and the README's
//!   table is the one made from the declaration (`CIRRUS_WRITE_README=1`
//!   rewrites it);
//! - each setting, given alone as an override (its declared example, in a
//!   context where it matters), changes what the renderer is handed.

use std::path::{Path, PathBuf};

use cirrus_scene::{examples, settings, settings_table, Overrides, Scene, VolumeCache};

const BEGIN: &str = "<!-- settings: made from crates/scene/src/description.rs -->\n";
const END: &str = "<!-- end of settings -->";

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn the_readme_table_is_the_declaration() {
    let table = settings_table();
    assert!(
        !table.contains("| ? |"),
        "a setting without a flag:\n{table}"
    );
    let path = repo().join("README.md");
    let readme = std::fs::read_to_string(&path).unwrap();
    let start = readme.find(BEGIN).expect("README marks the settings table") + BEGIN.len();
    let end = start + readme[start..].find(END).expect("the table's end mark");
    if std::env::var_os("CIRRUS_WRITE_README").is_some() {
        let written = format!("{}{table}{}", &readme[..start], &readme[end..]);
        std::fs::write(&path, written).unwrap();
        return;
    }
    assert_eq!(
        readme[start..end],
        table,
        "README.md's settings table differs from the declaration; \
         CIRRUS_WRITE_README=1 cargo test -p cirrus-scene --test settings rewrites it"
    );
}

#[test]
fn every_setting_with_a_flag_has_an_example() {
    let declared: Vec<&str> = settings()
        .iter()
        .filter(|s| s.has_flag)
        .map(|s| s.keyword)
        .collect();
    let examples: Vec<&str> = examples().iter().map(|(k, _)| *k).collect();
    assert_eq!(declared, examples);
    assert!(declared.len() >= 40, "{} settings", declared.len());
}

/// What a setting must be given with to matter at all.
fn context(keyword: &str) -> Overrides {
    let mut o = Overrides::default();
    match keyword {
        // Adaptive sampling's most samples (spp) at least its fewest.
        "min_spp" => {
            o.noise_threshold = Some(0.05);
            o.spp = Some(32);
        }
        "noise_threshold" => o.spp = Some(32),
        "step" | "shadow_step" => o.integrator = Some(cirrus_render::IntegratorKind::RayMarch),
        "g2" | "lobe_weight" => o.phase = Some("hg2".into()),
        "droplet_diameter" => o.phase = Some("mie".into()),
        "draine_alpha" => o.phase = Some("draine".into()),
        "velocity" => o.shutter = Some([-0.25, 0.25]),
        "velocity_unit" | "velocity_scale" => {
            o.shutter = Some([-0.25, 0.25]);
            o.velocity = Some("velocity".into());
        }
        "deep_samples" => o.deep = Some(PathBuf::from("deep.exr")),
        "holdout_far" => o.holdout_depth = Some(depth_image().display().to_string()),
        "env_rotation" | "env_intensity" => {
            o.env_map = Some(repo().join("data/sky.exr"));
        }
        _ => {}
    }
    o
}

/// A 6x4 depth image (planar depths from 1 to 24, as another renderer's
/// Z pass), written once.
fn depth_image() -> PathBuf {
    use exr::prelude::*;
    let path = std::env::temp_dir().join(format!("cirrus-settings-{}.exr", std::process::id()));
    if !path.exists() {
        let depths: Vec<f32> = (1..=24).map(|d| d as f32).collect();
        let channel = AnyChannel::new("Z", FlatSamples::F32(depths));
        let layer = Layer::new(
            (6, 4),
            LayerAttributes::default(),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(smallvec::smallvec![channel]),
        );
        Image::from_layer(layer).write().to_file(&path).unwrap();
    }
    path
}

/// Everything the renderer is handed for `scene`, and the outputs: the
/// render settings, camera, lights, each medium (its parameters, its
/// field's bounds and majorant, its densities mid-shutter and the
/// segments along one ray, which the majorant refinement changes), and
/// the frame range a sequence renders.
fn handed(scene: &Scene) -> String {
    let mut cache = VolumeCache::default();
    let p = match scene.prepare(&mut cache, None) {
        Ok(p) => p,
        Err(e) => return format!("error: {e}"),
    };
    let mut s = format!(
        "{:?}\n{:?}\n{:?}\n{:?}\n{:?}\n{:?}\n",
        p.settings,
        p.scene.camera,
        p.scene.lights,
        scene.outputs(),
        scene.description().render.frames,
        // Where it renders: the caller's choice of device, not the renderer's.
        scene.settings().map(|s| s.device).ok()
    );
    use cirrus_render::{DensityField, Media};
    let b = p.scene.media.bounds();
    let mid = 0.5 * (b.min + b.max);
    // Mid-shutter densities on a 9^3 lattice over the bounds.
    let lattice = (0..729).map(|i| {
        let f = glam::Vec3::new((i % 9) as f32, ((i / 9) % 9) as f32, (i / 81) as f32) / 8.0;
        b.min + (b.max - b.min) * f
    });
    let lattice: Vec<glam::Vec3> = lattice.collect();
    for m in p.scene.media.instances() {
        let moved: f32 = lattice.iter().map(|&q| m.field.density_at(q, 0.5)).sum();
        let segments: usize = [glam::Vec3::X, glam::Vec3::Y, glam::Vec3::Z]
            .into_iter()
            .map(|axis| m.field.segments(mid, axis, 0.0, f32::INFINITY).count())
            .sum();
        s += &format!(
            "{} {} {} {:?} {:?} {} {} {}\n",
            m.density_scale,
            m.extinction_tint,
            m.albedo,
            m.phase,
            m.field.bounds(),
            m.field.global_majorant(),
            moved,
            segments
        );
    }
    s
}

/// The name `renamed_velocity()` gives multi_grid.vdb's "velocity" grid:
/// of the same length, so the file's layout is unchanged.
const RENAMED_VELOCITY: &str = "motion_v";

/// multi_grid.vdb with its velocity grid renamed, so that no grid has a
/// name looked for by default; written once.
fn renamed_velocity() -> PathBuf {
    let path = std::env::temp_dir().join(format!("cirrus-settings-{}.vdb", std::process::id()));
    if !path.exists() {
        let mut bytes = std::fs::read(repo().join("data/multi_grid.vdb")).unwrap();
        let (from, to) = (b"velocity", RENAMED_VELOCITY.as_bytes());
        let mut renamed = 0;
        for i in 0..bytes.len().saturating_sub(from.len()) {
            if &bytes[i..i + from.len()] == from {
                bytes[i..i + from.len()].copy_from_slice(to);
                renamed += 1;
            }
        }
        assert!(renamed > 0);
        std::fs::write(&path, bytes).unwrap();
    }
    path
}

/// A 6x4 image of `file` (in data/, or an absolute path) from a fixed
/// camera.
fn base_scene(file: &str) -> Scene {
    let data = repo().join("data");
    let base = format!(
        r#"
        [camera]
        res = "6x4"
        from = [300.0, 60.0, 400.0]
        to = [60.0, 40.0, 60.0]
        [render]
        spp = 2
        [[volume]]
        file = "{}"
        "#,
        data.join(file).display()
    );
    let description = cirrus_scene::SceneDescription::parse(&base).unwrap();
    Scene::from_description(description, &data).unwrap()
}

#[test]
fn every_setting_reaches_the_renderer() {
    for (keyword, example) in examples() {
        // The test files' velocity grids have 1-unit voxels, where world
        // units and voxels are one unit; `crates/render/tests/motion_blur.rs`
        // checks the voxel unit on a grid of 2-unit voxels.
        if keyword == "velocity_unit" {
            continue;
        }
        // A file with a velocity grid, or for the grid's choice one with
        // two density-like grids.
        let renamed = renamed_velocity();
        let file = match keyword {
            "grid" => "fireball.vdb",
            // multi_grid.vdb's "velocity" is found unnamed; a grid of
            // another name is not.
            "velocity" => renamed.to_str().unwrap(),
            _ => "multi_grid.vdb",
        };
        let mut before = base_scene(file);
        before.apply(&context(keyword));
        let mut after = before.clone();
        after.apply(&example);
        if keyword == "velocity" {
            after.apply(&Overrides {
                velocity: Some(RENAMED_VELOCITY.into()),
                ..Default::default()
            });
        }
        if keyword == "holdout_depth" {
            // The declared example names no file here: the one written.
            after.apply(&Overrides {
                holdout_depth: Some(depth_image().display().to_string()),
                ..Default::default()
            });
        }
        let (a, b) = (handed(&before), handed(&after));
        assert!(!a.starts_with("error"), "{keyword}: the context fails: {a}");
        assert!(!b.starts_with("error"), "{keyword}: the example fails: {b}");
        assert_ne!(a, b, "{keyword} changes nothing the renderer is handed");
    }
}

/// The render crate's `RenderSettings::default()` is the render a scene
/// with nothing set gets (the command line without flags): every setting
/// equal, and so the same image from both.
#[test]
fn the_render_crates_defaults_are_the_declared_ones() {
    use cirrus_render::{Budget, RenderSettings};
    let mut scene = Scene::load(&repo().join("data/cloud.vdb")).unwrap();
    let declared = scene.settings().unwrap().render;
    let library = RenderSettings {
        progress: false,
        ..RenderSettings::default()
    };
    assert_eq!(format!("{declared:?}"), format!("{library:?}"));

    // A small view, its sample count lowered alike on both sides.
    scene.apply(&Overrides {
        res: Some((20, 16)),
        spp: Some(2),
        ..Default::default()
    });
    let mut cache = VolumeCache::default();
    let p = scene.prepare(&mut cache, None).unwrap();
    let library = RenderSettings {
        progress: false,
        budget: Budget::Spp(2),
        ..RenderSettings::default()
    };
    let a = cirrus_render::render(&p.scene, &p.settings).image;
    let b = cirrus_render::render(&p.scene, &library).image;
    assert!(
        a.rgba.iter().any(|px| px[3] > 0.0),
        "the view sees the cloud"
    );
    let bits = |img: &cirrus_render::Image| -> Vec<u32> {
        img.rgba.iter().flatten().map(|v| v.to_bits()).collect()
    };
    assert_eq!(bits(&a), bits(&b));
}

/// The keys `data/scene_example.toml` shows, set or commented out, by
/// table: a line `key = ...` (after an optional `# `) under `[table]` or
/// `[[table]]` (itself perhaps commented out).
fn example_keys(text: &str) -> Vec<(String, String)> {
    let mut table = String::new();
    let mut keys = Vec::new();
    for line in text.lines() {
        let line = line.trim_start_matches('#').trim();
        if line.starts_with('[') {
            let name = line.trim_matches(|c| c == '[' || c == ']');
            if name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
                table = name.to_string();
            }
            continue;
        }
        let Some((key, _)) = line.split_once('=') else {
            continue;
        };
        let key = key.trim();
        if !key.is_empty() && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            keys.push((table.clone(), key.to_string()));
        }
    }
    keys
}

#[test]
fn the_example_scene_names_every_setting_and_renders_as_read() {
    let path = repo().join("data/scene_example.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let shown = example_keys(&text);
    let missing: Vec<String> = settings()
        .iter()
        .filter(|s| !shown.iter().any(|(t, k)| t == s.table && k == s.key))
        .map(|s| format!("[{}] {}", s.table, s.key))
        .collect();
    assert!(
        missing.is_empty(),
        "data/scene_example.toml, the commented reference, lacks: {}",
        missing.join(", ")
    );
    // And what it sets (uncommented) is a valid scene.
    cirrus_scene::SceneDescription::read(&path).unwrap();
}
