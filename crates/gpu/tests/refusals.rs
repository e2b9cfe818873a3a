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
    let mut settings = cirrus_render::RenderSettings::default();
    let said = cirrus_gpu::substitutions(&settings).expect("the defaults differ");
    for want in ["--sampler sobol", "--sunward auto"] {
        assert!(said.contains(want), "{want:?} not in {said:?}");
    }
    for never in ["--transmittance", "--majorant"] {
        assert!(!said.contains(never), "{never:?} in {said:?}");
    }
    settings.sampler = cirrus_render::SamplerKind::Random;
    settings.light_sampling = cirrus_render::LightSampling::All;
    settings.sunward = cirrus_render::Sunward::Off;
    assert_eq!(cirrus_gpu::substitutions(&settings), None);
}
