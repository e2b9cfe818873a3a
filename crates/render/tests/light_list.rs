//! The lights are a list, and the integrators take any number of each
//! kind:
//! - a sun split into two suns of half its irradiance, in the same
//!   direction, renders what the one sun renders (pooled bias and
//!   per-pixel spread), with one light picked per vertex among the three
//!   lights (the shadow grid weighing them, sunward scattering toward one
//!   of the two) and with every light sampled, and with the ray marcher;
//! - two constant domes summing to a furnace's radiance keep the white
//!   furnace: a non-absorbing cloud vanishes;
//! - a black light is dropped and costs nothing: the render is the one
//!   without it, bit for bit.

mod common;

use cirrus_render::{
    render, Environment, IntegratorKind, Light, LightSampling, Lights, RenderSettings, Sun,
};
use glam::Vec3;

fn sun(irradiance: Vec3) -> Light {
    Sun::new(Vec3::new(-0.4, -1.0, -0.3), irradiance, 1.0f32.to_radians()).into()
}

fn sky() -> Light {
    Environment::new(Vec3::new(0.2, 0.3, 0.45)).into()
}

const IRRADIANCE: Vec3 = Vec3::new(3.0, 2.8, 2.5);

/// Renders the cloud (g 0.8, so sunward scattering runs under `auto`)
/// under one sun and a sky, and under the sun split in two and the sky,
/// with `s` (different seeds), and checks they agree.
fn assert_split_sun_agrees(label: &str, s: RenderSettings) {
    let medium = || common::medium(common::cloud_field(4), 20.0, 0.95, 0.8);
    let one = Lights::new([sun(IRRADIANCE), sky()]);
    let two = Lights::new([sun(0.5 * IRRADIANCE), sky(), sun(0.5 * IRRADIANCE)]);
    let a = render(&common::scene(medium(), 20, one), &s);
    let b = render(
        &common::scene(medium(), 20, two),
        &RenderSettings {
            seed: s.seed + 1000,
            ..s.clone()
        },
    );
    let c = &b.stats.counters;
    assert_eq!(c.nonfinite_samples, 0, "{label}");
    if s.integrator == IntegratorKind::Path {
        assert!(
            c.nee_rays_distant > 0 && c.nee_rays_dome > 0,
            "{label}: {c:?}"
        );
    }
    for channel in 0..3 {
        let d = common::differences(&a.image, &b.image, channel);
        common::assert_pooled_agreement(&format!("{label}, channel {channel}"), &d);
    }
}

#[test]
fn a_sun_split_in_two_renders_as_the_sun_with_one_light_picked() {
    let mut s = common::settings(IntegratorKind::Path, 64, 7);
    s.light_sampling = LightSampling::One;
    assert_split_sun_agrees("one light per vertex", s);
}

#[test]
fn a_sun_split_in_two_renders_as_the_sun_with_every_light_sampled() {
    let mut s = common::settings(IntegratorKind::Path, 64, 11);
    s.light_sampling = LightSampling::All;
    assert_split_sun_agrees("every light", s);
}

/// The ray marcher (not the two-pass one: its light grid is one random
/// realisation per light, built once, whose error no pixel's standard
/// error sees).
#[test]
fn a_sun_split_in_two_renders_as_the_sun_in_the_ray_marcher() {
    let s = common::settings(IntegratorKind::RayMarch, 32, 13);
    assert_split_sun_agrees("ray marcher", s);
}

/// Two domes of 0.45 and 0.3 around a non-absorbing cloud: every pixel is
/// 0.75, within 5 of its standard errors (see `furnace.rs` for the bound).
#[test]
fn two_domes_keep_the_white_furnace() {
    let l_env = 0.75f32;
    let lights = Lights::new([
        Environment::new(Vec3::splat(0.45)).into(),
        Environment::new(Vec3::splat(0.3)).into(),
    ]);
    let medium = common::medium(common::cloud_field(4), 8.0, 1.0, 0.6);
    let scene = common::scene(medium, 16, lights);
    let mut s = common::settings(IntegratorKind::Path, 64, 23);
    s.max_depth = None;
    let out = render(&scene, &s);
    assert!(out.stats.counters.real_collisions > 1000);
    let img = &out.image;
    let mut worst = 0.0f32;
    for y in 0..img.height {
        for x in 0..img.width {
            let (px, se) = (img.pixel(x, y), img.std_error(x, y));
            for c in 0..3 {
                let z = (px[c] - l_env).abs() / (5.0 * se[c] + 1e-5 * l_env);
                worst = worst.max(z);
            }
        }
    }
    assert!(
        worst <= 1.0,
        "a pixel {worst} bounds from the furnace's 0.75"
    );
}

/// A black sun between a sun and a sky is pruned: the same bits as
/// without it, and no shadow ray more.
#[test]
fn a_black_light_costs_nothing() {
    let medium = || common::medium(common::cloud_field(4), 8.0, 0.9, 0.5);
    let s = common::settings(IntegratorKind::Path, 8, 29);
    let plain = render(
        &common::scene(medium(), 16, Lights::new([sun(IRRADIANCE), sky()])),
        &s,
    );
    let with_black = render(
        &common::scene(
            medium(),
            16,
            Lights::new([sun(IRRADIANCE), sun(Vec3::ZERO), sky()]),
        ),
        &s,
    );
    assert_eq!(common::image_bits(&plain), common::image_bits(&with_black));
    assert_eq!(plain.stats.counters, with_black.stats.counters);
}
