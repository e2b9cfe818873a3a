//! The USD reader on stages written here as text (and as binary crates by
//! the `openusd` writer): what it reads, what it warns about, the errors
//! broken stages give, and byte-mutated stages that must fail cleanly or
//! render. The comparisons against stages authored by Pixar's usd-core
//! are in `crates/python/tests/test_usd.py`.

use std::path::{Path, PathBuf};

use cirrus_scene::{ErrorKind, Overrides, Scene};
use cirrus_testkit::{mutate_past_header, SplitMix64};

fn cloud() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/cloud.vdb")
}

/// A fresh directory under the target dir holding `cloud.vdb`.
fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("usd")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::copy(cloud(), d.join("cloud.vdb")).unwrap();
    d
}

/// A volume named `name` reading `file`'s grid `grid`, bound to a material.
fn volume(name: &str, file: &str, grid: &str) -> String {
    format!(
        r#"
def Volume "{name}" (
    prepend apiSchemas = ["MaterialBindingAPI"]
)
{{
    rel field:density = </World/{name}/density>
    rel material:binding = </Materials/Smoke>
    double3 xformOp:translate = (1, 2, 3)
    uniform token[] xformOpOrder = ["xformOp:translate"]
    def OpenVDBAsset "density"
    {{
        asset filePath = @{file}@
        token fieldName = "{grid}"
    }}
}}
"#
    )
}

const MATERIAL: &str = r#"
def Scope "Materials"
{
    def Material "Smoke"
    {
        token outputs:volume.connect = </Materials/Smoke/Shader.outputs:volume>
        def Shader "Shader"
        {
            uniform token info:id = "cirrus:volume"
            float inputs:density = 2.5
            color3f inputs:albedo = (0.9, 0.8, 0.7)
            float inputs:anisotropy = 0.3
            float inputs:roughness = 1
            token outputs:volume
        }
    }
}
"#;

fn stage(body: &str) -> String {
    format!("#usda 1.0\n(\n    startTimeCode = 1\n    endTimeCode = 1\n)\n\ndef Xform \"World\"\n{{\n{body}\n}}\n{MATERIAL}")
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_volume_its_material_and_transform_are_read() {
    let d = dir("read");
    let p = write(
        &d,
        "shot.usda",
        &stage(&volume("Cloud", "./cloud.vdb", "density")),
    );
    let scene = Scene::load(&p).unwrap();
    let desc = scene.description();
    assert_eq!(desc.volumes.len(), 1);
    let v = &desc.volumes[0];
    assert_eq!(v.file, d.join("cloud.vdb"));
    assert_eq!(v.grid.as_deref(), Some("density"));
    assert_eq!(v.density_scale.unwrap().rgb(), [2.5; 3]);
    assert_eq!(v.albedo.unwrap().rgb(), [0.9, 0.8, 0.7]);
    assert_eq!(v.g, Some(0.3));
    let m = v.transform.matrix.unwrap();
    assert_eq!([m[0][3], m[1][3], m[2][3]], [1.0, 2.0, 3.0]);
    // The shader input cirrus does not read is named in a warning; no
    // lights make another.
    let w = scene.warnings().join("\n");
    assert!(w.contains("inputs:roughness"), "{w}");
    assert!(
        w.contains(
            "no DistantLight, DomeLight, SphereLight, RectLight, DiskLight or CylinderLight"
        ),
        "{w}"
    );
}

#[test]
fn a_mesh_is_named_in_a_warning_and_the_volume_still_renders() {
    let d = dir("mesh");
    let body = format!(
        "{}\n    def Mesh \"Ground\" {{}}\n",
        volume("Cloud", "./cloud.vdb", "density")
    );
    let p = write(&d, "shot.usda", &stage(&body));
    let mut scene = Scene::load(&p).unwrap();
    let w = scene.warnings().join("\n");
    assert!(w.contains("/World/Ground (Mesh)"), "{w}");
    assert_eq!(w.matches("/World/Ground").count(), 1, "listed once: {w}");
    scene.apply(&Overrides {
        res: Some((8, 8)),
        spp: Some(1),
        env_radiance: Some([1.0; 3]),
        ..Default::default()
    });
    let rendered = scene.render().unwrap();
    let alpha: f32 = rendered.image.rgba.iter().map(|p| p[3]).sum();
    assert!(alpha > 0.0, "the cloud covers some pixels");
}

#[test]
fn broken_stages_name_the_prim_and_the_file() {
    let d = dir("broken");
    let err = |name: &str, text: &str| {
        let p = write(&d, name, text);
        Scene::load(&p)
            .err()
            .unwrap_or_else(|| panic!("{name} loaded"))
    };
    let e = err(
        "missing.usda",
        &stage(&volume("Cloud", "./nowhere.vdb", "density")),
    );
    assert_eq!(e.kind(), ErrorKind::File);
    for part in ["missing.usda", "/World/Cloud/density", "nowhere.vdb"] {
        assert!(e.to_string().contains(part), "{part}: {}", e);
    }
    let e = err(
        "grid.usda",
        &stage(&volume("Cloud", "./cloud.vdb", "smoke")),
    );
    for part in [
        "grid.usda",
        "/World/Cloud/density",
        "cloud.vdb",
        "\"smoke\"",
        "density",
    ] {
        assert!(e.to_string().contains(part), "{part}: {}", e);
    }
    std::fs::write(
        d.join("garbage.usda"),
        "#usda 1.0\ndef Xform \"A\" {{{{ nonsense",
    )
    .unwrap();
    let broken_ref = stage(&format!(
        "{}\n    def \"Prop\" (prepend references = @./garbage.usda@</A>) {{}}\n",
        volume("Cloud", "./cloud.vdb", "density")
    ));
    let e = err("unreadable.usda", &broken_ref);
    assert!(
        e.to_string().contains("unreadable.usda") && e.to_string().contains("garbage.usda"),
        "{}",
        e.to_string()
    );
    assert!(e.to_string().contains("/World/Prop"), "{}", e.to_string());
    write(
        &d,
        "b.usda",
        "#usda 1.0\n(defaultPrim = \"B\")\ndef Xform \"B\" (prepend references = @./a.usda@) {}\n",
    );
    let e = err(
        "a.usda",
        "#usda 1.0\n(defaultPrim = \"A\")\ndef Xform \"A\" (prepend references = @./b.usda@) {}\n",
    );
    assert!(
        e.to_string().contains("a.usda") && e.to_string().contains("cycle"),
        "{}",
        e.to_string()
    );
    let e = err("empty.usda", "#usda 1.0\ndef Xform \"World\" {}\n");
    assert!(e.to_string().contains("no Volume"), "{}", e.to_string());
}

#[test]
fn time_samples_become_frames_files_and_transforms() {
    let d = dir("time");
    std::fs::copy(cloud(), d.join("cloud2.vdb")).unwrap();
    let text = r#"#usda 1.0
(
    startTimeCode = 1
    endTimeCode = 3
    timeCodesPerSecond = 24
)
def Volume "Cloud"
{
    rel field:density = </Cloud/density>
    double3 xformOp:translate.timeSamples = { 1: (0, 0, 0), 3: (4, 0, 0) }
    uniform token[] xformOpOrder = ["xformOp:translate"]
    def OpenVDBAsset "density"
    {
        asset filePath = @./cloud.vdb@
        token fieldName = "density"
    }
}
"#;
    // The per-frame filePath, authored through openusd into a binary
    // crate (its text parser takes no asset values in timeSamples).
    let usda = write(&d, "base.usda", text);
    let stage = openusd::usd::Stage::open(usda.to_str().unwrap()).unwrap();
    let file_path = stage.attribute("/Cloud/density.filePath");
    for (t, f) in [(1.0, "./cloud.vdb"), (2.0, "./cloud2.vdb")] {
        let value = openusd::sdf::Value::AssetPath(openusd::sdf::AssetPath::new(f));
        file_path
            .clone()
            .set_at(value, openusd::usd::TimeCode::new(t))
            .unwrap();
    }
    let p = d.join("shot.usdc");
    stage.root_layer().export(p.to_str().unwrap()).unwrap();
    let scene = Scene::load(&p).unwrap();
    let desc = scene.description();
    assert_eq!(desc.render.frames.as_deref(), Some("1-3"));
    assert_eq!(desc.render.frame, Some(1.0));
    let v = &desc.volumes[0];
    let samples = v.transform.samples.as_ref().unwrap();
    assert_eq!(
        samples.iter().map(|s| s.time).collect::<Vec<_>>(),
        [1.0, 3.0]
    );
    assert_eq!(samples[1].matrix[0][3], 4.0);
    assert_eq!(v.file, d.join("cloud.vdb"));
    let files: Vec<PathBuf> = [1, 2, 3]
        .into_iter()
        .map(|f| scene.for_frame(f).inputs()[0].clone())
        .collect();
    assert_eq!(
        files,
        [
            d.join("cloud.vdb"),
            d.join("cloud2.vdb"),
            d.join("cloud2.vdb")
        ]
    );
    assert!(scene.warnings().join("\n").contains("no volume material"));
    // The same samples in a text layer: refused with a hint.
    let sampled = text.replace(
        "asset filePath = @./cloud.vdb@",
        "asset filePath.timeSamples = { 1: @./cloud.vdb@, 2: @./cloud2.vdb@ }",
    );
    let e = Scene::load(&write(&d, "text.usda", &sampled)).unwrap_err();
    assert!(
        e.to_string().contains("text.usda") && e.to_string().contains(".usdc"),
        "{}",
        e.to_string()
    );
}

/// 200 stages, text and binary, with bytes flipped, overwritten or cut:
/// each loads and renders (8x8, 1 spp) or gives an error naming the file;
/// none panics the process or hangs.
#[test]
fn mutated_stages_fail_cleanly_or_render() {
    let d = dir("mutated");
    let text = stage(&format!(
        "{}\n{}",
        volume("A", "./cloud.vdb", "density"),
        volume("B", "./cloud.vdb", "density")
    ));
    let usda = write(&d, "base.usda", &text);
    let usdc = d.join("base.usdc");
    openusd::usd::Stage::open(usda.to_str().unwrap())
        .unwrap()
        .root_layer()
        .export(usdc.to_str().unwrap())
        .unwrap();
    let mut rng = SplitMix64(24);
    let (mut loaded, mut refused) = (0, 0);
    for k in 0..200 {
        let (base, ext) = if k % 2 == 0 {
            (&usda, "usda")
        } else {
            (&usdc, "usdc")
        };
        let mut bytes = std::fs::read(base).unwrap();
        mutate_past_header(&mut rng, &mut bytes, 4);
        let p = d.join(format!("m{k}.{ext}"));
        std::fs::write(&p, &bytes).unwrap();
        match Scene::load(&p) {
            Ok(mut scene) => {
                scene.apply(&Overrides {
                    res: Some((8, 8)),
                    spp: Some(1),
                    ..Default::default()
                });
                match scene.render() {
                    Ok(_) => loaded += 1,
                    Err(e) => {
                        assert!(!e.to_string().is_empty());
                        refused += 1
                    }
                }
            }
            Err(e) => {
                assert!(
                    e.to_string().contains(&format!("m{k}.{ext}")),
                    "{}",
                    e.to_string()
                );
                refused += 1;
            }
        }
    }
    eprintln!("200 mutated stages: {loaded} rendered, {refused} refused");
    assert_eq!(loaded + refused, 200);
    assert!(
        refused > 0 && loaded > 0,
        "{loaded} loaded, {refused} refused"
    );
}

#[test]
fn every_light_of_a_stage_is_read_with_its_transform_and_shaping() {
    let d = dir("lights");
    let lights = r#"
    def DistantLight "Sun"
    {
        float inputs:intensity = 2
        bool inputs:normalize = 1
    }
    def DistantLight "Moon"
    {
        float inputs:intensity = 0.25
        bool inputs:normalize = 1
        float inputs:angle = 0.5
        float3 xformOp:rotateXYZ = (90, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
    }
    def SphereLight "Bulb"
    {
        float inputs:radius = 0.5
        float inputs:intensity = 8
        float inputs:exposure = 1
        color3f inputs:color = (1, 0.5, 0.25)
        double3 xformOp:translate = (10, 20, 30)
        float3 xformOp:scale = (2, 2, 2)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]
    }
    def SphereLight "Lamp" (
        prepend apiSchemas = ["ShapingAPI"]
    )
    {
        float inputs:radius = 0.5
        bool inputs:normalize = 1
        bool treatAsPoint = 1
        float inputs:intensity = 100
        float inputs:shaping:cone:angle = 30
        float inputs:shaping:cone:softness = 0.25
        float inputs:shaping:focus = 1
        double3 xformOp:translate = (0, 50, 0)
        float3 xformOp:rotateXYZ = (-90, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ"]
    }
"#;
    let area = r#"
    def RectLight "Panel"
    {
        float inputs:width = 2
        float inputs:height = 3
        float inputs:intensity = 5
        double3 xformOp:translate = (0, 10, 0)
        float3 xformOp:scale = (2, 1, 1)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]
    }
    def DiskLight "Round"
    {
        float inputs:radius = 0.25
    }
"#;
    let body = format!(
        "{}{lights}{area}",
        volume("Cloud", "./cloud.vdb", "density")
    );
    let p = write(&d, "shot.usda", &stage(&body));
    let mut scene = Scene::load(&p).unwrap();
    let w = scene.warnings().join("\n");
    assert!(
        w.contains("/World/Lamp: shaping:focus is not applied"),
        "{w}"
    );
    assert!(!w.contains("not rendered"), "{w}");
    let desc = scene.description();
    assert_eq!(desc.sun.as_ref().unwrap().sun_irradiance, Some([2.0; 3]));
    let l = &desc.lights;
    assert_eq!(l.len(), 5, "{l:?}");
    // The panel: 2 x 3 scaled by 2 in X, emitting along -Z, up +Y.
    assert_eq!(l[3].kind, "rect");
    assert_eq!((l[3].width, l[3].height), (Some(4.0), Some(3.0)));
    assert_eq!(l[3].direction, Some([0.0, 0.0, -1.0]));
    assert_eq!(l[3].up, Some([0.0, 1.0, 0.0]));
    assert_eq!(l[3].position, Some([0.0, 10.0, 0.0]));
    assert_eq!(l[3].color, Some([5.0; 3]));
    assert_eq!(l[4].kind, "disk");
    assert_eq!((l[4].width, l[4].height), (Some(0.5), Some(0.5)));
    // The moon: -Z turned 90 degrees about X points along +Y.
    assert_eq!(
        (l[0].kind.as_str(), l[0].name.as_deref()),
        ("distant", Some("Moon"))
    );
    let dir = l[0].direction.unwrap();
    assert!(
        (dir[1] - 1.0).abs() < 1e-6 && dir[2].abs() < 1e-6,
        "{dir:?}"
    );
    assert_eq!(l[0].color, Some([0.25; 3]));
    assert_eq!(l[0].angle, Some(0.5));
    // The bulb: radiance 8 * 2 * colour, radius scaled by 2.
    assert_eq!(l[1].kind, "sphere");
    assert_eq!(l[1].position, Some([10.0, 20.0, 30.0]));
    assert_eq!(l[1].radius, Some(1.0));
    assert_eq!(l[1].color, Some([16.0, 8.0, 4.0]));
    assert_eq!(l[1].normalize, Some(false));
    // The lamp: a point spot of the normalised sphere's intensity, 100 / 4,
    // its axis -Z turned -90 degrees about X: down.
    assert_eq!(l[2].kind, "spot");
    assert_eq!(l[2].radius, Some(0.0));
    assert_eq!(l[2].color, Some([25.0; 3]));
    let axis = l[2].direction.unwrap();
    assert!((axis[1] + 1.0).abs() < 1e-6, "{axis:?}");
    assert_eq!(
        (l[2].cone_angle, l[2].cone_softness),
        (Some(30.0), Some(0.25))
    );
    // It renders, lamp and bulb and moon in their own layers.
    scene.apply(&Overrides {
        res: Some((8, 8)),
        spp: Some(1),
        light_groups: Some(true),
        ..Default::default()
    });
    let out = scene.render().unwrap();
    let names = &out.layers.as_ref().unwrap().group_names;
    assert_eq!(names[3..], ["Moon", "Bulb", "Lamp", "Panel", "Round"]);
    assert!(out.stats.counters.nee_rays_sphere > 0);
}

#[test]
fn a_cylinder_light_lies_along_its_x_axis_and_renders() {
    let d = dir("cylinder");
    let tube = r#"
    def CylinderLight "Tube"
    {
        float inputs:length = 30
        float inputs:radius = 1
        float inputs:intensity = 40
        bool treatAsLine = 1
        double3 xformOp:translate = (150, 150, 100)
        float3 xformOp:rotateXYZ = (0, 0, 90)
        float3 xformOp:scale = (2, 1, 3)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ", "xformOp:scale"]
    }
"#;
    let body = format!("{}{tube}", volume("Cloud", "./cloud.vdb", "density"));
    let p = write(&d, "tube.usda", &stage(&body));
    let mut scene = Scene::load(&p).unwrap();
    let w = scene.warnings().join("\n");
    assert!(w.contains("/World/Tube: treatAsLine is not applied"), "{w}");
    assert!(!w.contains("not rendered"), "{w}");
    let l = &scene.description().lights;
    // Its X axis turned 90 degrees about Z to +Y (scaled by 2), its
    // length scaled by 2, its radius by the mean of the Y and Z scales.
    assert_eq!(l.len(), 1, "{l:?}");
    assert_eq!(
        (l[0].kind.as_str(), l[0].name.as_deref()),
        ("cylinder", Some("Tube"))
    );
    assert_eq!(l[0].position, Some([150.0, 150.0, 100.0]));
    let axis = l[0].direction.unwrap();
    assert!(
        (axis[1] - 2.0).abs() < 1e-5 && axis[0].abs() < 1e-5,
        "{axis:?}"
    );
    assert_eq!((l[0].length, l[0].radius), (Some(60.0), Some(2.0)));
    assert_eq!(l[0].color, Some([40.0; 3]));
    scene.apply(&Overrides {
        res: Some((16, 12)),
        spp: Some(2),
        ..Default::default()
    });
    let out = scene.render().unwrap();
    assert!(out.stats.counters.nee_rays_area > 0);
    let mean: f32 = out.image.rgba.iter().map(|p| p[0]).sum::<f32>() / out.image.rgba.len() as f32;
    assert!(mean > 0.0, "the tube lights the cloud");
}

#[test]
fn lights_under_an_invisible_parent_are_not_read() {
    let d = dir("invisible");
    let body = format!(
        r#"{}
    def Xform "Hidden"
    {{
        token visibility = "invisible"
        def SphereLight "Behind" {{ float inputs:intensity = 5 }}
        def Xform "Deeper" {{ def RectLight "Under" {{ float inputs:intensity = 5 }} }}
    }}
    def Xform "Shown"
    {{
        def SphereLight "Lamp" {{ float inputs:intensity = 5 }}
    }}
"#,
        volume("Cloud", "./cloud.vdb", "density")
    );
    let p = write(&d, "hidden.usda", &stage(&body));
    let scene = Scene::load(&p).unwrap();
    let names: Vec<_> = scene
        .description()
        .lights
        .iter()
        .map(|l| l.name.clone().unwrap_or_default())
        .collect();
    assert_eq!(names, ["Lamp"]);
}

#[test]
fn light_values_past_f32_are_refused_naming_the_stage_prim_and_value() {
    let d = dir("f32_lights");
    let cases = [
        // Finite doubles that are infinite in f32.
        ("def SphereLight \"Hot\" { double inputs:intensity = 1e300 }", "/World/Hot", "inf"),
        ("def DomeLight \"Sky\" { float inputs:intensity = 1e39 }", "/World/Sky", "inf"),
        (
            "def SphereLight \"Far\" { double3 xformOp:translate = (1e300, 0, 0)\n uniform token[] xformOpOrder = [\"xformOp:translate\"] }",
            "/World/Far",
            "position",
        ),
        // A NaN read as a person writes it, not as a debug form.
        ("def SphereLight \"Nan\" { float inputs:intensity = nan }", "/World/Nan", "got nan"),
        (
            "def SphereLight \"Neg\" { float inputs:intensity = -1e38 }",
            "/World/Neg",
            "-1e38",
        ),
    ];
    for (k, (light, prim, says)) in cases.iter().enumerate() {
        let body = format!("{}\n{light}\n", volume("Cloud", "./cloud.vdb", "density"));
        let name = format!("case{k}.usda");
        let p = write(&d, &name, &stage(&body));
        let e = Scene::load(&p).map(drop).unwrap_err().to_string();
        assert!(
            e.contains(&name) && e.contains(prim) && e.contains(says),
            "{light}: {e}"
        );
        assert!(
            !e.contains("Float(") && !e.contains("Vec3") && !e.contains("000000000000"),
            "{e}"
        );
    }
}

#[test]
fn a_distant_light_too_dim_to_see_is_warned_about() {
    let d = dir("dim_sun");
    // UsdLux: without `normalize`, intensity 2 is the radiance of a
    // 0.53-degree disk, 2 pi sin^2(0.265 deg) = 1.3e-4 W/m^2.
    let warnings = |normalize: &str| {
        let light = format!(
            "    def DistantLight \"Sun\"\n    {{\n        float inputs:intensity = 2\n{normalize}    }}\n"
        );
        let body = format!("{}{light}", volume("Cloud", "./cloud.vdb", "density"));
        let p = write(&d, "shot.usda", &stage(&body));
        Scene::load(&p).unwrap().warnings().join("\n")
    };
    let w = warnings("");
    assert!(
        w.contains("/World/Sun: irradiance 1.344e-4 W/m^2 lights nothing visibly")
            && w.contains("inputs:normalize = 1"),
        "{w}"
    );
    let w = warnings("        bool inputs:normalize = 1\n");
    assert!(!w.contains("/World/Sun"), "{w}");
}

#[test]
fn time_sampled_lights_become_keyed_lights_that_render_as_their_toml_twins() {
    let d = dir("moving_lights");
    let body = format!(
        r#"{}
    def SphereLight "Lamp"
    {{
        float inputs:intensity.timeSamples = {{ 1: 2, 3: 6 }}
        float inputs:radius = 0.5
        double3 xformOp:translate.timeSamples = {{ 1: (0, 2, 0), 3: (4, 2, 0) }}
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }}
    def DistantLight "Sun"
    {{
        float inputs:intensity = 3
        float inputs:angle = 0
        float3 xformOp:rotateX.timeSamples = {{ 1: -90, 3: -60 }}
        uniform token[] xformOpOrder = ["xformOp:rotateX"]
    }}
"#,
        volume("Cloud", "./cloud.vdb", "density")
    );
    let text = stage(&body).replace("endTimeCode = 1", "endTimeCode = 3");
    let p = write(&d, "lamps.usda", &text);
    let scene = Scene::load(&p).unwrap();
    let desc = scene.description();
    assert_eq!(
        desc.sun.as_ref().unwrap().sun,
        Some(false),
        "a moving sun is a keyed light"
    );
    let sun = desc.lights.iter().find(|l| l.kind == "distant").unwrap();
    assert_eq!(
        sun.group.as_deref(),
        Some("sun"),
        "in the sun's layer still"
    );
    let lamp = desc.lights.iter().find(|l| l.kind == "sphere").unwrap();
    let keys = lamp.keys.as_ref().unwrap();
    assert_eq!(keys.iter().map(|k| k.time).collect::<Vec<_>>(), [1.0, 3.0]);
    assert_eq!(keys[1].position, Some([4.0, 2.0, 0.0]));
    assert_eq!(keys[1].color, Some([6.0; 3]));
    // Frame 2 is halfway: the lamp at (2, 2, 0) of radiance 4, the sun
    // turned 75 degrees; the same light as a scene file renders the same.
    let at2 = lamp.at(2.0);
    assert_eq!(at2.position, Some([2.0, 2.0, 0.0]));
    assert_eq!(at2.color, Some([4.0; 3]));
    let small = Overrides {
        res: Some((16, 12)),
        spp: Some(2),
        ..Default::default()
    };
    let mut usd = scene.for_frame(2);
    usd.apply(&small);
    let r = usd.render().unwrap();
    let mut twin = usd.description().clone();
    for l in &mut twin.lights {
        *l = l.at(2.0);
    }
    let mut twin = Scene::from_description(twin, &d).unwrap();
    twin.apply(&small);
    let t = twin.render().unwrap();
    assert_eq!(r.image.rgba, t.image.rgba);
    let first = {
        let mut s = scene.for_frame(1);
        s.apply(&small);
        s.render().unwrap()
    };
    assert_ne!(
        first.image.rgba, r.image.rgba,
        "the lights move between frames"
    );
}
