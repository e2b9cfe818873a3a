//! Past 8 lights one light is picked per vertex by what each sends toward
//! it (`integrator/many_lights.rs`): a fog lit by a street of 16 lamps
//! (three of them spots, which the light tree bounds by their cones) and
//! a dim sky renders what sampling every light renders, weighed or
//! uniform, with one shadow ray per vertex instead of 17 (and one per
//! segment's equi-angular sample).

mod common;

use cirrus_render::{
    render, Camera, ConstantBox, Environment, IntegratorKind, Light, LightSampling, Lights, Medium,
    Rendered, Scene, SphereLight, Spot, Volumes,
};
use glam::Vec3;

fn street() -> Lights {
    let lamps = (0..16).map(|k| {
        let x = -7.5 + k as f32;
        let at = Vec3::new(x, 1.5 + 0.3 * (k % 3) as f32, 0.5 * (k % 2) as f32);
        let radius = if k % 4 == 0 { 0.0 } else { 0.1 };
        let i = Vec3::new(4.0, 3.0 + 0.2 * k as f32, 2.0);
        let lamp = SphereLight::new(at, radius, i);
        // Some are spots shining down, which the tree bounds by their cone.
        if k % 5 == 2 {
            Light::from(lamp.with_spot(Spot::new(Vec3::NEG_Y, 0.7, 0.3)))
        } else {
            Light::from(lamp)
        }
    });
    Lights::new(lamps.chain([Environment::new(Vec3::new(0.02, 0.03, 0.05)).into()]))
}

fn render_street(sampling: LightSampling, seed: u64) -> Rendered {
    let fog = ConstantBox::new(
        Vec3::new(-10.0, -2.0, -3.0),
        Vec3::new(10.0, 4.0, 3.0),
        1.0,
        0.25,
    );
    let scene = Scene {
        media: Volumes::from(Medium::new(fog, 0.3, Vec3::splat(0.8), 0.3)),
        camera: Camera::new(
            Vec3::new(0.0, 0.5, -9.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::Y,
            60.0,
            24,
            16,
        ),
        lights: street(),
    };
    let mut s = common::settings(IntegratorKind::Path, 64, seed);
    s.light_sampling = sampling;
    s.max_depth = Some(3);
    let out = render(&scene, &s);
    assert_eq!(out.stats.counters.nonfinite_samples, 0);
    out
}

#[test]
fn many_lights_picked_one_per_vertex_render_as_every_light() {
    let all = render_street(LightSampling::All, 1);
    let weighed = render_street(LightSampling::Auto, 2);
    let uniform = render_street(LightSampling::Uniform, 3);
    let rays = |r: &Rendered| r.stats.counters.nee_rays_sphere + r.stats.counters.nee_rays_dome;
    let vertices = |r: &Rendered| r.stats.counters.real_collisions;
    // Every light: a ray a vertex to each of the 13 lamps that are not
    // spots (a spot's is dropped outside its cone) and a sky ray (the
    // sky's drawn toward its pole may be dropped); one picked: at most one.
    assert!(
        rays(&all) >= 13 * vertices(&all),
        "{:?}",
        all.stats.counters
    );
    // (and one a segment for its equi-angular sample).
    let one_each = |r: &Rendered| vertices(r) + r.stats.counters.equiangular_samples;
    assert!(
        rays(&weighed) <= one_each(&weighed),
        "{:?}",
        weighed.stats.counters
    );
    assert!(
        rays(&uniform) <= one_each(&uniform),
        "{:?}",
        uniform.stats.counters
    );
    for (label, other) in [("weighed", &weighed), ("uniform", &uniform)] {
        for channel in 0..3 {
            let d = common::differences(&all.image, &other.image, channel);
            common::assert_pooled_agreement(&format!("{label}, channel {channel}"), &d);
        }
    }
}
