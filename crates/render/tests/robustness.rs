//! Broken fields must not hang a render or put NaN or infinity in an image;
//! and image files are written whole.

mod common;

use cirrus_render::image_io::{tonemap, write_exr, write_png};
use cirrus_render::{
    render, ConstantBox, Counters, DensityField, IntegratorKind, Lights, MajorantSegment, Medium,
    Scene, TransmittanceEstimator, Volumes,
};
use glam::Vec3;

/// Wraps a box and breaks it: NaN or infinite density in part of it, or
/// segments whose majorant is infinite or NaN.
struct Broken {
    inner: ConstantBox,
    density: f32,
    majorant: f32,
}

impl DensityField for Broken {
    type Segments<'a> = std::vec::IntoIter<MajorantSegment>;

    fn bounds(&self) -> cirrus_render::Bounds3 {
        self.inner.bounds()
    }
    fn density(&self, p: Vec3) -> f32 {
        match self.inner.density(p) {
            0.0 => 0.0,
            _ if p.x > 0.0 => self.density,
            d => d,
        }
    }
    fn segments(&self, o: Vec3, d: Vec3, t0: f32, t1: f32) -> Self::Segments<'_> {
        let mut v: Vec<_> = self.inner.segments(o, d, t0, t1).collect();
        for s in &mut v {
            // Minorant 0, so delta tracking must look the density up.
            s.minorant = 0.0;
            s.majorant = self.majorant;
        }
        v.into_iter()
    }
    fn global_majorant(&self) -> f32 {
        self.majorant
    }
    fn voxel_size(&self) -> f32 {
        self.inner.voxel_size()
    }
}

fn broken_scene(density: f32, majorant: f32, size: u32) -> Scene<Volumes<Broken>> {
    let inner = ConstantBox::new(Vec3::splat(-0.5), Vec3::splat(0.5), 1.0, 0.1);
    let medium = Medium::new(
        Broken {
            inner,
            density,
            majorant,
        },
        2.0,
        Vec3::splat(0.8),
        0.4,
    );
    let lights = Lights::sun_and_sky(common::sun(1.0), common::env(Vec3::splat(0.3)));
    let camera = cirrus_render::Camera::framing(medium.field.bounds(), size, size);
    Scene {
        media: medium.into(),
        camera,
        lights,
    }
}

const ALL: [(IntegratorKind, TransmittanceEstimator); 5] = [
    (IntegratorKind::Path, TransmittanceEstimator::Ratio),
    (IntegratorKind::Path, TransmittanceEstimator::Residual),
    (IntegratorKind::Path, TransmittanceEstimator::TrackLength),
    (IntegratorKind::RayMarch, TransmittanceEstimator::Ratio),
    (IntegratorKind::RayMarch2Pass, TransmittanceEstimator::Ratio),
];

/// Renders with each configuration, asserts every pixel is finite, and
/// returns the summed counters.
fn assert_finite(
    label: &str,
    scene: &Scene<Volumes<Broken>>,
    configs: &[(IntegratorKind, TransmittanceEstimator)],
) -> Counters {
    let mut total = Counters::default();
    for &(kind, est) in configs {
        let mut s = common::settings(kind, 2, 1);
        s.transmittance = est;
        s.step_voxels = 1.0;
        let out = render(scene, &s);
        assert!(
            out.image.rgba.iter().flatten().all(|x| x.is_finite()),
            "{label} {kind:?} {est:?}: non-finite pixel"
        );
        total += out.stats.counters;
    }
    total
}

#[test]
fn nan_density_is_counted_and_kept_out_of_the_image() {
    let stats = assert_finite("NaN density", &broken_scene(f32::NAN, 1.0, 8), &ALL);
    assert!(
        stats.nonfinite_samples > 0,
        "NaN should have been seen and counted"
    );
}

#[test]
fn infinite_density_stays_finite() {
    assert_finite("inf density", &broken_scene(f32::INFINITY, 1.0, 8), &ALL);
}

#[test]
fn infinite_majorant_hits_the_collision_cap() {
    // An infinite majorant puts every tentative collision at the same t
    // with acceptance 1/inf = 0: only the cap ends the walk.
    // Each capped call costs a million iterations: a 3x3 image, one
    // estimator, 2 spp.
    let scene = broken_scene(1.0, f32::INFINITY, 3);
    let stats = assert_finite("inf majorant", &scene, &ALL[..1]);
    assert!(stats.collision_cap_hits > 0);
}

#[test]
fn nan_majorant_is_skipped() {
    assert_finite("NaN majorant", &broken_scene(1.0, f32::NAN, 8), &ALL);
}

#[test]
fn density_above_the_majorant_is_counted() {
    let stats = assert_finite("violation", &broken_scene(3.0, 1.0, 8), &ALL);
    assert!(stats.majorant_violations > 0);
}

#[test]
fn images_are_written_whole() {
    let scene = common::scene(
        common::medium(common::cloud_field(4), 8.0, 0.9, 0.5),
        12,
        Lights::sun_and_sky(common::sun(0.0), common::env(Vec3::splat(0.2))),
    );
    let out = render(&scene, &common::settings(IntegratorKind::Path, 2, 3));
    let dir = std::env::temp_dir().join(format!("cirrus-render-io-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (exr, png) = (dir.join("image.exr"), dir.join("image.png"));
    write_exr(&exr, &out.image).unwrap();
    write_png(&png, &out.image, 0.0).unwrap();
    // Overwriting works too (rename replaces).
    write_png(&png, &out.image, 1.0).unwrap();
    // The EXR reads back bit-exact, alpha included.
    let back = exr::prelude::read_first_rgba_layer_from_file(
        &exr,
        |size, _| vec![[0f32; 4]; size.0 * size.1],
        |px: &mut Vec<[f32; 4]>, pos, (r, g, b, a): (f32, f32, f32, f32)| {
            px[pos.1 * 12 + pos.0] = [r, g, b, a];
        },
    )
    .unwrap();
    assert_eq!(back.layer_data.channel_data.pixels, out.image.rgba);
    assert_eq!(&std::fs::read(&png).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
    // Only the two outputs remain: no temporary files left behind.
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert_eq!(names, ["image.exr", "image.png"]);
    // A failed write leaves no file: the directory does not exist.
    assert!(write_png(&dir.join("missing/x.png"), &out.image, 0.0).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
    // The tone curve is bounded, monotone, and safe on junk.
    assert_eq!(tonemap(f32::NAN), 0.0);
    assert_eq!(tonemap(f32::INFINITY), 1.0);
    assert!(tonemap(0.5) < tonemap(1.0) && tonemap(100.0) <= 1.0);
}
