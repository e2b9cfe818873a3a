//! Lights along the axes: a sun straight overhead (or along any axis, or
//! a hair off one) beside a constant sky, and a point light far away,
//! render through every walk that can meet such a direction (free
//! flights, shadow rays, the light grid's march, both ray marchers, the
//! majorant probe) with a bounded number of walk steps per path, finite
//! pixels and light in the image.
//!
//! Each case runs under a step budget (majorant segments per path) and
//! the whole under a generous time budget set here, so a walk that does
//! not end fails the test instead of hanging the suite.

use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

use cirrus_scene::{Scene, SceneDescription};

/// Walk steps (majorant segments) a walk may take on the default cloud,
/// on average: a straight walk through it is a few dozen; a walk that
/// crept along a face took ~1e5. Walks are counted as camera paths,
/// shadow rays (the light grid's marches among them) and real
/// collisions (each starts a free flight).
const SEGMENTS_PER_WALK: u64 = 500;

fn cloud() -> String {
    format!("{}/../../data/cloud.vdb", env!("CARGO_MANIFEST_DIR"))
}

/// Sun directions with zero, negative-zero and tiny components.
const SUN_DIRECTIONS: [[f32; 3]; 8] = [
    [0.0, -1.0, 0.0],
    [-0.0, -1.0, -0.0],
    [1.0, 0.0, 0.0],
    [0.6, -0.8, 0.0],
    [0.0, -1.0, 1e-7],
    [0.0, -1.0, 1e-30],
    [0.0, 0.0, -1.0],
    [1e-7, -1.0, -1e-7],
];

/// The settings each direction renders with: every integrator, light
/// choice and majorant mode that walks differently.
const MODES: [&str; 6] = [
    "",
    "light_sampling = \"one\"",
    "light_sampling = \"all\"\nmajorant = \"hierarchy\"\ntransmittance = \"ratio\"",
    "majorant = \"global\"",
    "integrator = \"raymarch\"",
    "integrator = \"raymarch2pass\"",
];

/// The image's mean red, the walks' segments, the walks, and how many
/// channel values are finite.
fn render_case(lights: &str, mode: &str) -> (f64, u64, u64, usize) {
    let text = format!(
        "[[volume]]\nfile = {:?}\n[camera]\nres = \"16x16\"\n[render]\nspp = 1\n{mode}\n{lights}",
        cloud()
    );
    let desc = SceneDescription::parse(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    let scene = Scene::from_description(desc, Path::new(".")).unwrap();
    let r = scene.render().unwrap();
    let c = &r.stats.counters;
    let finite = r
        .image
        .rgba
        .iter()
        .flatten()
        .filter(|v| v.is_finite())
        .count();
    let mean = r.image.rgba.iter().map(|p| p[0] as f64).sum::<f64>() / r.image.rgba.len() as f64;
    let walks = c.paths + c.shadow_rays + c.real_collisions;
    (mean, c.dda_segments, walks.max(1), finite)
}

fn check(lights: &str, mode: &str) {
    let (mean, segments, walks, finite) = render_case(lights, mode);
    let what = format!("{lights:?} with {mode:?}");
    assert_eq!(finite, 16 * 16 * 4, "{what}: non-finite pixels");
    assert!(mean > 0.0, "{what}: black image");
    assert!(
        segments <= SEGMENTS_PER_WALK * walks,
        "{what}: {segments} walk segments over {walks} walks"
    );
}

/// Runs `body` on a thread, failing if it does not end within `secs`.
fn within_budget(secs: u64, body: impl FnOnce() + Send + 'static) {
    let (done, wait) = mpsc::channel();
    let worker = std::thread::spawn(move || {
        body();
        let _ = done.send(());
    });
    match wait.recv_timeout(Duration::from_secs(secs)) {
        Ok(()) => worker.join().unwrap(),
        Err(mpsc::RecvTimeoutError::Disconnected) => {
            std::panic::resume_unwind(worker.join().unwrap_err())
        }
        Err(mpsc::RecvTimeoutError::Timeout) => panic!("a render did not end in {secs} s"),
    }
}

#[test]
fn suns_along_the_axes_beside_a_sky_render_in_bounded_walks() {
    within_budget(600, || {
        for d in SUN_DIRECTIONS {
            let lights = format!(
                "[sun]\ndirection = [{:?}, {:?}, {:?}]\n[environment]\nradiance = [0.2, 0.2, 0.3]",
                d[0], d[1], d[2]
            );
            for mode in MODES {
                check(&lights, mode);
            }
        }
    });
}

#[test]
fn far_point_lights_cost_no_more_than_near_ones() {
    within_budget(600, || {
        let mut per_walk = Vec::new();
        for distance in [1e2f64, 1e4, 1e6, 1e9] {
            // Intensity rising with the square of the distance, so each
            // lights the cloud alike.
            let lights = format!(
                "[environment]\nradiance = [0.1, 0.1, 0.1]\n[[light]]\ntype = \"point\"\n\
                 position = [{distance:e}, 0, 0]\nintensity = {:e}",
                100.0 * distance * distance
            );
            for mode in ["light_sampling = \"one\"", "integrator = \"raymarch2pass\""] {
                check(&lights, mode);
            }
            let (_, segments, walks, _) = render_case(&lights, "light_sampling = \"one\"");
            per_walk.push(segments as f64 / walks as f64);
        }
        // A walk's cost is what it crosses in the cloud, not how far the
        // light is: within 1.5x of the nearest light's.
        for p in &per_walk {
            assert!(
                *p < 1.5 * per_walk[0] + 10.0,
                "segments per walk {per_walk:?}"
            );
        }
    });
}
