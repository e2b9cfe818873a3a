//! The HDR environment map against the lights it must reduce to: a
//! constant map is the constant environment, and a map dark but for one
//! texel is a sun of irradiance `L * texel solid angle` from that texel.

mod common;

use std::sync::Arc;

use cirrus_render::{render, EnvMap, Environment, IntegratorKind, Lights, Sun};
use glam::Vec3;

/// Per-pixel (5 combined standard errors: 5.7e-7 false failures per pixel)
/// and pooled agreement of two renders' green channels.
fn assert_agree(label: &str, a: &cirrus_render::Image, b: &cirrus_render::Image) {
    common::assert_pooled_agreement(label, &common::differences(a, b, 1));
    for y in 0..a.height {
        for x in 0..a.width {
            let (pa, pb) = (a.pixel(x, y)[1], b.pixel(x, y)[1]);
            let (sa, sb) = (a.std_error(x, y)[1], b.std_error(x, y)[1]);
            let bound = 5.0 * (sa * sa + sb * sb).sqrt() + 1e-5 * pa.abs().max(pb.abs());
            assert!((pa - pb).abs() <= bound, "{label}: ({x}, {y}) {pa} vs {pb}");
        }
    }
}

#[test]
fn a_constant_map_is_the_constant_environment() {
    let l = Vec3::new(0.6, 0.7, 0.9);
    let map = EnvMap::new(16, 8, vec![l; 128], 30.0);
    let medium = || common::medium(common::cloud_field(4), 8.0, 0.8, 0.3);
    let constant = common::scene(medium(), 16, Lights::sun_and_sky(None, common::env(l)));
    let mapped = common::scene(
        medium(),
        16,
        Lights::sun_and_sky(None, Some(Environment::from_map(Arc::new(map), Vec3::ONE))),
    );
    let a = render(&constant, &common::settings(IntegratorKind::Path, 64, 3));
    let b = render(&mapped, &common::settings(IntegratorKind::Path, 64, 4));
    assert!(b.stats.counters.dome_samples > 0 && b.stats.counters.nee_rays_dome > 0);
    assert_agree("constant map vs constant environment", &a.image, &b.image);
    // Pixels that miss the cloud see exactly the constant.
    assert_eq!(b.image.pixel(0, 0), [l.x, l.y, l.z, 0.0]);
}

#[test]
fn one_bright_texel_is_the_equivalent_sun() {
    let (w, h) = (512, 256);
    let (col, row) = (300, 80);
    let l_texel = Vec3::new(900.0, 800.0, 700.0);
    let mut texels = vec![Vec3::ZERO; w * h];
    texels[row * w + col] = l_texel;
    let map = EnvMap::new(w, h, texels, 25.0);
    let (dir, omega) = map.texel_direction(col, row);
    // A texel 0.7 degrees wide: its shadows are the delta sun's to well
    // under a voxel of the 16^3 test cloud.
    let sun = Sun::new(-dir, l_texel * omega, 0.0);
    let medium = || common::medium(common::cloud_field(4), 8.0, 0.9, 0.4);
    let with_sun = common::scene(medium(), 16, Lights::sun_and_sky(Some(sun), None));
    let with_map = common::scene(
        medium(),
        16,
        Lights::sun_and_sky(None, Some(Environment::from_map(Arc::new(map), Vec3::ONE))),
    );
    let a = render(&with_sun, &common::settings(IntegratorKind::Path, 64, 5));
    let b = render(&with_map, &common::settings(IntegratorKind::Path, 64, 6));
    assert_eq!(b.stats.counters.nonfinite_samples, 0);
    assert_agree("one-texel map vs sun", &a.image, &b.image);
}
