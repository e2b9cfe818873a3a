//! Motion blur through the scene model: the shutter and velocity fields of
//! lone volumes and scene files, on the corpus's `multi_grid.vdb` (its
//! "velocity" grid is a vec3s swirl with an updraft).

use cirrus_scene::{Overrides, Scene, SceneDescription};
use std::path::Path;

fn data(name: &str) -> String {
    format!("{}/../../data/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn small() -> Overrides {
    Overrides {
        res: Some((24, 16)),
        spp: Some(2),
        seed: Some(5),
        ..Default::default()
    }
}

fn bits(rgba: &[[f32; 4]]) -> Vec<[u32; 4]> {
    rgba.iter().map(|p| p.map(f32::to_bits)).collect()
}

fn lone(extra: Overrides) -> Result<cirrus_render::Rendered, cirrus_scene::Error> {
    let mut scene = Scene::load(Path::new(&data("multi_grid.vdb")))?;
    scene.apply(&small());
    scene.apply(&extra);
    scene.render()
}

#[test]
fn a_closed_shutter_renders_bit_identical_to_no_motion_blur() {
    let reference = lone(Overrides::default()).unwrap();
    let closed = lone(Overrides {
        shutter: Some([0.0, 0.0]),
        velocity: Some("velocity".into()),
        ..Default::default()
    })
    .unwrap();
    assert_eq!(bits(&closed.image.rgba), bits(&reference.image.rgba));
    // The random sampler draws its time from a hash, never the stream.
    let random = |shutter| Overrides {
        sampler: Some(cirrus_render::SamplerKind::Random),
        shutter,
        ..Default::default()
    };
    let a = lone(random(None)).unwrap();
    let b = lone(Overrides {
        shutter: Some([0.0, 0.0]),
        ..random(None)
    })
    .unwrap();
    assert_eq!(bits(&a.image.rgba), bits(&b.image.rgba));
}

#[test]
fn a_velocity_grid_called_velocity_is_found_and_a_missing_one_is_warned_about() {
    let open = |velocity: Option<&str>| Overrides {
        shutter: Some([-0.5, 0.5]),
        velocity: velocity.map(String::from),
        ..Default::default()
    };
    // Houdini's and Blender's name: used without being named.
    let named = lone(open(Some("velocity"))).unwrap();
    let found = lone(open(None)).unwrap();
    assert_eq!(bits(&found.image.rgba), bits(&named.image.rgba));
    assert!(
        found.stats.warnings.is_empty(),
        "{:?}",
        found.stats.warnings
    );
    let still = lone(Overrides::default()).unwrap();
    assert_ne!(bits(&found.image.rgba), bits(&still.image.rgba), "it blurs");
    // A file with no vector grid renders still, and says why.
    let mut scene = Scene::load(Path::new(&data("cloud.vdb"))).unwrap();
    scene.apply(&small());
    scene.apply(&open(None));
    let r = scene.render().unwrap();
    let w = r.stats.warnings.join("\n");
    assert!(
        w.contains("cloud.vdb") && w.contains("no velocity grid") && w.contains("no vector grid"),
        "{w}"
    );
}

#[test]
fn an_open_shutter_blurs_with_true_majorants() {
    let reference = lone(Overrides::default()).unwrap();
    let blurred = lone(Overrides {
        shutter: Some([-0.5, 0.5]),
        velocity: Some("velocity".into()),
        velocity_scale: Some(8.0),
        ..Default::default()
    })
    .unwrap();
    assert_ne!(bits(&blurred.image.rgba), bits(&reference.image.rgba));
    assert_eq!(blurred.stats.counters.majorant_violations, 0);
}

#[test]
fn a_velocity_grid_that_is_not_vec3_is_an_error_naming_file_and_grid() {
    let e = lone(Overrides {
        shutter: Some([0.0, 0.5]),
        velocity: Some("temperature".into()),
        ..Default::default()
    })
    .err()
    .expect("a float grid is no velocity");
    assert!(
        e.to_string().contains("multi_grid.vdb") && e.to_string().contains("\"temperature\""),
        "{}",
        e
    );
    assert!(e.to_string().contains("vec3"), "{e}");
}

#[test]
fn scene_files_take_the_shutter_and_per_volume_velocity() {
    let text = format!(
        r#"
        [render]
        spp = 2
        seed = 5
        shutter = [-0.25, 0.25]
        [camera]
        res = "24x16"
        [[volume]]
        file = "{}"
        velocity = "velocity"
        velocity_unit = "voxels"
        velocity_scale = 4.0
        "#,
        data("multi_grid.vdb")
    );
    let desc = SceneDescription::parse(&text).unwrap();
    assert_eq!(desc.render.shutter, Some([-0.25, 0.25]));
    assert_eq!(desc.volumes[0].velocity.as_deref(), Some("velocity"));
    let scene = Scene::from_description(desc.clone(), Path::new("/")).unwrap();
    let blurred = scene.render().unwrap();
    assert_eq!(blurred.stats.counters.majorant_violations, 0);
    let mut still = desc;
    still.render.shutter = None;
    let reference = Scene::from_description(still, Path::new("/"))
        .unwrap()
        .render()
        .unwrap();
    assert_ne!(bits(&blurred.image.rgba), bits(&reference.image.rgba));
    let e = SceneDescription::parse("[render]\nshutter = [0.5]\n").unwrap_err();
    assert!(e.contains("shutter"), "{e}");
}
