//! Lights that change over time (`[[light]]` keys): read at the frame
//! rendered, and over an open shutter blurred as the mean of the instants
//! it is open for.

use std::path::Path;

use cirrus_render::Rendered;
use cirrus_scene::{Scene, SceneDescription};

fn cloud() -> String {
    format!("{}/../../data/cloud.vdb", env!("CARGO_MANIFEST_DIR"))
}

/// Renders the cloud with `lights` and the `[render]` keys `render` (8
/// samples and seed 3 where it gives none).
fn render(render: &str, lights: &str) -> Result<Rendered, cirrus_scene::Error> {
    let mut render = render.to_string();
    for (key, default) in [("spp", "spp = 8"), ("seed", "seed = 3")] {
        if !render.contains(key) {
            render = format!("{default}\n{render}");
        }
    }
    let text = format!(
        "[render]\n{render}\n[camera]\nres = \"32x24\"\n[[volume]]\nfile = {:?}\ndensity_scale = 0.03\n{lights}",
        cloud()
    );
    let desc = SceneDescription::parse(&text).map_err(cirrus_scene::Error::input)?;
    Scene::from_description(desc, Path::new("."))?.render()
}

fn bits(r: &Rendered) -> Vec<[u32; 4]> {
    r.image.rgba.iter().map(|p| p.map(f32::to_bits)).collect()
}

/// A point light inside the cloud that crosses it from x = 60 to x = 240
/// over frames 0 to 1, brightening from 4e4 to 8e4.
const CROSSING: &str = r#"
[[light]]
type = "point"
position = [60, 83, 100]
intensity = 4e4
keys = [
  { time = 0, position = [60, 83, 100], intensity = 4e4 },
  { time = 1, position = [240, 83, 100], intensity = 8e4 },
]
"#;

#[test]
fn a_keyed_light_renders_at_its_frame_as_the_still_light_of_its_interpolated_values() {
    // A quarter of the way: x = 60 + 180 / 4 = 105, intensity 5e4, both
    // exact in f32, so the two renders are the same bits.
    let keyed = render("frame = 0.25", CROSSING).unwrap();
    let still = render(
        "",
        "[[light]]\ntype = \"point\"\nposition = [105, 83, 100]\nintensity = 5e4\n",
    )
    .unwrap();
    assert_eq!(bits(&keyed), bits(&still));
    let other = render("frame = 0.5", CROSSING).unwrap();
    assert_ne!(bits(&keyed), bits(&other), "the light moves between frames");
}

/// Per vertical strip of the image, the mean of `a - b` and its standard
/// error from the pixels' sample variances.
fn strip_differences(a: &Rendered, b: &[(Rendered, f64)], strips: u32) -> Vec<(f64, f64)> {
    let (w, h) = (a.image.width, a.image.height);
    (0..strips)
        .map(|s| {
            let (x0, x1) = (s * w / strips, (s + 1) * w / strips);
            let (mut d, mut var, mut n) = (0.0, 0.0, 0.0);
            for y in 0..h {
                for x in x0..x1 {
                    let p = (y * w + x) as usize;
                    let lum = |v: [f32; 4]| f64::from(v[0] + v[1] + v[2]) / 3.0;
                    d += lum(a.image.rgba[p]);
                    var += lum(a.image.variance[p]) / f64::from(a.image.spp);
                    for (r, weight) in b {
                        d -= weight * lum(r.image.rgba[p]);
                        var += weight * weight * lum(r.image.variance[p]) / f64::from(r.image.spp);
                    }
                    n += 1.0;
                }
            }
            (d / n, var.sqrt() / n)
        })
        .collect()
}

#[test]
fn a_light_moving_while_the_shutter_is_open_renders_the_mean_of_its_instants() {
    let blurred = render("spp = 64\nshutter = [0, 1]", CROSSING).unwrap();
    // Eight instants at the midpoints of eighths of the shutter: the
    // midpoint rule's error for this smooth motion is far below the noise.
    let instants: Vec<(Rendered, f64)> = (0..8)
        .map(|i| {
            let frame = (f64::from(i) + 0.5) / 8.0;
            let r = render(
                &format!("spp = 16\nseed = {}\nframe = {frame}", 10 + i),
                CROSSING,
            )
            .unwrap();
            (r, 1.0 / 8.0)
        })
        .collect();
    for (i, (d, se)) in strip_differences(&blurred, &instants, 4)
        .into_iter()
        .enumerate()
    {
        eprintln!("strip {i}: {d} +- {se}");
        assert!(
            d.abs() <= 4.0 * se,
            "strip {i}: blurred - mean of instants = {d} +- {se}"
        );
    }
    // The same bound tells the blur from the light held at the open time.
    let opening = render("spp = 64\nseed = 9", CROSSING).unwrap();
    let worst = strip_differences(&blurred, &[(opening, 1.0)], 4)
        .into_iter()
        .map(|(d, se)| d.abs() / se)
        .fold(0.0, f64::max);
    assert!(
        worst > 8.0,
        "the blur differs from the opening instant by {worst} standard errors"
    );
}

#[test]
fn a_closed_shutter_or_a_still_light_renders_as_without_keys() {
    let still = "[[light]]\ntype = \"point\"\nposition = [60, 83, 100]\nintensity = 4e4\n";
    let closed = render("shutter = [0, 0]", CROSSING).unwrap();
    assert_eq!(bits(&closed), bits(&render("", still).unwrap()));
    // Keys that hold the light still over the shutter cost no tables.
    let held = format!(
        "{still}keys = [{{ time = 0, intensity = 4e4 }}, {{ time = 1, intensity = 4e4 }}]\n"
    );
    let open = "shutter = [0, 1]";
    assert_eq!(
        bits(&render(open, &held).unwrap()),
        bits(&render(open, still).unwrap())
    );
}

#[test]
fn bad_keys_and_moving_lights_the_integrator_cannot_blur_are_refused_by_name() {
    let err = |render_table: &str, lights: &str| match render(render_table, lights) {
        Ok(_) => panic!("rendered: {lights}"),
        Err(e) => e.to_string(),
    };
    let e = err("", "[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nkeys = [{ time = 1, intensity = 2 }, { time = 0, intensity = 3 }]\n");
    assert!(
        e.contains("light 1") && e.contains("keys: times must be finite and increasing"),
        "{e}"
    );
    let e = err("", "[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nkeys = [{ time = 0, cone_angle = 30 }]\n");
    assert!(
        e.contains("`cone_angle` does not apply to a point light"),
        "{e}"
    );
    let e = err("", "[[light]]\ntype = \"point\"\nkeys = [{ time = 0, position = [0, 0, 0] }, { time = 2, intensity = -1 }]\n");
    assert!(
        e.contains("at the key at time") && e.contains("`intensity` is negative"),
        "{e}"
    );
    let e = err("", "[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nkeys = [{ time = 0, position = [0, 0] }]\n");
    assert!(e.contains("expected 3 numbers, got 2"), "{e}");
    let e = err("integrator = \"raymarch2pass\"\nshutter = [0, 1]", CROSSING);
    assert!(
        e.contains("light 1 changes while the shutter is open") && e.contains("raymarch2pass"),
        "{e}"
    );
    // Keys given only in the keys: the base needs no position of its own.
    render("", "[[light]]\ntype = \"point\"\nintensity = 4e4\nkeys = [{ time = 0, position = [60, 83, 100] }]\n").unwrap();
}
