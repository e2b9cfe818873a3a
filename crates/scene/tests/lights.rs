//! `[[light]]` tables: their units, which lights a scene then has, their
//! light-group layers (which sum to the beauty), and bad input named by
//! file and light.

use std::path::Path;

use cirrus_render::{AreaShape, Light};
use cirrus_scene::{Overrides, Scene, SceneDescription};
use glam::Vec3;

fn cloud() -> String {
    format!("{}/../../data/cloud.vdb", env!("CARGO_MANIFEST_DIR"))
}

fn scene(lights: &str) -> Scene {
    let text = format!("[[volume]]\nfile = {:?}\n{lights}", cloud());
    let desc = SceneDescription::parse(&text).unwrap();
    Scene::from_description(desc, Path::new(".")).unwrap()
}

fn lights_of(text: &str) -> Vec<Light> {
    let settings = scene(text).settings().unwrap();
    settings.lights.iter().cloned().collect()
}

#[test]
fn a_sphere_light_sends_its_radiance_times_its_projected_area() {
    // Radiance 2 * 2^1 * color over the area 4 pi 0.5^2 (normalised), times
    // the projected area pi 0.5^2: intensity 4 / 4 * color = color.
    let lights = lights_of(
        r#"
        [[light]]
        type = "sphere"
        position = [1, 2, 3]
        radius = 0.5
        intensity = 2
        exposure = 1
        color = [1, 0.5, 0.25]
        normalize = true
        visible_to_camera = true
        "#,
    );
    assert_eq!(lights.len(), 1, "no default sun or sky beside a [[light]]");
    let Light::Sphere(s) = &lights[0] else {
        panic!("{:?}", lights[0])
    };
    assert!(s.camera_visible());
    assert!(!s.soft_falloff(), "a ball by default, as UsdLux's sphere");
    assert!(
        (s.intensity() - Vec3::new(1.0, 0.5, 0.25))
            .abs()
            .max_element()
            < 1e-6
    );
    assert_eq!(s.position(), Vec3::new(1.0, 2.0, 3.0));
    // Unnormalised, the same numbers are the radiance: 4 color, times pi / 4.
    let lights = lights_of(
        "[[light]]\ntype = \"sphere\"\nposition = [0, 0, 0]\nradius = 0.5\nintensity = 4\n",
    );
    let Light::Sphere(s) = &lights[0] else {
        panic!()
    };
    assert!((s.intensity().x - std::f32::consts::PI).abs() < 1e-5);
    assert!(!s.camera_visible(), "hidden from the camera by default");
    // A point's strength is its intensity.
    let lights = lights_of("[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\nintensity = 3\n");
    let Light::Sphere(s) = &lights[0] else {
        panic!()
    };
    assert!(s.is_point());
    assert_eq!(s.intensity(), Vec3::splat(3.0));
    // Soft falloff on a sphere and a spot; refused where it has no meaning.
    for (kind, axis) in [
        ("sphere", ""),
        ("spot", "direction = [0, -1, 0]\ncone_angle = 30\n"),
    ] {
        let lights = lights_of(&format!(
            "[[light]]\ntype = \"{kind}\"\nposition = [0, 0, 0]\n{axis}radius = 0.5\nsoft_falloff = true\n"
        ));
        let Light::Sphere(s) = &lights[0] else {
            panic!()
        };
        assert!(s.soft_falloff(), "{kind}");
    }
}

#[test]
fn the_sun_and_sky_join_lights_only_where_given() {
    assert_eq!(lights_of("").len(), 2, "the default sun and sky");
    let lights = lights_of(
        r#"
        [sun]
        direction = [0, -1, 0]
        [[light]]
        type = "distant"
        direction = [1, -1, 0]
        intensity = 0.1
        angle = 0.5
        [[light]]
        type = "dome"
        intensity = 0.2
        "#,
    );
    let kinds: Vec<_> = lights.iter().map(Light::kind).collect();
    use cirrus_render::LightKind::{Distant, Dome};
    assert_eq!(kinds, [Distant, Distant, Dome]);
}

#[test]
fn light_groups_are_named_by_light_and_sum_to_the_beauty() {
    let mut s = scene(
        r#"
        [environment]
        radiance = [0.1, 0.12, 0.2]
        [[light]]
        type = "point"
        name = "lamp"
        position = [150, 160, 50]
        intensity = 4000
        [[light]]
        type = "spot"
        group = "lamp"
        position = [150, 200, 50]
        direction = [0, -1, 0]
        cone_angle = 30
        cone_softness = 0.2
        intensity = 8000
        [[light]]
        type = "sphere"
        position = [150, 80, -40]
        radius = 5
        intensity = 3
        "#,
    );
    s.apply(&Overrides {
        res: Some((24, 16)),
        spp: Some(4),
        light_groups: Some(true),
        ..Default::default()
    });
    let out = s.render().unwrap();
    let layers = out.layers.as_ref().unwrap();
    assert_eq!(
        layers.group_names,
        ["sun", "sky", "emission", "lamp", "lights"]
    );
    let c = &out.stats.counters;
    assert!(c.nee_rays_sphere > 0 && c.nee_rays_distant == 0, "{c:?}");
    let (mut lamp, mut sky) = (0.0f64, 0.0f64);
    for (i, px) in out.image.rgba.iter().enumerate() {
        for ch in 0..3 {
            let sum: f32 = layers.groups.iter().map(|g| g[i][ch]).sum();
            assert!(
                (sum - px[ch]).abs() <= 1e-5 * px[ch].abs().max(1.0),
                "pixel {i} channel {ch}: groups {sum} vs beauty {}",
                px[ch]
            );
        }
        lamp += layers.groups[3][i][1] as f64;
        sky += layers.groups[1][i][1] as f64;
        assert_eq!(layers.groups[0][i], [0.0; 3], "no sun");
    }
    assert!(lamp > 0.0 && sky > 0.0, "lamp {lamp} sky {sky}");
}

/// The error `text` (a scene file's lights) gives, read from a file.
fn error_of(lights: &str) -> String {
    let dir = std::env::temp_dir().join(format!("cirrus-lights-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    std::fs::write(&path, lights).unwrap();
    let e = Scene::load(&path)
        .err()
        .unwrap_or_else(|| panic!("no error from {lights}"))
        .to_string();
    assert!(e.contains("bad.toml"), "{e}");
    e
}

#[test]
fn bad_lights_are_errors_naming_the_file_and_the_light() {
    let lamp = "[[light]]\ntype = \"point\"\nposition = [0, 0, 0]\n[[light]]\nname = \"lamp\"\n";
    for (body, says) in [
        ("type = \"point\"\nposition = [0, 0, 0]\nintensity = -1", "`intensity` is negative"),
        ("type = \"sphere\"\nposition = [0, 0, 0]\nradius = -0.1", "`radius` is negative"),
        ("type = \"point\"\nposition = [0, nan, 0]", "`position` is not finite"),
        ("type = \"point\"", "needs `position`"),
        ("type = \"distant\"\ndirection = [0, 0, 0]", "`direction` is zero"),
        (
            "type = \"spot\"\nposition = [0, 0, 0]\ndirection = [0, -1, 0]\ncone_angle = 200",
            "`cone_angle` 200 is not in (0, 180]",
        ),
        (
            "type = \"spot\"\nposition = [0, 0, 0]\ndirection = [0, -1, 0]\ncone_angle = 20\ncone_softness = 2",
            "`cone_softness` 2 is not in [0, 1]",
        ),
        (
            "type = \"cylinder\"\nposition = [0, 0, 0]\ndirection = [1, 0, 0]\nlength = -2",
            "`length` -2 is not positive: an area light needs an area",
        ),
        ("type = \"cylinder\"\nposition = [0, 0, 0]", "a cylinder light needs `direction`"),
        (
            "type = \"cylinder\"\nposition = [0, 0, 0]\ndirection = [1, 0, 0]\nwidth = 2",
            "`width` does not apply to a cylinder light",
        ),
        (
            "type = \"rect\"\nposition = [0, 0, 0]\ndirection = [0, -1, 0]\nwidth = 0",
            "`width` 0 is not positive: an area light needs an area",
        ),
        (
            "type = \"disk\"\nposition = [0, 0, 0]\ndirection = [0, -1, 0]\nradius = 0",
            "`radius` 0: an area light needs an area",
        ),
        ("type = \"rect\"\nposition = [0, 0, 0]", "a rect light needs `direction`"),
        ("type = \"lamp\"", "unknown type \"lamp\""),
        (
            "type = \"point\"\nposition = [0, 0, 0]\nvisible_to_camera = true",
            "`visible_to_camera` does not apply to a point light",
        ),
        ("type = \"distant\"\ndirection = [0, -1, 0]\nradius = 1", "`radius` does not apply to a distant light"),
        (
            "type = \"point\"\nposition = [0, 0, 0]\nsoft_falloff = true",
            "`soft_falloff` does not apply to a point light",
        ),
        ("type = \"point\"\nposition = [0, 0, 0]\ncolor = [1, -1, 1]", "`color` is negative"),
    ] {
        let e = error_of(&format!("{lamp}{body}\n"));
        assert!(e.contains("light 2 (\"lamp\")"), "{e}");
        assert!(e.contains(says), "{e} (expected {says:?})");
    }
    let many: String = (0..6)
        .map(|i| format!("[[light]]\ntype = \"point\"\nname = \"l{i}\"\nposition = [0, 0, 0]\n"))
        .collect();
    // More named lights than light-group layers render where no groups
    // are written, and are refused where they are.
    let mut s = scene(&many);
    s.apply(&Overrides {
        res: Some((8, 8)),
        spp: Some(1),
        ..Default::default()
    });
    assert!(s.render().is_ok());
    s.apply(&Overrides {
        light_groups: Some(true),
        ..Default::default()
    });
    let e = s.render().map(drop).unwrap_err().to_string();
    assert!(
        e.contains("9 light groups") && e.contains("shared `group`"),
        "{e}"
    );
    // A long list of names is cut with a count.
    let lots: String = (0..10_000)
        .map(|i| format!("[[light]]\ntype = \"point\"\nname = \"n{i}\"\nposition = [0, 0, 0]\n"))
        .collect();
    let mut s = scene(&lots);
    s.apply(&Overrides {
        light_groups: Some(true),
        ..Default::default()
    });
    let e = s.render().map(drop).unwrap_err().to_string();
    assert!(
        e.contains("10003 light groups") && e.contains("and 9993 more"),
        "{e}"
    );
    assert!(e.len() < 400, "{} bytes", e.len());
}

/// Values each fine alone that overflow f32 together, or past what a
/// render can carry, and the shorthand tables' values: each refused
/// naming the file, the light or table, and the key.
#[test]
fn light_values_that_overflow_f32_are_refused_by_key() {
    for (body, says) in [
        ("type = \"dome\"\nexposure = 128", "`intensity` x 2^`exposure` x `color` is [inf"),
        ("type = \"dome\"\nintensity = 1e38\nexposure = 10", "past 1e30"),
        ("type = \"distant\"\ndirection = [0, -1, 0]\nintensity = 1e38", "past 1e30"),
        (
            "type = \"distant\"\ndirection = [0, -1, 0]\nintensity = 1e29\nangle = 0.01",
            "radiance (irradiance over the disc's solid angle)",
        ),
        (
            "type = \"sphere\"\nposition = [0, 0, 0]\nradius = 1e-25\nnormalize = true",
            "`radius` 1e-25 is too small",
        ),
        ("type = \"sphere\"\nposition = [0, 0, 0]\nradius = 1e19", "`radius` 1e19 is past 1e12"),
        ("type = \"point\"\nposition = [1e20, 0, 0]", "`position` [1.000e20, 0, 0] is past 1e12"),
        (
            "type = \"rect\"\nposition = [0, 0, 0]\ndirection = [0, -1, 0]\nwidth = 1e-30\nheight = 1e-30\nnormalize = true",
            "not positive in f32",
        ),
        ("type = \"point\"\nposition = [1, 2, 3, 4]", "expected 3 numbers, got 4"),
        ("type = \"point\"\nposition = [1, 2]", "expected 3 numbers, got 2"),
        ("type = \"dome\"\nmap = \"\"", "`map` is empty"),
    ] {
        let e = error_of(&format!("[[light]]\nname = \"hot\"\n{body}\n"));
        assert!(e.contains("bad.toml"), "{e}");
        assert!(e.contains(says), "{e} (expected {says:?})");
        if !says.starts_with("expected") {
            assert!(e.contains("light 1 (\"hot\")"), "{e}");
        }
    }
    // The shorthand tables (and so their flags) are checked where the
    // settings are resolved: their ranges by flag and key, then what a
    // render can carry.
    for (body, says) in [
        (
            "[sun]\ndirection = [0, 0, 0]",
            "--sun-dir ([sun] direction)",
        ),
        (
            "[sun]\nirradiance = [-1, 1, 1]",
            "--sun-irradiance ([sun] irradiance)",
        ),
        (
            "[environment]\nrotation = nan",
            "--env-rotation ([environment] rotation)",
        ),
        (
            "[environment]\nradiance = [nan, 0, 0]",
            "--env-radiance ([environment] radiance)",
        ),
        (
            "[environment]\nradiance = [1e31, 0, 0]",
            "[environment] its mean radiance",
        ),
        (
            "[sun]\nirradiance = [1e29, 1e29, 1e29]\nangle = 0.01",
            "[sun] its radiance (irradiance over the disc's solid angle)",
        ),
    ] {
        let e = scene(&format!("{body}\n"))
            .settings()
            .map(drop)
            .unwrap_err()
            .to_string();
        assert!(e.contains(says), "{e} (expected {says:?})");
    }
    // Within the limits, a normalised ball of any radius sends strength / 4.
    let lights = lights_of(
        "[[light]]\ntype = \"sphere\"\nposition = [0, 0, 0]\nradius = 1e-6\nintensity = 8\nnormalize = true\n",
    );
    let Light::Sphere(s) = &lights[0] else {
        panic!()
    };
    assert!((s.intensity() - Vec3::splat(2.0)).abs().max_element() < 1e-6);
}

#[test]
fn a_sphere_light_stays_where_it_is_against_the_volume_wherever_both_are() {
    // The cloud, a lamp beside it and the camera, all moved 5000 units:
    // render space follows the volumes, so the image is the same.
    let text = |dx: f32| {
        format!(
            r#"
            [camera]
            res = "24x16"
            from = [{}, 83, -250]
            to = [{}, 83, 100]
            [render]
            spp = 4
            [[light]]
            type = "sphere"
            position = [{}, 150, 20]
            radius = 5
            intensity = 200
            [[volume]]
            file = {:?}
            transform = {{ translate = [{dx}, 0, 0] }}
            "#,
            150.0 + dx,
            150.0 + dx,
            260.0 + dx,
            cloud()
        )
    };
    let render = |dx: f32| {
        let desc = SceneDescription::parse(&text(dx)).unwrap();
        let out = Scene::from_description(desc, Path::new("."))
            .unwrap()
            .render()
            .unwrap();
        out.image.rgba.iter().map(|p| p[1] as f64).sum::<f64>()
    };
    let (here, there) = (render(0.0), render(5000.0));
    assert!(here > 0.0);
    assert!(
        (here / there - 1.0).abs() < 1e-3,
        "green sum {here} here, {there} moved"
    );
}

#[test]
fn area_lights_take_their_size_orientation_and_normalisation() {
    let lights = lights_of(
        r#"
        [[light]]
        type = "rect"
        position = [1, 2, 3]
        direction = [0, -2, 0]
        up = [0, 0, 1]
        width = 2
        height = 0.5
        intensity = 3
        normalize = true
        [[light]]
        type = "disk"
        position = [0, 5, 0]
        direction = [0, -1, 0]
        radius = 0.5
        color = [1, 0.5, 0.25]
        [[light]]
        type = "cylinder"
        position = [0, 1, 0]
        direction = [0, 0, 3]
        radius = 0.25
        length = 4
        intensity = 2
        normalize = true
        visible_to_camera = true
        "#,
    );
    let [Light::Area(rect), Light::Area(disk), Light::Area(tube)] = lights.as_slice() else {
        panic!("{lights:?}")
    };
    assert_eq!(tube.shape(), AreaShape::Cylinder);
    assert!(tube.camera_visible() && !rect.camera_visible());
    assert!((tube.area() - 2.0 * std::f32::consts::PI).abs() < 1e-5);
    assert_eq!(tube.normal(), Vec3::Z, "its axis");
    assert!(
        (tube.radiance() - Vec3::splat(1.0 / std::f32::consts::PI))
            .abs()
            .max_element()
            < 1e-6
    );
    assert_eq!(rect.area(), 1.0);
    assert_eq!(rect.normal(), -Vec3::Y);
    assert_eq!(
        rect.radiance(),
        Vec3::splat(3.0),
        "normalised by its area of 1"
    );
    assert_eq!(rect.centre(), Vec3::new(1.0, 2.0, 3.0));
    assert!((disk.area() - std::f32::consts::PI * 0.25).abs() < 1e-6);
    assert_eq!(disk.radiance(), Vec3::new(1.0, 0.5, 0.25));
}

/// Forty balls and panels of different strengths through a thin fog,
/// rendered with the light tree's pick (`one`: past 8 lights) and with the
/// uniform pick (whose expectation is the image): the two image means
/// agree within four standard errors (from the pixels' sample variances),
/// and the tree's pick is the less noisy. The balls are met by scattered
/// rays too, so their MIS weights take the tree's probability of the
/// light, which must be the pick's for the means to agree.
#[test]
fn a_light_trees_image_is_the_uniform_picks() {
    let mut rng = cirrus_testkit::SplitMix64(40);
    let mut lights = String::new();
    for k in 0..40 {
        let p = [0, 1, 2].map(|_| 40.0 + 200.0 * rng.unit());
        let strength = 500.0 + 4000.0 * rng.unit();
        lights += &if k % 4 == 0 {
            format!(
                "[[light]]\ntype = \"rect\"\nposition = [{}, {}, {}]\ndirection = [0, -1, 0.3]\n\
                 width = 12\nheight = 12\nintensity = {}\n",
                p[0],
                p[1],
                p[2],
                strength / 100.0
            )
        } else {
            format!(
                "[[light]]\ntype = \"sphere\"\nposition = [{}, {}, {}]\nradius = 6\nintensity = {}\n",
                p[0], p[1], p[2], strength / 100.0
            )
        };
    }
    let render = |sampling: cirrus_render::LightSampling| {
        let mut s = scene(&lights);
        s.apply(&Overrides {
            density_scale: Some(cirrus_scene::description::Colour::Grey(0.05)),
            res: Some((32, 24)),
            spp: Some(96),
            camera_from: Some([150.0, 83.0, -250.0]),
            camera_to: Some([150.0, 83.0, 100.0]),
            light_sampling: Some(sampling),
            ..Default::default()
        });
        s.render().unwrap().image
    };
    // The image's mean (green) and its standard error.
    let stats = |i: &cirrus_render::Image| {
        let n = i.rgba.len() as f64;
        let mean = i.rgba.iter().map(|p| f64::from(p[1])).sum::<f64>() / n;
        let var: f64 = i.variance.iter().map(|v| f64::from(v[1])).sum::<f64>() / f64::from(i.spp);
        (mean, var.sqrt() / n)
    };
    let (tree, tree_se) = stats(&render(cirrus_render::LightSampling::One));
    let (uniform, uniform_se) = stats(&render(cirrus_render::LightSampling::Uniform));
    let se = (tree_se * tree_se + uniform_se * uniform_se).sqrt();
    assert!(tree > 10.0 * se, "a lit image: {tree} +- {tree_se}");
    assert!(
        (tree - uniform).abs() < 4.0 * se,
        "tree {tree} +- {tree_se}, uniform {uniform} +- {uniform_se}"
    );
    assert!(tree_se < uniform_se, "{tree_se} vs {uniform_se}");
}
