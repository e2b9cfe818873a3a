//! Light groups, holdout volumes and deep samples against the beauty they
//! split, matte or flatten to.

mod common;

use std::sync::Arc;

use cirrus_render::compositing::deep::{flatten, DeepSample};
use cirrus_render::compositing::DEFAULT_LIGHT_GROUPS;
use cirrus_render::{
    Camera, DepthHoldout, Emission, EnvMap, Environment, GridField, Image, IntegratorKind, Lights,
    Medium, RenderSettings, Rendered, Sun, Volumes,
};
use glam::Vec3;

const SIZE: u32 = 24;

fn blob(offset: Vec3) -> GridField {
    common::cloud_field_at(4, offset)
}

/// A lat-long sky brighter toward +Y with a warm band, so the map's
/// importance sampling matters.
fn sky() -> Environment {
    let (w, h) = (16, 8);
    let texels = (0..w * h)
        .map(|i| {
            let row = (i / w) as f32 / h as f32;
            Vec3::new(0.2 + 0.6 * (1.0 - row), 0.3, 0.5 - 0.3 * row)
                * if i % w == 3 { 4.0 } else { 1.0 }
        })
        .collect();
    Environment::from_map(Arc::new(EnvMap::new(w, h, texels, 30.0)), Vec3::ONE)
}

/// A cloud and a glowing blob beside it and in front; `glow` turns the
/// blob's emission on.
fn volumes(glow: bool) -> Volumes<GridField> {
    volumes_with(glow, false)
}

/// [`volumes`], the blob a holdout if `holdout`.
fn volumes_with(glow: bool, holdout: bool) -> Volumes<GridField> {
    let cloud = Medium::new(blob(Vec3::ZERO), 12.0, Vec3::splat(0.9), 0.4);
    let mut ember = Medium::new(blob(Vec3::new(0.45, 0.1, 0.2)), 40.0, Vec3::splat(0.5), 0.0);
    ember.holdout = holdout;
    if glow {
        ember.emission = Some(Emission {
            temperature: None,
            grid: Some((blob(Vec3::new(0.45, 0.1, 0.2)), Vec3::new(2.0, 0.8, 0.3))),
        });
    }
    Volumes::new(vec![cloud, ember])
}

fn camera() -> Camera {
    Camera::new(
        Vec3::new(0.7, 0.6, 2.6),
        Vec3::new(0.7, 0.55, 0.6),
        Vec3::Y,
        40.0,
        SIZE,
        SIZE,
    )
}

fn lights(sun: bool, sky_on: bool) -> Lights {
    Lights::sun_and_sky(
        sun.then(|| Sun::new(Vec3::new(-0.5, -1.0, -0.4), Vec3::new(3.0, 2.8, 2.5), 0.02)),
        sky_on.then(sky),
    )
}

fn settings(integrator: IntegratorKind, spp: u32) -> RenderSettings {
    let mut s = common::settings(integrator, spp, 7);
    s.compositing.light_groups = DEFAULT_LIGHT_GROUPS.iter().map(|s| s.to_string()).collect();
    s
}

/// An image holding one light group's means, with the beauty's variances:
/// the group is a part of the beauty's estimate, positively correlated
/// with the rest (both scale with the path throughput), so the beauty's
/// variance bounds the group's from above and the test stays honest
/// where a pixel's few collisions make one light's own estimate unstable.
fn group_image(r: &Rendered, group: usize) -> Image {
    let g = &r.layers.as_ref().unwrap().groups[group];
    Image {
        rgba: g.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect(),
        ..r.image.clone()
    }
}

/// The groups sum to the beauty within 1e-5 relative per pixel, for the
/// path tracer and both marchers.
#[test]
fn light_groups_sum_to_the_beauty() {
    for integrator in [
        IntegratorKind::Path,
        IntegratorKind::RayMarch,
        IntegratorKind::RayMarch2Pass,
    ] {
        let r = common::render_through(
            &volumes(true),
            &camera(),
            &lights(true, true),
            &settings(integrator, 16),
        );
        let layers = r.layers.as_ref().unwrap();
        let mut worst = 0.0f32;
        for (i, px) in r.image.rgba.iter().enumerate() {
            for c in 0..3 {
                let sum: f32 = layers.groups.iter().map(|g| g[i][c]).sum();
                worst = worst.max((sum - px[c]).abs() / px[c].abs().max(1e-3));
            }
        }
        eprintln!("{}: largest relative gap {worst:e}", integrator.name());
        assert!(worst <= 1e-5, "{}: {worst}", integrator.name());
        for g in &layers.groups {
            let total: f32 = g.iter().map(|p| p[0] + p[1] + p[2]).sum();
            assert!(total > 0.0, "{}: an empty group", integrator.name());
        }
    }
}

/// Each group of the path tracer agrees, within noise, with a render that
/// has only that light on.
#[test]
fn each_group_is_its_light_alone() {
    let spp = 64;
    let all = common::render_through(
        &volumes(true),
        &camera(),
        &lights(true, true),
        &settings(IntegratorKind::Path, spp),
    );
    let solo = [
        common::render_through(
            &volumes(false),
            &camera(),
            &lights(true, false),
            &settings(IntegratorKind::Path, spp),
        ),
        common::render_through(
            &volumes(false),
            &camera(),
            &lights(false, true),
            &settings(IntegratorKind::Path, spp),
        ),
        common::render_through(
            &volumes(true),
            &camera(),
            &lights(false, false),
            &settings(IntegratorKind::Path, spp),
        ),
    ];
    for (g, alone) in solo.iter().enumerate() {
        let group = group_image(&all, g);
        for c in 0..3 {
            let d = common::differences(&group, &alone.image, c);
            common::assert_pooled_agreement(
                &format!("group {} channel {c}", DEFAULT_LIGHT_GROUPS[g]),
                &d,
            );
        }
    }
}

/// A holdout volume: pixels its camera paths never reached are bit for bit
/// the render without the flag (it still lights and shadows the cloud);
/// alpha drops by exactly its coverage; where every sample met it first,
/// the pixel is black and transparent.
#[test]
fn a_holdout_volume_is_a_matte() {
    let mut s = settings(IntegratorKind::Path, 32);
    s.compositing.cryptomatte = true;
    let sun = lights(true, true);
    let plain = common::render_through(&volumes(false), &camera(), &sun, &s);
    let out = common::render_through(&volumes_with(false, true), &camera(), &sun, &s);
    let cov = &plain.layers.as_ref().unwrap().coverage;
    let (mut untouched, mut covered) = (0, 0);
    for (i, pixel) in cov.iter().enumerate() {
        let of_holdout: f32 = pixel.iter().filter(|(k, _)| *k == 1).map(|(_, c)| c).sum();
        let (a, b) = (plain.image.rgba[i], out.image.rgba[i]);
        assert!(
            (b[3] - (a[3] - of_holdout)).abs() <= 1e-5,
            "pixel {i}: alpha {} vs {} - {of_holdout}",
            b[3],
            a[3]
        );
        if of_holdout == 0.0 {
            assert_eq!(a, b, "pixel {i}: no path met the holdout first");
            untouched += 1;
        } else if of_holdout >= 1.0 {
            assert_eq!(b, [0.0; 4], "pixel {i}: every path met the holdout first");
            covered += 1;
        }
    }
    eprintln!("{untouched} pixels untouched, {covered} wholly held out");
    assert!(untouched > 50 && covered > 20, "{untouched}, {covered}");
}

/// Deep samples flatten ("over", front to back) to the flat pixel to float
/// rounding, at any sample budget.
#[test]
fn deep_samples_flatten_to_the_flat_render() {
    for budget in [16, 3] {
        let mut s = settings(IntegratorKind::Path, 32);
        s.compositing.deep_samples = Some(budget);
        let r = common::render_through(&volumes(true), &camera(), &lights(true, true), &s);
        let deep = &r.layers.as_ref().unwrap().deep;
        let mut worst = 0.0f32;
        for (px, samples) in r.image.rgba.iter().zip(deep) {
            assert!(samples.len() <= budget as usize + 1);
            let flat = flatten(samples);
            for c in 0..4 {
                worst = worst.max((flat[c] - px[c]).abs() / px[c].abs().max(1e-3));
            }
        }
        eprintln!("budget {budget}: largest relative gap {worst:e}");
        assert!(worst <= 1e-5, "{worst}");
    }
}

/// OpenEXR's deep holdout at planar depth d: samples behind d dropped, a
/// sample straddling d split with alpha `1 - (1 - a)^f` for the fraction
/// `f` of it in front.
fn cut(samples: &[DeepSample], d: f32) -> Vec<DeepSample> {
    samples
        .iter()
        .filter(|s| s.z < d)
        .map(|s| {
            if s.z_back <= d || s.z_back == s.z {
                return *s;
            }
            let f = (d - s.z) / (s.z_back - s.z);
            let alpha = 1.0 - (1.0 - s.alpha).powf(f);
            let k = if s.alpha > 0.0 { alpha / s.alpha } else { f };
            DeepSample {
                z_back: d,
                rgb: s.rgb.map(|c| c * k),
                alpha,
                ..*s
            }
        })
        .collect()
}

/// The deep image held out at depth d agrees within noise with the render
/// whose camera rays end at d (`--holdout-depth`).
#[test]
fn a_deep_holdout_is_the_depth_holdout() {
    let spp = 64;
    let cam = camera();
    // The cloud spans planar depths of about 1.4 to 2.6: the plane cuts
    // both volumes.
    let d = 1.7;
    let mut s = settings(IntegratorKind::Path, spp);
    s.compositing.deep_samples = Some(16);
    let deep = common::render_through(&volumes(false), &cam, &lights(true, true), &s);
    let mut s = settings(IntegratorKind::Path, spp);
    let depth = vec![d; (SIZE * SIZE) as usize];
    s.compositing.holdout_depth = Some(Arc::new(
        DepthHoldout::new(SIZE, SIZE, depth, 1e10).unwrap(),
    ));
    let held = common::render_through(&volumes(false), &cam, &lights(true, true), &s);
    let cut_image = Image {
        rgba: deep
            .layers
            .as_ref()
            .unwrap()
            .deep
            .iter()
            .map(|p| flatten(&cut(p, d)))
            .collect(),
        ..held.image.clone()
    };
    let full_alpha: f32 = deep.image.rgba.iter().map(|p| p[3]).sum();
    let held_alpha: f32 = held.image.rgba.iter().map(|p| p[3]).sum();
    eprintln!("alpha summed: {full_alpha} whole, {held_alpha} held out at {d}");
    assert!(
        held_alpha < 0.8 * full_alpha,
        "the plane must cut the cloud"
    );
    for c in 0..4 {
        let d = common::differences(&cut_image, &held.image, c);
        common::assert_pooled_agreement(&format!("deep cut channel {c}"), &d);
    }
}

/// Every layer is the same on one thread as on three.
#[test]
fn layers_do_not_depend_on_the_thread_count() {
    let mut s = settings(IntegratorKind::Path, 8);
    s.compositing.cryptomatte = true;
    s.compositing.deep_samples = Some(4);
    let run = |threads: usize| {
        common::with_threads(threads, || {
            common::render_through(&volumes(true), &camera(), &lights(true, true), &s)
        })
    };
    let (one, three) = (run(1), run(3));
    assert_eq!(one.image, three.image);
    assert_eq!(one.layers, three.layers);
    let layers = one.layers.unwrap();
    assert!(
        layers.deep.iter().any(|p| p.len() > 1) && layers.coverage.iter().any(|p| p.len() == 2)
    );
}
