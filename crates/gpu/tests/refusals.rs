//! What the GPU does not render is refused by name, before any device is
//! needed.

mod common;

use cirrus_scene::VolumeCache;
use common::scene;

/// What `cirrus_gpu::unsupported` names for a scene of `toml`.
fn refused(toml: &str) -> Vec<String> {
    let s = scene(toml);
    let mut cache = VolumeCache::default();
    let prepared = s.prepare(&mut cache, None).expect("scene prepares");
    cirrus_gpu::unsupported(&prepared.scene, &prepared.settings)
}

#[test]
fn the_default_scene_is_supported() {
    let names = refused(
        r#"
        [[volume]]
        file = "cloud.vdb"
        "#,
    );
    assert!(names.is_empty(), "{names:?}");
}

#[test]
fn unsupported_features_are_named() {
    let names = refused(
        r#"
        [render]
        integrator = "raymarch"
        noise_threshold = 0.05
        [environment]
        map = "sky.exr"
        [[volume]]
        file = "cloud.vdb"
        "#,
    );
    for want in [
        "the raymarch integrator",
        "adaptive sampling",
        "environment maps",
    ] {
        assert!(
            names.iter().any(|n| n.contains(want)),
            "{want:?} not named in {names:?}"
        );
    }
    let message = cirrus_gpu::GpuError::Unsupported(names).to_string();
    assert!(
        message.contains("--device gpu does not render"),
        "{message}"
    );
    assert!(message.contains("use --device cpu"), "{message}");
}

/// Every phase function renders: HG, two-lobe HG, Draine, the
/// approximate Mie fit and Rayleigh are one form on the device (a table
/// has its own, `tests/render.rs`).
#[test]
fn every_phase_function_is_supported() {
    for phase in ["hg", "hg2", "draine", "mie", "rayleigh"] {
        let names = refused(&format!(
            r#"
            [[volume]]
            file = "cloud.vdb"
            phase = "{phase}"
            "#
        ));
        assert!(names.is_empty(), "{phase}: {names:?}");
    }
}

/// Estimators the GPU does not have are said, not refused: its own reach
/// the same expectation. The majorants and shadow rays' estimator are the
/// settings' own, never said.
#[test]
fn substituted_estimators_are_said() {
    let s = scene(
        r#"
        [[volume]]
        file = "cloud.vdb"
        "#,
    );
    let mut cache = VolumeCache::default();
    let prepared = s.prepare(&mut cache, None).expect("scene prepares");
    let substitutions = |settings: &cirrus_render::RenderSettings| {
        cirrus_gpu::substitutions(&prepared.scene, settings)
    };
    let mut settings = cirrus_render::RenderSettings::default();
    let said = substitutions(&settings).expect("the defaults differ");
    for want in ["--sampler sobol", "--sunward auto"] {
        assert!(said.contains(want), "{want:?} not in {said:?}");
    }
    for never in ["--transmittance", "--majorant", "--distance-sampling"] {
        assert!(!said.contains(never), "{never:?} in {said:?}");
    }
    settings.sampler = cirrus_render::SamplerKind::Random;
    settings.light_sampling = cirrus_render::LightSampling::All;
    settings.sunward = cirrus_render::Sunward::Off;
    assert_eq!(substitutions(&settings), None);
}

/// Sphere, point and spot lights (soft falloff too) and area lights
/// (rects, discs, cylinders) render; lights that
/// move while the shutter is open are refused by name; equi-angular
/// sampling toward sphere lights, where the settings ask for it, is
/// said as substituted.
#[test]
fn local_lights_render_and_moving_ones_are_refused() {
    let lights = r#"
        [[volume]]
        file = "cloud.vdb"
        [[light]]
        type = "sphere"
        position = [100, 80, 100]
        radius = 5
        [[light]]
        type = "point"
        position = [150, 80, 100]
        [[light]]
        type = "spot"
        position = [150, 150, 100]
        direction = [0, -1, 0]
        cone_angle = 30
        cone_softness = 0.4
        radius = 2
        soft_falloff = true
        [[light]]
        type = "rect"
        position = [150, 160, 100]
        direction = [0, -1, 0]
        [[light]]
        type = "disk"
        position = [150, 160, 100]
        direction = [0, -1, 0]
        [[light]]
        type = "cylinder"
        position = [150, 160, 100]
        direction = [1, 0, 0]
        "#;
    let names = refused(lights);
    assert!(names.is_empty(), "{names:?}");
    let moving = refused(&format!(
        r#"
        [render]
        shutter = [0.0, 0.5]
        {lights}
        keys = [{{ time = 0, position = [150, 150, 100] }}, {{ time = 1, position = [160, 150, 100] }}]
        "#
    ));
    assert!(
        moving
            .iter()
            .any(|n| n.contains("lights moving while the shutter is open")),
        "{moving:?}"
    );
    let s = scene(lights);
    let mut cache = VolumeCache::default();
    let prepared = s.prepare(&mut cache, None).expect("scene prepares");
    let mut settings = prepared.settings.clone();
    settings.distance_sampling = cirrus_render::DistanceSampling::Equiangular;
    let said = cirrus_gpu::substitutions(&prepared.scene, &settings).unwrap_or_default();
    assert!(said.contains("--distance-sampling equiangular"), "{said}");
    settings.distance_sampling = cirrus_render::DistanceSampling::FreeFlight;
    let said = cirrus_gpu::substitutions(&prepared.scene, &settings).unwrap_or_default();
    assert!(!said.contains("--distance-sampling"), "{said}");
}

/// A chromatic medium renders under lights at infinity; a local light in
/// it is refused by name (its flight weights are not memoryless, so the
/// kernel cannot stop them at a lamp).
#[test]
fn local_lights_in_chromatic_media_are_refused() {
    let chromatic = r#"
        [[volume]]
        file = "cloud.vdb"
        density_scale = [2, 1, 0.5]
        "#;
    let names = refused(chromatic);
    assert!(names.is_empty(), "{names:?}");
    let names = refused(&format!(
        r#"
        {chromatic}
        [[light]]
        type = "point"
        position = [150, 80, 100]
        "#
    ));
    assert_eq!(
        names,
        vec!["sphere, point, spot and area lights in chromatic media".to_string()]
    );
}
