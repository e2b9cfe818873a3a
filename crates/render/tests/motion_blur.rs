//! Motion blur from a velocity grid: a box moving at constant velocity
//! against the closed-form time average of its transmittance, majorants
//! that bound the moving density at every time, and a closed shutter that
//! changes nothing.

use std::sync::Arc;

use cirrus_bricks::{convert_tree, BrickVolume, Precision, VelocityGrid};
use cirrus_kernel::medium::BrickField;
use cirrus_kernel::tracking::ratio_tracking;
use cirrus_kernel::{Ray, Rng};
use cirrus_render::{
    render, Budget, Camera, Counters, DensityField, Environment, Lights, Medium, RenderSettings,
    Scene, Shutter, Velocity, VelocityUnit, Volumes,
};
use cirrus_vdb::{Coord, Tree};
use glam::{DMat4, DVec3, Vec3};

/// Density 1 on voxels [0, 15] x [0, 7] x [0, 15] (index = world units).
fn box_volume() -> BrickVolume {
    let mut tree = Tree::new(0.0f32);
    for x in 0..16 {
        for y in 0..8 {
            for z in 0..16 {
                tree.set_value_on(Coord::new(x, y, z), 1.0);
            }
        }
    }
    convert_tree(&tree, Precision::F32).unwrap()
}

/// A constant velocity `v` over (and around) the box.
fn constant_velocity(v: [f32; 3]) -> Velocity {
    let mut tree = Tree::new([0.0f32; 3]);
    for x in -8..32 {
        for y in -8..24 {
            for z in -8..32 {
                tree.set_value_on(Coord::new(x, y, z), v);
            }
        }
    }
    Velocity {
        grid: Arc::new(VelocityGrid::from_tree("vel", &tree, DMat4::IDENTITY, |v| v).unwrap()),
        unit: VelocityUnit::World,
        scale: 1.0,
    }
}

/// A ray along +y at x0 = 13.5, z = 8 crosses the box's y profile, which
/// integrates to 8 voxels (7 between the first and last centres, plus half
/// of each trilinear ramp), so its optical depth is `K f(x)` with `f` the
/// box's x profile: 1 on [0, 15], `1 - (x - 15)` on the ramp [15, 16], 0
/// beyond. The velocity is -4 voxels a frame, so at time t the ray sees
/// `f(x0 + 4 t)`; over the shutter [0, 0.75] that sweeps [13.5, 16.5]: 1.5
/// voxels inside, the ramp, 0.5 outside. The time average of `exp(-K f)`
/// is therefore `(1.5 e^-K + (1 - e^-K) / K + 0.5) / 3`.
const X0: f32 = 13.5;
const V: f32 = -4.0;
const SHUTTER: Shutter = Shutter {
    open: 0.0,
    close: 0.75,
};
const K: f32 = 2.0;

fn closed_form() -> f64 {
    let k = K as f64;
    (1.5 * (-k).exp() + (1.0 - (-k).exp()) / k + 0.5) / 3.0
}

fn moving_box(volume: &BrickVolume) -> Volumes<BrickField<'_>> {
    let field = BrickField::new(volume, DMat4::IDENTITY, DVec3::ZERO)
        .with_motion(&constant_velocity([V, 0.0, 0.0]), SHUTTER)
        .unwrap();
    // The y profile integrates to 8 voxels: K = 8 * density scale.
    Volumes::from(Medium::new(field, K / 8.0, Vec3::ZERO, 0.0))
}

#[test]
fn constant_velocity_box_matches_the_time_averaged_transmittance() {
    let volume = box_volume();
    let medium = moving_box(&volume);
    let n = 200_000u64;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    let mut c = Counters::default();
    for i in 0..n {
        let mut rng = Rng::new(7, i, 0);
        let time = SHUTTER.open + (SHUTTER.close - SHUTTER.open) * rng.uniform();
        let ray = Ray::new(Vec3::new(X0, -20.0, 8.0), Vec3::Y).with_time(time);
        let tr = ratio_tracking::<f32, _>(&medium, &ray, f32::INFINITY, &mut rng, &mut c) as f64;
        sum += tr;
        sum2 += tr * tr;
    }
    let mean = sum / n as f64;
    let sd = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
    let want = closed_form();
    assert_eq!(c.majorant_violations, 0);
    // 5 standard errors (plus f32 rounding): fails about once in 10^6 runs.
    assert!(
        (mean - want).abs() < 5.0 * sd + 1e-4,
        "mean {mean} +- {sd}, closed form {want}"
    );
    // And it is blur: the still frame (t = 0, f = 1) is e^-K = 0.135.
    assert!((want - (-K as f64).exp()).abs() > 50.0 * sd);
}

#[test]
fn a_rendered_pixel_sees_the_time_averaged_transmittance() {
    // One pixel looking along +y at x0 through a tiny field of view: the
    // pure absorber shows the sky (radiance 1) times the transmittance,
    // each sample at its own time over the shutter.
    let volume = box_volume();
    let medium = moving_box(&volume);
    let camera = Camera::new(
        Vec3::new(X0, -40.0, 8.0),
        Vec3::new(X0, 0.0, 8.0),
        Vec3::Z,
        0.001,
        1,
        1,
    );
    let lights = Lights::sun_and_sky(None, Some(Environment::new(Vec3::ONE)));
    let scene = Scene {
        media: medium,
        camera,
        lights,
    };
    let spp = 4096;
    let settings = RenderSettings {
        budget: Budget::Spp(spp),
        max_depth: Some(0),
        shutter: SHUTTER,
        progress: false,
        majorant: cirrus_render::MajorantMode::Hierarchy,
        ..Default::default()
    };
    let r = render(&scene, &settings);
    let got = r.image.pixel(0, 0)[0] as f64;
    let want = closed_form();
    // Each sample is 0 or 1 (a free flight escapes or not): Bernoulli.
    let sd = (want * (1.0 - want) / spp as f64).sqrt();
    assert!(
        (got - want).abs() < 5.0 * sd,
        "pixel {got}, closed form {want} (sd {sd})"
    );
    assert_eq!(r.stats.counters.majorant_violations, 0);
}

/// A lumpy blob in a 40^3 grid and a swirling, non-uniform velocity.
fn blob_and_swirl() -> (BrickVolume, Velocity) {
    let mut density = Tree::new(0.0f32);
    let mut vel = Tree::new([0.0f32; 3]);
    for x in 0..40 {
        for y in 0..40 {
            for z in 0..40 {
                let p = Vec3::new(x as f32, y as f32, z as f32) - 20.0;
                let r = p.length() / 14.0;
                let lumps = 0.6 + 0.4 * (0.7 * p.x).sin() * (0.5 * p.y + 1.0).cos();
                let d = ((1.0 - r * r).max(0.0) * lumps).max(0.0);
                if d > 0.0 {
                    density.set_value_on(Coord::new(x, y, z), 3.0 * d);
                }
                let v = [-0.3 * p.z, 1.5 + 0.05 * p.y, 0.3 * p.x];
                vel.set_value_on(Coord::new(x, y, z), v);
            }
        }
    }
    let volume = convert_tree(&density, Precision::F16).unwrap();
    let grid = VelocityGrid::from_tree("vel", &vel, DMat4::IDENTITY, |v| v).unwrap();
    let velocity = Velocity {
        grid: Arc::new(grid),
        unit: VelocityUnit::World,
        scale: 1.0,
    };
    (volume, velocity)
}

/// Samples points of the segments of random rays at random shutter
/// times; counts (points, moved points, majorant violations, minorant
/// violations).
fn check_bounds<F: DensityField>(field: &F, shutter: Shutter, walk: &F) -> [u64; 4] {
    let mut counts = [0u64; 4];
    for i in 0..3000u64 {
        let mut rng = Rng::new(11, i, 0);
        let mut u = || rng.uniform();
        let o = Vec3::new(u(), u(), u()) * 60.0 - 10.0;
        let d = (Vec3::new(u(), u(), u()) * 2.0 - 1.0).normalize_or(Vec3::X);
        let times: Vec<f32> = (0..4)
            .map(|_| shutter.open + (shutter.close - shutter.open) * u())
            .collect();
        let segments: Vec<_> = walk.segments(o, d, 0.0, 200.0).collect();
        for s in segments {
            for &time in &times {
                let t = s.t0 + (s.t1 - s.t0) * u();
                let p = o + t * d;
                let rho = field.density_at(p, time);
                counts[0] += 1;
                counts[1] += u64::from(rho != field.density(p));
                counts[2] += u64::from(rho > s.majorant * (1.0 + 1e-5));
                counts[3] += u64::from(rho < s.minorant * (1.0 - 1e-5) - 1e-6);
            }
        }
    }
    counts
}

#[test]
fn majorants_bound_the_moving_density_at_every_time() {
    let (volume, velocity) = blob_and_swirl();
    // Displacements up to 6 voxels (bounds from whole cells) and up to 1.2
    // (bounds read from the voxels within reach).
    for shutter in [Shutter::new(-0.5, 1.0), Shutter::new(-0.1, 0.2)] {
        for refine in [None, Some(1.0)] {
            let mut field = BrickField::new(&volume, DMat4::IDENTITY, DVec3::ZERO);
            if let Some(r) = refine {
                field = field.with_refinement(0.5, r);
            }
            let field = field.with_motion(&velocity, shutter).unwrap();
            let [points, moved, over, under] = check_bounds(&field, shutter, &field);
            assert!(
                points > 10_000 && moved > points / 20,
                "{points} points, {moved} moved"
            );
            let what = format!("{points} points, {shutter:?}, refine {refine:?}");
            assert_eq!((over, under), (0, 0), "{what}");
        }
    }
    let shutter = Shutter::new(-0.5, 1.0);
    // The check can fail: the still volume's own bounds do not hold.
    let field = BrickField::new(&volume, DMat4::IDENTITY, DVec3::ZERO)
        .with_motion(&velocity, shutter)
        .unwrap();
    let still = BrickField::new(&volume, DMat4::IDENTITY, DVec3::ZERO);
    let mut over = 0;
    for i in 0..3000u64 {
        let mut rng = Rng::new(11, i, 0);
        let mut u = || rng.uniform();
        let o = Vec3::new(u(), u(), u()) * 60.0 - 10.0;
        let d = (Vec3::new(u(), u(), u()) * 2.0 - 1.0).normalize_or(Vec3::X);
        for s in still.segments(o, d, 0.0, 200.0) {
            let p = o + (s.t0 + (s.t1 - s.t0) * u()) * d;
            over += u64::from(field.density_at(p, shutter.close) > s.majorant * 1.001);
        }
    }
    assert!(
        over > 20,
        "undilated bounds were violated only {over} times"
    );
}

#[test]
fn a_closed_shutter_or_no_velocity_renders_bit_identical() {
    let (volume, velocity) = blob_and_swirl();
    let render_with = |field: BrickField<'_>, shutter: Shutter| {
        let medium = Volumes::from(Medium::new(field, 0.4, Vec3::splat(0.9), 0.5));
        let camera = Camera::new(
            Vec3::new(20.0, 25.0, -40.0),
            Vec3::splat(20.0),
            Vec3::Y,
            40.0,
            24,
            16,
        );
        let lights = Lights::sun_and_sky(
            Some(cirrus_render::Sun::new(
                Vec3::new(0.3, -1.0, 0.2),
                Vec3::splat(3.0),
                0.01,
            )),
            Some(Environment::new(Vec3::new(0.2, 0.3, 0.4))),
        );
        let scene = Scene {
            media: medium,
            camera,
            lights,
        };
        let settings = RenderSettings {
            budget: Budget::Spp(8),
            shutter,
            progress: false,
            majorant: cirrus_render::MajorantMode::Hierarchy,
            ..Default::default()
        };
        render(&scene, &settings).image.rgba
    };
    let still = || BrickField::new(&volume, DMat4::IDENTITY, DVec3::ZERO).with_refinement(0.4, 1.0);
    let reference = render_with(still(), Shutter::INSTANT);
    // A closed shutter with a velocity grid: nothing moves.
    let closed = still().with_motion(&velocity, Shutter::INSTANT).unwrap();
    assert!(!closed.moves());
    assert_eq!(
        bits(&render_with(closed, Shutter::INSTANT)),
        bits(&reference)
    );
    // An open shutter without a velocity: times are drawn, nothing reads them.
    let open = Shutter::new(-0.25, 0.25);
    assert_eq!(bits(&render_with(still(), open)), bits(&reference));
    // And an open shutter with the velocity does blur.
    let moving = still().with_motion(&velocity, open).unwrap();
    assert_ne!(bits(&render_with(moving, open)), bits(&reference));
}

fn bits(rgba: &[[f32; 4]]) -> Vec<[u32; 4]> {
    rgba.iter().map(|p| p.map(f32::to_bits)).collect()
}

/// A velocity in voxels moves the field by that many of the velocity
/// grid's own voxels: on a grid of 2-unit voxels, -2 voxels a frame is -4
/// world units a frame, and the same value read as world units is not.
#[test]
fn voxel_velocities_count_the_velocity_grid_voxels() {
    let volume = box_volume();
    let coarse = |v: [f32; 3], unit: VelocityUnit| {
        let mut tree = Tree::new([0.0f32; 3]);
        for x in -4..16 {
            for y in -4..12 {
                for z in -4..16 {
                    tree.set_value_on(Coord::new(x, y, z), v);
                }
            }
        }
        let to_world = DMat4::from_scale(DVec3::splat(2.0));
        Velocity {
            grid: Arc::new(VelocityGrid::from_tree("vel", &tree, to_world, |v| v).unwrap()),
            unit,
            scale: 1.0,
        }
    };
    let moving = |velocity: &Velocity| {
        BrickField::new(&volume, DMat4::IDENTITY, DVec3::ZERO)
            .with_motion(velocity, SHUTTER)
            .unwrap()
    };
    let world = moving(&constant_velocity([V, 0.0, 0.0]));
    let voxels = moving(&coarse([0.5 * V, 0.0, 0.0], VelocityUnit::Voxels));
    let as_world = moving(&coarse([0.5 * V, 0.0, 0.0], VelocityUnit::World));
    let (mut compared, mut differ) = (0, 0);
    for i in 0..40 {
        let p = Vec3::new(10.0 + 0.2 * i as f32, 4.0, 8.0);
        for t in [0.25f32, 0.5, 0.75] {
            let (a, b) = (world.density_at(p, t), voxels.density_at(p, t));
            assert!((a - b).abs() <= 1e-5, "{p} at {t}: {a} vs {b}");
            compared += 1;
            differ += usize::from((as_world.density_at(p, t) - a).abs() > 1e-3);
        }
    }
    assert_eq!(compared, 120);
    assert!(
        differ > 20,
        "the unit must matter: {differ} of {compared} differ"
    );
}
