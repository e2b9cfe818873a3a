//! Sunward scattering stays exact and reproducible:
//! - renders with and without it agree within noise (pooled bias and
//!   per-pixel spread) under a delta sun and a sky with one light picked
//!   per vertex, under a disc sun (whose samples are weighed against
//!   phase sampling) with every light sampled and a Mie phase function,
//!   in a chromatic medium, and with the scattering depth limited (the
//!   last vertex's continuation gathers nothing, so the strategy must not
//!   run there);
//! - its renders are the same, bit for bit, on one thread and two, and a
//!   crop of one is the full render's pixels;
//! - `auto` runs it where the phase function is forward-peaked and
//!   nowhere else, where it renders what `off` does.

mod common;

use cirrus_render::{
    render, Emission, Extinction, IntegratorKind, LightSampling, Lights, Medium, Phase, Sunward,
};
use glam::Vec3;

fn lights(sun_degrees: f32) -> Lights {
    Lights::sun_and_sky(
        common::sun(sun_degrees),
        common::env(Vec3::new(0.2, 0.3, 0.45)),
    )
}

fn sunlit<F: cirrus_render::DensityField>(
    medium: Medium<F>,
    sun_degrees: f32,
) -> cirrus_render::Scene<cirrus_render::Volumes<F>> {
    common::scene(medium, 20, lights(sun_degrees))
}

/// Renders `scene` with sunward scattering on and off (different seeds)
/// and checks the two agree, and that the strategy ran.
fn assert_agrees<M: cirrus_render::Media>(
    label: &str,
    scene: &cirrus_render::Scene<M>,
    mut s: cirrus_render::RenderSettings,
) {
    s.sunward = Sunward::Off;
    let off = render(scene, &s);
    assert_eq!(off.stats.counters.sunward_rays, 0, "{label}");
    s.sunward = Sunward::On;
    s.seed += 1000;
    let on = render(scene, &s);
    let c = &on.stats.counters;
    assert!(c.sunward_rays > 100, "{label}: {c:?}");
    assert_eq!(c.nonfinite_samples, 0, "{label}");
    for channel in 0..3 {
        let d = common::differences(&on.image, &off.image, channel);
        common::assert_pooled_agreement(&format!("{label}, channel {channel}"), &d);
    }
}

#[test]
fn delta_sun_and_sky_with_one_light_per_vertex() {
    // Peak optical depth about 35: long paths, many sunward vertices.
    let scene = sunlit(common::medium(common::cloud_field(4), 50.0, 0.99, 0.8), 0.0);
    let mut s = common::settings(IntegratorKind::Path, 64, 41);
    s.light_sampling = LightSampling::One;
    assert_agrees("delta sun, one light", &scene, s);
}

#[test]
fn disc_sun_with_every_light_and_mie() {
    let medium = common::medium(common::cloud_field(4), 30.0, 0.95, 0.0)
        .with_phase(Phase::mie(10.0).unwrap());
    let scene = sunlit(medium, 5.0);
    let mut s = common::settings(IntegratorKind::Path, 64, 43);
    s.light_sampling = LightSampling::All;
    assert_agrees("disc sun, every light, Mie", &scene, s);
}

#[test]
fn chromatic_medium() {
    let e = Extinction::split(Vec3::new(1.0, 0.6, 0.3) * 40.0);
    let medium = Medium::new(common::cloud_field(4), e.scale, Vec3::splat(0.98), 0.75)
        .with_extinction_tint(e.tint);
    let scene = sunlit(medium, 0.0);
    assert_agrees(
        "chromatic",
        &scene,
        common::settings(IntegratorKind::Path, 64, 45),
    );
}

#[test]
fn limited_scattering_depth() {
    let scene = sunlit(common::medium(common::cloud_field(4), 40.0, 0.99, 0.8), 0.0);
    for depth in [2, 3] {
        let mut s = common::settings(IntegratorKind::Path, 256, 47 + u64::from(depth));
        s.max_depth = Some(depth);
        assert_agrees(&format!("max depth {depth}"), &scene, s);
    }
    // In emitting media a path goes on past its last scattering vertex
    // to gather emission only: no sunlight may be gathered from there.
    let emitting =
        common::medium(common::cloud_field(4), 40.0, 0.95, 0.8).with_emission(Emission {
            temperature: None,
            grid: Some((common::cloud_field(4), Vec3::new(0.06, 0.04, 0.02))),
        });
    let mut s = common::settings(IntegratorKind::Path, 512, 51);
    s.max_depth = Some(2);
    assert_agrees("max depth 2, emitting", &sunlit(emitting, 0.0), s);
}

#[test]
fn sunward_renders_are_the_same_on_any_thread_count_and_in_crops() {
    let scene = sunlit(common::medium(common::cloud_field(4), 50.0, 0.99, 0.8), 0.0);
    let mut s = common::settings(IntegratorKind::Path, 16, 5);
    s.sunward = Sunward::On;
    s.tile_size = 8;
    let one = common::with_threads(1, || render(&scene, &s));
    let two = common::with_threads(2, || render(&scene, &s));
    assert!(two.stats.counters.sunward_rays > 0);
    assert_eq!(common::image_bits(&one), common::image_bits(&two));
    s.crop = Some(common::CROP);
    s.tile_size = 4;
    let part = render(&scene, &s);
    common::assert_crop_of("sunward", &part, &two, common::CROP);
}

#[test]
fn auto_runs_where_the_phase_function_is_forward_peaked() {
    for (g, runs) in [(0.5, false), (0.59, false), (0.6, true), (0.85, true)] {
        let scene = sunlit(common::medium(common::cloud_field(4), 30.0, 0.99, g), 0.0);
        let mut s = common::settings(IntegratorKind::Path, 8, 3);
        s.sunward = Sunward::Auto;
        let auto = render(&scene, &s);
        assert_eq!(auto.stats.sunward, "auto");
        assert_eq!(auto.stats.counters.sunward_rays > 0, runs, "g {g}");
        if !runs {
            s.sunward = Sunward::Off;
            let off = render(&scene, &s);
            assert_eq!(common::image_bits(&off), common::image_bits(&auto), "g {g}");
        }
    }
}
