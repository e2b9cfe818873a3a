//! A large ball lamp inside a box of fog, with multiple scattering, against
//! an analog random walk written here: exponential flights in the box,
//! absorption by survival with the albedo, isotropic directions, and the
//! ball's radiance gathered where a flight crosses its surface (the near
//! side from outside, the far side from inside, as cirrus and Cycles
//! define a lamp's ball; camera rays do not see it). The walk shares no
//! code and no strategy with the renderer (no next-event estimation, no
//! equi-angular sampling, no MIS, its own random numbers), so agreement
//! checks the ball's sampling from outside and inside, its hits, their
//! weights and the light choice at once. The walk was first written in
//! numpy and agreed with cirrus to 0.1% on scenes like these.

mod common;

use cirrus_render::{
    render, Camera, ConstantBox, IntegratorKind, Lights, Medium, Scene, SphereLight, Volumes,
};
use cirrus_testkit::SplitMix64;
use glam::{DVec3, Vec3};

const HALF: f64 = 40.0;
const ALBEDO: f64 = 0.8;
const RADIANCE: f64 = 1.0;

/// The ball: centre and radius.
struct Ball {
    centre: DVec3,
    radius: f64,
}

/// The distances along `o + t d` at which it enters and leaves the box,
/// if it meets it ahead.
fn box_span(o: DVec3, d: DVec3) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a].abs() > HALF {
                return None;
            }
            continue;
        }
        let (u, v) = ((-HALF - o[a]) / d[a], (HALF - o[a]) / d[a]);
        t0 = t0.max(u.min(v));
        t1 = t1.min(u.max(v));
    }
    (t0 < t1).then_some((t0, t1))
}

/// Where `o + t d` crosses the ball's surface in the lamp's sense: the
/// near side from outside, the far side from inside.
fn surface(ball: &Ball, o: DVec3, d: DVec3) -> Option<f64> {
    let oc = o - ball.centre;
    let b = d.dot(oc);
    let c = oc.length_squared() - ball.radius * ball.radius;
    let disc = b * b - c;
    if disc <= 0.0 {
        return None;
    }
    let t = if c < 0.0 {
        -b + disc.sqrt()
    } else {
        -b - disc.sqrt()
    };
    (t > 0.0).then_some(t)
}

/// The walk's estimate of the radiance along the camera ray `o + t d`,
/// and its standard error.
fn walk(sigma_t: f64, ball: &Ball, o: DVec3, d: DVec3, paths: u32, seed: u64) -> (f64, f64) {
    // The walk's own random numbers, not the renderer's streams.
    let mut rng = SplitMix64(seed);
    let (mut sum, mut sum_sq) = (0.0, 0.0);
    for _ in 0..paths {
        let (mut o, mut d) = (o, d);
        let mut gathered = 0.0;
        for depth in 0.. {
            let Some((t_in, t_out)) = box_span(o, d) else {
                break;
            };
            let s = t_in - (1.0 - rng.unit_f64()).ln() / sigma_t;
            let end = s.min(t_out);
            if depth > 0 && surface(ball, o, d).is_some_and(|t| t < end) {
                gathered += RADIANCE;
            }
            if s >= t_out || rng.unit_f64() >= ALBEDO {
                break;
            }
            o += s * d;
            let z = 1.0 - 2.0 * rng.unit_f64();
            let phi = std::f64::consts::TAU * rng.unit_f64();
            let r = (1.0 - z * z).max(0.0).sqrt();
            d = DVec3::new(r * phi.cos(), r * phi.sin(), z);
        }
        sum += gathered;
        sum_sq += gathered * gathered;
    }
    let n = paths as f64;
    let mean = sum / n;
    (mean, ((sum_sq / n - mean * mean) / n).sqrt())
}

/// The renderer's one pixel, a ray from `from` through the ball's centre
/// (a field of view of 0.001 degrees), and its standard error.
fn rendered(sigma_t: f32, ball: &Ball, from: Vec3, spp: u32) -> (f64, f64) {
    let fog = ConstantBox::new(
        Vec3::splat(-HALF as f32),
        Vec3::splat(HALF as f32),
        1.0,
        0.5,
    );
    let centre = ball.centre.as_vec3();
    let r = ball.radius as f32;
    // A ball's intensity is its radiance times its cross-section.
    let intensity = Vec3::splat((RADIANCE * std::f64::consts::PI) as f32 * r * r);
    let scene = Scene {
        media: Volumes::from(Medium::new(fog, sigma_t, Vec3::splat(ALBEDO as f32), 0.0)),
        camera: Camera::new(from, centre, Vec3::Y, 0.001, 1, 1),
        lights: Lights::new([SphereLight::new(centre, r, intensity).into()]),
    };
    let out = render(&scene, &common::settings(IntegratorKind::Path, spp, 11));
    assert_eq!(out.stats.counters.nonfinite_samples, 0);
    (
        out.image.pixel(0, 0)[0] as f64,
        out.image.std_error(0, 0)[0] as f64,
    )
}

fn assert_agrees(sigma_t: f32, ball: Ball, from: Vec3) {
    let o = from.as_dvec3();
    let d = (ball.centre - o).normalize();
    let (want, want_se) = walk(sigma_t as f64, &ball, o, d, 1_000_000, 5);
    let (got, got_se) = rendered(sigma_t, &ball, from, 1 << 16);
    let z = (got - want) / (want_se * want_se + got_se * got_se).sqrt();
    eprintln!("cirrus {got:.5} +- {got_se:.5}, walk {want:.5} +- {want_se:.5}, z {z:+.2}");
    assert!(want > 0.05, "a scene that shows the ball's light ({want})");
    assert!(
        z.abs() < 5.0,
        "cirrus {got} +- {got_se} against the walk's {want} +- {want_se}"
    );
}

#[test]
fn a_ball_lamp_in_thin_fog_seen_from_outside_the_fog_agrees_with_a_random_walk() {
    // Four mean free paths across the box; the ball off its centre, the
    // camera outside the box.
    let ball = Ball {
        centre: DVec3::new(6.0, 3.0, 0.0),
        radius: 9.0,
    };
    assert_agrees(0.05, ball, Vec3::new(0.0, 0.0, -120.0));
}

#[test]
fn a_ball_lamp_in_dense_fog_seen_from_near_it_agrees_with_a_random_walk() {
    // Two mean free paths from the camera to the ball, whose inside is
    // lit from every direction by its own surface.
    let ball = Ball {
        centre: DVec3::new(0.0, 0.0, 5.0),
        radius: 12.0,
    };
    assert_agrees(0.2, ball, Vec3::new(0.0, 0.0, -17.0));
}
