//! What the GPU kernel renders, and the refusal of everything else by
//! name: a scene the kernel cannot render exactly as the CPU would (in
//! expectation) is never rendered differently in silence.

use cirrus_bricks::Precision;
use cirrus_kernel::medium::BrickField;
use cirrus_kernel::transform_motion::MovingField;
use cirrus_render::{
    IntegratorKind, Light, LightSampling, RenderSettings, SamplerKind, Scene, Sunward, Volumes,
};

/// The prepared scene the GPU backend takes: what `cirrus-scene` prepares
/// for every render.
pub type PreparedScene<'v> = Scene<Volumes<MovingField<BrickField<'v>>>>;

/// What the scene or settings ask for that the GPU kernel does not do,
/// each named; empty when it renders them.
pub fn unsupported(scene: &PreparedScene, settings: &RenderSettings) -> Vec<String> {
    let mut out = Vec::new();
    let mut no = |what: &str| out.push(what.to_string());
    if settings.integrator != IntegratorKind::Path {
        no(&format!("the {} integrator", settings.integrator.name()));
    }
    if settings.adaptive.is_some() {
        no("adaptive sampling");
    }
    if settings.aovs {
        no("AOVs");
    }
    if settings.halves {
        no("denoising");
    }
    let c = &settings.compositing;
    if !c.light_groups.is_empty() {
        no("light groups");
    }
    if c.cryptomatte {
        no("Cryptomatte");
    }
    if c.deep_samples.is_some() {
        no("deep images");
    }
    if c.holdout_depth.is_some() {
        no("depth holdouts");
    }
    if scene.camera.moves() {
        no("camera motion blur");
    }
    if scene.camera.near() != 0.0 {
        no("near clipping");
    }
    let mut local_lights = false;
    for light in scene.lights.clone().pruned().iter() {
        local_lights |= !light.is_at_infinity();
        if matches!(light, Light::Dome(env) if env.map.is_some()) {
            no("environment maps (a constant sky only)");
        }
    }
    if scene.lights.over_shutter().is_some() {
        no("lights moving while the shutter is open");
    }
    let instances = scene.media.instances();
    if instances.len() != 1 {
        no(&format!(
            "several volumes ({} in this scene; one only)",
            instances.len()
        ));
    }
    // A chromatic medium's flight weights are not memoryless, so the
    // kernel cannot stop a flight's weight at a light's surface or a
    // shadow ray's track-length weight at a lamp: its lights are all at
    // infinity.
    for m in instances {
        if local_lights && m.extinction_tint != glam::Vec3::ONE {
            no("sphere, point, spot and area lights in chromatic media");
        }
        if m.field.moves() || m.field.still_field().moves() {
            no("volume motion blur");
        }
        if m.emission.is_some() {
            no("emission");
        }
        if m.holdout {
            no("holdout volumes");
        }
        if m.field.still_field().volume().precision() == Precision::U8 {
            no("u8 bricks (f32 or f16 only)");
        }
    }
    out.sort();
    out.dedup();
    out
}

/// Where the GPU estimates the same image of `scene` by other means than
/// `settings` name (each unbiased, so the expectation is the same; the
/// noise is not), in words, for the caller to say; `None` where it uses
/// those.
pub fn substitutions(scene: &PreparedScene, settings: &RenderSettings) -> Option<String> {
    let mut out = Vec::new();
    // The CPU's rule (`PathTracer::with_distance_sampling`): equi-angular
    // samples toward sphere, point and spot lights where the setting
    // and the media say so.
    let points = scene
        .lights
        .clone()
        .pruned()
        .iter()
        .any(|l| l.point_centre().is_some());
    if points && settings.distance_sampling.samples_equiangular(&scene.media) {
        out.push(format!(
            "free flights alone (no equi-angular sampling toward sphere lights) for \
             --distance-sampling {}",
            settings.distance_sampling.name()
        ));
    }
    if settings.sampler != SamplerKind::Random {
        out.push(format!(
            "random numbers for --sampler {}",
            settings.sampler.name()
        ));
    }
    if settings.light_sampling != LightSampling::All {
        out.push(format!(
            "every light at each vertex for --light-sampling {}",
            settings.light_sampling.name()
        ));
    }
    if settings.sunward != Sunward::Off {
        out.push(format!(
            "no sunward scattering for --sunward {}",
            settings.sunward.name()
        ));
    }
    (!out.is_empty()).then(|| out.join(", "))
}
