//! Next-event estimation to one light per vertex (`--light-sampling one`)
//! estimates what sampling every light does, at half the shadow rays or
//! fewer:
//! - under a delta sun and a sky, and under a disc sun (whose escaped
//!   light is weighed by MIS against the picked light's density) and a
//!   sky, the two renders agree pixel by pixel within noise (an escaped
//!   ray's MIS weight that forgot the pick probability measured a pooled
//!   z of -10.9 here);
//! - in a thick cloud, where the shadow grid leaves deep vertices without
//!   a shadow ray most of the time, they still agree;
//! - each scattering vertex traces at most one light's shadow ray.

mod common;

use cirrus_render::{render, IntegratorKind, LightSampling, Lights, Rendered, Sun};
use glam::Vec3;

/// A bright sky beside the sun and a mildly forward phase function, so
/// that the sky's share, and the MIS weights between its samples and the
/// phase function's, weigh in every pixel.
fn sunlit(sun_degrees: f32, sampling: LightSampling, seed: u64) -> Rendered {
    lit_cloud(12.0, sun_degrees, sampling, seed)
}

/// The cloud at density scale `scale` under a sun and a bright sky.
fn lit_cloud(scale: f32, sun_degrees: f32, sampling: LightSampling, seed: u64) -> Rendered {
    let lights = Lights::sun_and_sky(
        Some(Sun::new(
            Vec3::new(-0.4, -1.0, -0.3),
            Vec3::new(1.5, 1.4, 1.2),
            sun_degrees.to_radians(),
        )),
        common::env(Vec3::new(0.5, 0.6, 0.8)),
    );
    let scene = common::scene(
        common::medium(common::cloud_field(4), scale, 0.95, 0.3),
        20,
        lights,
    );
    let mut s = common::settings(IntegratorKind::Path, 256, seed);
    s.max_depth = None;
    s.light_sampling = sampling;
    render(&scene, &s)
}

#[test]
fn one_light_per_vertex_agrees_with_every_light() {
    // A 0.5 deg sun is sampled as a disc (MIS with the phase function); a
    // 0 deg one is a delta light (next-event estimation only).
    for degrees in [0.0, 0.5] {
        let all = sunlit(degrees, LightSampling::All, 31);
        let one = sunlit(degrees, LightSampling::One, 32);
        assert_eq!(one.stats.counters.nonfinite_samples, 0);
        for c in 0..3 {
            let d = common::differences(&one.image, &all.image, c);
            common::assert_pooled_agreement(&format!("sun {degrees} deg, channel {c}"), &d);
        }
    }
}

/// Density scale 150 puts an optical depth of about 100 through the
/// blob's core, where the grid expects almost no light: most vertices
/// there trace no shadow ray, and the image is still the same.
#[test]
fn one_light_per_vertex_agrees_with_every_light_in_a_thick_cloud() {
    let all = lit_cloud(150.0, 0.0, LightSampling::All, 41);
    let one = lit_cloud(150.0, 0.0, LightSampling::One, 42);
    let c = one.stats.counters;
    let traced = c.nee_rays_distant + c.nee_rays_dome;
    assert!(
        (traced as f64) < 0.8 * c.real_collisions as f64,
        "{traced} shadow rays for {} vertices",
        c.real_collisions
    );
    for ch in 0..3 {
        let d = common::differences(&one.image, &all.image, ch);
        common::assert_pooled_agreement(&format!("thick, channel {ch}"), &d);
    }
}

#[test]
fn one_light_per_vertex_traces_at_most_one_shadow_ray_per_vertex() {
    let all = sunlit(0.0, LightSampling::All, 5).stats.counters;
    let one = sunlit(0.0, LightSampling::One, 5).stats.counters;
    // Every real collision scatters (unlimited depth, albedo 0.95 > 0):
    // one vertex each.
    assert!(all.real_collisions > 10_000, "{}", all.real_collisions);
    assert_eq!(all.nee_rays_distant, all.real_collisions);
    assert_eq!(all.nee_rays_dome, all.real_collisions);
    let traced = one.nee_rays_distant + one.nee_rays_dome;
    assert!(traced <= one.real_collisions, "{one:?}");
    // Both lights are picked, each with probability at least 0.1.
    assert!(one.nee_rays_dome > one.real_collisions / 10, "{one:?}");
    assert!(one.nee_rays_distant > one.real_collisions / 10, "{one:?}");
}
