//! Renders the procedural test cloud with every integrator and writes EXR
//! and PNG previews: `cargo run --release -p cirrus-render --example
//! test_scene -- OUT_DIR [SIZE] [SPP]`.

use std::path::PathBuf;

use cirrus_render::image_io::{write_exr, write_png};
use cirrus_render::Bounds3;
use cirrus_render::{
    render, Budget, Camera, Environment, GridField, IntegratorKind, Lights, Medium, RenderSettings,
    Scene, Sun, Volumes,
};
use glam::Vec3;

fn main() -> std::io::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let out = PathBuf::from(args.get(1).map_or("/tmp/cirrus-test-scene", String::as_str));
    let size: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(256);
    let spp: u32 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(64);
    std::fs::create_dir_all(&out)?;

    let n = 64;
    let vs = 1.0 / n as f32;
    let field = GridField::from_fn([n, n, n], Vec3::splat(0.5 * vs), vs, 8, |i, j, k| {
        let p = (Vec3::new(i as f32, j as f32, k as f32) + 0.5) / n as f32 - 0.5;
        let r2 = (p * Vec3::new(1.0, 1.4, 1.0)).length_squared() / 0.2;
        let lumps = 0.65 + 0.35 * (9.0 * p.x).sin() * (7.0 * p.y + 1.0).cos() * (8.0 * p.z).sin();
        ((1.0 - r2).max(0.0) * lumps).max(0.0)
    });
    let bounds = field.bounds_for_framing();
    let scene = Scene {
        media: Volumes::from(Medium::new(field, 40.0, Vec3::splat(0.98), 0.6)),
        camera: Camera::framing(bounds, size, size),
        lights: Lights::sun_and_sky(
            Some(Sun::new(Vec3::new(-0.4, -1.0, -0.3), Vec3::splat(3.0), 0.0)),
            Some(Environment::new(Vec3::new(0.25, 0.35, 0.5))),
        ),
    };
    for integrator in [
        IntegratorKind::Path,
        IntegratorKind::RayMarch,
        IntegratorKind::RayMarch2Pass,
    ] {
        let settings = RenderSettings {
            integrator,
            budget: Budget::Spp(spp),
            step_voxels: 1.0,
            ..Default::default()
        };
        let r = render(&scene, &settings);
        let name = integrator.name();
        write_exr(&out.join(format!("{name}.exr")), &r.image)?;
        write_png(&out.join(format!("{name}.png")), &r.image, 0.0)?;
        println!("{}", r.stats.to_json());
    }
    Ok(())
}

trait FramingBounds {
    fn bounds_for_framing(&self) -> Bounds3;
}

impl FramingBounds for GridField {
    fn bounds_for_framing(&self) -> Bounds3 {
        let c = Vec3::splat(0.5);
        let blob = Vec3::new(0.45, 0.33, 0.45);
        Bounds3::new(c - blob, c + blob)
    }
}
