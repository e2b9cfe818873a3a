//! The automatic majorant structure: the probe picks the global bound
//! where the hierarchy's segments would cost more than the null
//! collisions they save, the hierarchy where a global bound would fill
//! empty space with null collisions, and the image is then exactly the
//! chosen structure's, on any crop.

mod common;

use cirrus_render::{render, Crop, GridField, IntegratorKind, Lights, MajorantMode};
use glam::Vec3;

fn lights() -> Lights {
    Lights::sun_and_sky(common::sun(0.0), common::env(Vec3::new(0.2, 0.3, 0.45)))
}

/// 32^3 voxels of constant density in fine majorant cells: every cell's
/// bound is the global one, so the hierarchy takes the same collisions
/// and only adds segments.
fn uniform() -> GridField {
    GridField::from_fn([32, 32, 32], Vec3::ZERO, 1.0 / 32.0, 2, |_, _, _| 1.0)
}

/// Two small dense puffs at opposite corners of a 64^3 box: a global bound
/// fills the empty box with null collisions the hierarchy skips.
fn sparse() -> GridField {
    GridField::from_fn([64, 64, 64], Vec3::ZERO, 1.0 / 64.0, 4, |i, j, k| {
        let p = Vec3::new(i as f32, j as f32, k as f32);
        let puff = |c: Vec3| (1.0 - (p - c).length() / 5.0).max(0.0) * 20.0;
        puff(Vec3::splat(8.0)) + puff(Vec3::splat(55.0))
    })
}

#[test]
fn auto_takes_the_structure_the_probe_finds_cheaper_and_renders_its_image() {
    for (name, field, expected) in [
        ("uniform", uniform(), MajorantMode::Global),
        ("sparse", sparse(), MajorantMode::Hierarchy),
    ] {
        let scene = common::scene(common::medium(field, 4.0, 0.9, 0.3), 12, lights());
        let mut s = common::settings(IntegratorKind::Path, 4, 3);
        s.majorant = MajorantMode::Auto;
        let auto = render(&scene, &s);
        assert_eq!(
            auto.stats.majorant,
            format!("auto: {}", expected.name()),
            "{name}"
        );
        let [local, global] = auto.stats.majorant_probe.expect("the path tracer probes");
        match expected {
            MajorantMode::Global => assert!(global < local, "{name}: {global} vs {local}"),
            _ => assert!(local < global, "{name}: {local} vs {global}"),
        }
        s.majorant = expected;
        let chosen = render(&scene, &s);
        assert_eq!(auto.image.rgba, chosen.image.rgba, "{name}");

        // The probe does not look at the crop: a crop is the full image's pixels.
        s.majorant = MajorantMode::Auto;
        s.crop = Some(Crop {
            x0: 2,
            y0: 5,
            x1: 9,
            y1: 11,
        });
        let crop = render(&scene, &s);
        assert_eq!(crop.stats.majorant, auto.stats.majorant, "{name}");
        for y in 5..11 {
            for x in 2..9 {
                let full = auto.image.rgba[(y * 12 + x) as usize];
                let part = crop.image.rgba[((y - 5) * 7 + (x - 2)) as usize];
                assert_eq!(full, part, "{name} pixel {x},{y}");
            }
        }
    }
}

#[test]
fn marchers_never_probe_and_walk_the_hierarchy() {
    let scene = common::scene(common::medium(uniform(), 4.0, 0.9, 0.3), 8, lights());
    let mut s = common::settings(IntegratorKind::RayMarch, 2, 3);
    s.majorant = MajorantMode::Auto;
    let r = render(&scene, &s);
    assert_eq!(r.stats.majorant, "auto: hierarchy");
    assert!(r.stats.majorant_probe.is_none());
}

/// One very dense voxel in a large empty box: a global bound puts about
/// 40,000 null collisions on every ray through the box, so probing it in
/// full would cost some 10^8 lookups. The probe stops the global side once
/// it has cost more than the whole hierarchy probe, and takes the
/// hierarchy.
#[test]
fn the_global_probe_stops_once_it_has_lost() {
    let field = GridField::from_fn([64, 64, 64], Vec3::ZERO, 1.0 / 64.0, 4, |i, j, k| {
        if (i, j, k) == (60, 60, 60) {
            1.0e4
        } else {
            0.0
        }
    });
    let lights = lights();
    let scene = common::scene(common::medium(field, 4.0, 0.9, 0.3), 8, lights);
    let mut s = common::settings(IntegratorKind::Path, 1, 3);
    s.majorant = MajorantMode::Auto;
    let r = render(&scene, &s);
    assert_eq!(r.stats.majorant, "auto: hierarchy");
    let [local, global] = r.stats.majorant_probe.unwrap();
    // Stopped past `local`, with at most a few paths in flight (each path
    // here costs on the order of 10^5).
    assert!(global > local, "{global} vs {local}");
    assert!(global < local + 2.0e6, "{global} vs {local}");
}
