//! Writes the procedural HDR sky `data/sky.exr` (run by tools/make_sky.sh):
//! `cargo run --release -p cirrus-render --example make_sky -- data/sky.exr`.
//!
//! A 256 x 128 lat-long map in cirrus's (Mitsuba 3's) layout, RGB half
//! floats: a blue zenith fading to a pale horizon, a dim brown ground, and
//! a one-texel sun toward (-0.7, 0.5, -0.5) (the default `--sun-dir`
//! reversed) whose radiance times its texel's solid angle is an
//! irradiance of (2.6, 2.5, 2.3), the default sun's. Deterministic.

use cirrus_render::EnvMap;
use exr::prelude::*;
use glam::Vec3;

const W: usize = 256;
const H: usize = 128;

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "data/sky.exr".into());
    let blank = EnvMap::new(W, H, vec![Vec3::ZERO; W * H], 0.0);
    let to_sun = Vec3::new(-0.7, 0.5, -0.5).normalize();
    let (sun_col, sun_row) = (0..H)
        .flat_map(|r| (0..W).map(move |c| (c, r)))
        .max_by(|a, b| {
            let da = blank.texel_direction(a.0, a.1).0.dot(to_sun);
            let db = blank.texel_direction(b.0, b.1).0.dot(to_sun);
            da.total_cmp(&db)
        })
        .expect("non-empty map");
    let (_, omega) = blank.texel_direction(sun_col, sun_row);
    let sun = Vec3::new(2.6, 2.5, 2.3) / omega;
    let zenith = Vec3::new(0.10, 0.20, 0.45);
    let horizon = Vec3::new(0.55, 0.62, 0.70);
    let ground = Vec3::new(0.07, 0.06, 0.05);
    let texel = |x: usize, y: usize| -> Vec3 {
        if (x, y) == (sun_col, sun_row) {
            return sun;
        }
        let (d, _) = blank.texel_direction(x, y);
        if d.y >= 0.0 {
            // Brighter toward the horizon and around the sun.
            let t = (1.0 - d.y).powi(3);
            let glow = 0.25 * d.dot(to_sun).max(0.0).powi(8);
            zenith.lerp(horizon, t) + Vec3::new(1.0, 0.9, 0.7) * glow
        } else {
            ground.lerp(horizon * 0.3, (1.0 + d.y).powi(6))
        }
    };
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let t = texel(x, y);
        (f16::from_f32(t.x), f16::from_f32(t.y), f16::from_f32(t.z))
    });
    let layer = Layer::new(
        (W, H),
        LayerAttributes::named("sky"),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    Image::from_layer(layer)
        .write()
        .to_file(&out)
        .expect("write the sky");
    println!("{out}: {W}x{H}, sun texel ({sun_col}, {sun_row}) radiance {sun}");
}
