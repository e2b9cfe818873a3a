//! Seeded fuzzing of light input: `[[light]]` tables, the `[sun]` and
//! `[environment]` shorthands, and UsdLux stages, each with values drawn
//! from the edges of f32 and f64 (zeros of either sign, subnormals, 1e19
//! to 1e300, infinities, NaN), arrays of the wrong length and names
//! outside Latin-1, and keys over time (frames between keys, open
//! shutters, USD time samples). Every case must end in a clean error naming the file,
//! or a render whose pixels are all finite and that dropped no sample to
//! NaN or infinity: never a panic, a hang or a silent black image.
//!
//! Budgets, set here rather than timed: each render's walks take at most
//! `SEGMENTS_PER_WALK` majorant segments on average, and the whole test
//! runs on a thread that must end within `TIME_BUDGET`.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use cirrus_scene::{Overrides, Scene};
use cirrus_testkit::SplitMix64;

const SEGMENTS_PER_WALK: u64 = 500;
const TIME_BUDGET: Duration = Duration::from_secs(900);

/// Numbers at the edges of what a light's keys take.
const EDGES: [&str; 22] = [
    "0.0", "-0.0", "1.0", "-1.0", "0.5", "2.0", "1e-45", "1e-30", "1e-7", "1e7", "1e12", "1e19",
    "1e20", "1e30", "1e38", "3.4e38", "1e300", "inf", "-inf", "nan", "180.0", "128.0",
];

const KINDS: [&str; 8] = [
    "distant", "sphere", "point", "spot", "rect", "disk", "cylinder", "dome",
];

const NAMES: [&str; 5] = ["ランプ", "key", "fill light", "x.y", "émission"];

fn cloud() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/cloud.vdb")
}

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("light_fuzz")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn pick<'a>(rng: &mut SplitMix64, from: &[&'a str]) -> &'a str {
    from[rng.below(from.len())]
}

/// The keys a kind takes besides the strength and the name.
fn takes(kind: &str) -> &'static [&'static str] {
    match kind {
        "distant" => &["direction", "angle"],
        "sphere" => &["position", "radius", "normalize", "soft_falloff"],
        "point" => &["position"],
        "spot" => &[
            "position",
            "direction",
            "radius",
            "normalize",
            "cone_angle",
            "cone_softness",
            "soft_falloff",
        ],
        "rect" => &["position", "direction", "width", "height", "normalize"],
        "disk" => &["position", "direction", "radius", "normalize"],
        "cylinder" => &["position", "direction", "radius", "length", "normalize"],
        _ => &[],
    }
}

/// A number: mostly ordinary, now and then an edge.
fn number(rng: &mut SplitMix64, ordinary: &str) -> String {
    if rng.below(8) == 0 {
        pick(rng, &EDGES).to_string()
    } else {
        ordinary.to_string()
    }
}

/// A 3-vector, sometimes of the wrong length.
fn vector(rng: &mut SplitMix64, ordinary: [&str; 3]) -> String {
    let n = match rng.below(12) {
        0 => 2,
        1 => 4,
        _ => 3,
    };
    let v: Vec<String> = (0..n).map(|i| number(rng, ordinary[i.min(2)])).collect();
    format!("[{}]", v.join(", "))
}

/// One `[[light]]` table of a random kind with a random choice of keys.
fn light_table(rng: &mut SplitMix64) -> String {
    let kind = pick(rng, &KINDS);
    let mut lines = vec![
        format!("position = {}", vector(rng, ["0", "300", "0"])),
        format!("direction = {}", vector(rng, ["0", "-1", "0"])),
        format!("intensity = {}", number(rng, "1000")),
        format!("exposure = {}", number(rng, "1")),
        format!("color = {}", vector(rng, ["1", "0.9", "0.8"])),
        format!("radius = {}", number(rng, "10")),
        format!("normalize = {}", rng.below(2) == 0),
        format!("soft_falloff = {}", rng.below(2) == 0),
        format!("name = \"{}\"", pick(rng, &NAMES)),
    ];
    match kind {
        "spot" => {
            lines.push(format!("cone_angle = {}", number(rng, "30")));
            lines.push(format!("cone_softness = {}", number(rng, "0.2")));
        }
        "rect" | "disk" => {
            lines.push(format!("width = {}", number(rng, "50")));
            lines.push(format!("height = {}", number(rng, "50")));
        }
        "cylinder" => lines.push(format!("length = {}", number(rng, "50"))),
        "distant" => lines.push(format!("angle = {}", number(rng, "0.53"))),
        _ => {}
    }
    let mut t = format!("[[light]]\ntype = \"{kind}\"\n");
    for line in lines {
        let key = line.split(' ').next().unwrap_or_default();
        let applies =
            takes(kind).contains(&key) || ["intensity", "exposure", "color", "name"].contains(&key);
        // Most keys that apply given, some left to their defaults (or
        // missing); now and then one that does not apply.
        let given = if applies {
            rng.below(5) != 0
        } else {
            rng.below(20) == 0
        };
        if given {
            t += &line;
            t.push('\n');
        }
    }
    if rng.below(3) == 0 {
        t += &light_keys(rng);
    }
    t
}

/// A light's `keys`: two or three, at times sometimes out of order or not
/// finite, each with a few values (now and then one its kind does not take).
fn light_keys(rng: &mut SplitMix64) -> String {
    let keys: Vec<String> = (0..2 + rng.below(2))
        .map(|k| {
            let time = number(rng, &k.to_string());
            let mut values = vec![format!("time = {time}")];
            let choices = [
                format!("position = {}", vector(rng, ["0", "300", "0"])),
                format!("direction = {}", vector(rng, ["0", "-1", "0"])),
                format!("intensity = {}", number(rng, "1000")),
                format!("color = {}", vector(rng, ["1", "0.9", "0.8"])),
                format!("radius = {}", number(rng, "10")),
                format!("cone_angle = {}", number(rng, "30")),
            ];
            for c in choices {
                if rng.below(3) == 0 {
                    values.push(c);
                }
            }
            format!("{{ {} }}", values.join(", "))
        })
        .collect();
    format!("keys = [{}]\n", keys.join(", "))
}

/// A scene file: a cloud and some lights, or the shorthand tables.
fn scene_text(rng: &mut SplitMix64) -> String {
    let mut text = format!("[[volume]]\nfile = {:?}\n", cloud());
    if rng.below(3) == 0 {
        text += &format!(
            "[sun]\ndirection = {}\nirradiance = {}\nangle = {}\n[environment]\nradiance = {}\nrotation = {}\n",
            vector(rng, ["0", "-1", "0"]),
            vector(rng, ["2", "2", "2"]),
            number(rng, "0.53"),
            vector(rng, ["0.2", "0.2", "0.3"]),
            number(rng, "0"),
        );
    } else {
        for _ in 0..1 + rng.below(3) {
            text += &light_table(rng);
        }
    }
    // Keyed lights read at a frame between keys, or blurred over a shutter.
    match rng.below(4) {
        0 => text += &format!("[render]\nframe = {}\n", number(rng, "0.5")),
        1 => text += &format!("[render]\nshutter = [0, {}]\n", number(rng, "1")),
        _ => {}
    }
    text
}

/// One UsdLux light prim under an Xform that is sometimes invisible.
fn usd_light(rng: &mut SplitMix64, i: usize) -> String {
    let kinds = [
        "DistantLight",
        "DomeLight",
        "SphereLight",
        "RectLight",
        "DiskLight",
        "CylinderLight",
    ];
    let kind = pick(rng, &kinds);
    let name = if rng.below(4) == 0 { "ランプ" } else { "L" };
    let mut attrs = vec![
        format!("float inputs:intensity = {}", usd_number(rng, "1000")),
        format!("float inputs:exposure = {}", usd_number(rng, "0")),
        format!(
            "color3f inputs:color = ({}, {}, {})",
            usd_number(rng, "1"),
            usd_number(rng, "1"),
            usd_number(rng, "1")
        ),
        format!(
            "double3 xformOp:translate = ({}, {}, 0)",
            usd_number(rng, "0"),
            usd_number(rng, "300")
        ),
        format!(
            "double3 xformOp:scale = ({0}, {0}, {0})",
            usd_number(rng, "1")
        ),
        "uniform token[] xformOpOrder = [\"xformOp:translate\", \"xformOp:scale\"]".into(),
    ];
    if rng.below(2) == 0 {
        attrs.push(format!("float inputs:radius = {}", usd_number(rng, "10")));
    }
    if rng.below(3) == 0 {
        attrs.push(format!("bool inputs:normalize = {}", rng.below(2) == 0));
    }
    if kind == "SphereLight" && rng.below(2) == 0 {
        attrs.push(format!(
            "float inputs:shaping:cone:angle = {}",
            usd_number(rng, "30")
        ));
    }
    // Time-sampled: a moving, brightening light (keyed light).
    if rng.below(3) == 0 {
        attrs[3] = format!(
            "double3 xformOp:translate.timeSamples = {{ 1: (0, 300, 0), {}: ({}, 300, 0) }}",
            usd_number(rng, "3"),
            usd_number(rng, "50")
        );
        attrs[0] = format!(
            "float inputs:intensity.timeSamples = {{ 1: 1000, 2: {} }}",
            usd_number(rng, "2000")
        );
    }
    // Doubles as USD writes them: some finite in f64 and not in f32.
    if rng.below(3) == 0 {
        attrs[0] = format!("double inputs:intensity = {}", usd_number(rng, "1e300"));
    }
    let visibility = match rng.below(5) {
        0 => "token visibility = \"invisible\"\n",
        _ => "",
    };
    format!(
        "def Xform \"G{i}\"\n{{\n{visibility}def {kind} \"{name}\"\n{{\n{}\n}}\n}}\n",
        attrs.join("\n")
    )
}

fn usd_number(rng: &mut SplitMix64, ordinary: &str) -> String {
    let n = number(rng, ordinary);
    match n.as_str() {
        "inf" => "inf".into(),
        "-inf" => "-inf".into(),
        "nan" => "nan".into(),
        _ => n,
    }
}

fn stage_text(rng: &mut SplitMix64) -> String {
    let mut text = String::from(
        "#usda 1.0\n(\n    startTimeCode = 1\n    endTimeCode = 1\n)\n\n\
         def Volume \"Cloud\"\n{\n    rel field:density = </Cloud/density>\n\
         def OpenVDBAsset \"density\"\n    {\n        asset filePath = @./cloud.vdb@\n\
         token fieldName = \"density\"\n    }\n}\n",
    );
    for i in 0..1 + rng.below(3) {
        text += &usd_light(rng, i);
    }
    text
}

/// What one case came to.
#[derive(Default, Debug)]
struct Tally {
    cases: u32,
    errors: u32,
    renders: u32,
    black: u32,
}

/// Loads and renders `path` (8x8, 1 spp), checking what it gives.
fn run_case(path: &Path, tally: &mut Tally) {
    tally.cases += 1;
    let name = path.file_name().unwrap().to_string_lossy().to_string();
    let scene = Scene::load(path).and_then(|mut scene| {
        scene.apply(&Overrides {
            res: Some((8, 8)),
            spp: Some(1),
            ..Default::default()
        });
        scene.render()
    });
    match scene {
        Err(e) => {
            let text = e.to_string();
            assert!(!text.is_empty());
            // Errors found at load name the file; those found when the
            // settings resolve name the table and key (the shorthand
            // tables) or what failed (every sample dropped).
            let named = ["[sun]", "[environment]", "light group", "samples"];
            assert!(
                text.contains(&name) || named.iter().any(|n| text.contains(n)),
                "{name}: {text}"
            );
            tally.errors += 1;
        }
        Ok(r) => {
            let c = &r.stats.counters;
            assert!(
                r.image.rgba.iter().flatten().all(|v| v.is_finite()),
                "{name}: a non-finite pixel"
            );
            assert_eq!(c.nonfinite_samples, 0, "{name}: dropped samples");
            let walks = (c.paths + c.shadow_rays + c.real_collisions).max(1);
            assert!(
                c.dda_segments <= SEGMENTS_PER_WALK * walks,
                "{name}: {} segments over {walks} walks",
                c.dda_segments
            );
            tally.renders += 1;
            let black = r.image.rgba.iter().all(|p| p[..3] == [0.0; 3]);
            tally.black += black as u32;
        }
    }
}

fn within_budget(body: impl FnOnce() + Send + 'static) {
    let (done, wait) = mpsc::channel();
    let worker = std::thread::spawn(move || {
        body();
        let _ = done.send(());
    });
    match wait.recv_timeout(TIME_BUDGET) {
        Ok(()) => worker.join().unwrap(),
        Err(mpsc::RecvTimeoutError::Disconnected) => {
            std::panic::resume_unwind(worker.join().unwrap_err())
        }
        Err(mpsc::RecvTimeoutError::Timeout) => panic!("a case did not end within the budget"),
    }
}

#[test]
fn mutated_light_tables_error_cleanly_or_render_finite_images() {
    within_budget(|| {
        let d = dir("toml");
        let mut rng = SplitMix64(50);
        let mut tally = Tally::default();
        for k in 0..300 {
            let p = d.join(format!("case{k}.toml"));
            std::fs::write(&p, scene_text(&mut rng)).unwrap();
            run_case(&p, &mut tally);
        }
        eprintln!("light tables: {tally:?}");
        // Both outcomes are exercised.
        assert!(tally.errors > 30 && tally.renders > 30, "{tally:?}");
    });
}

#[test]
fn mutated_usdlux_stages_error_cleanly_or_render_finite_images() {
    within_budget(|| {
        let d = dir("usd");
        std::fs::copy(cloud(), d.join("cloud.vdb")).unwrap();
        let mut rng = SplitMix64(51);
        let mut tally = Tally::default();
        for k in 0..150 {
            let p = d.join(format!("stage{k}.usda"));
            std::fs::write(&p, stage_text(&mut rng)).unwrap();
            run_case(&p, &mut tally);
        }
        eprintln!("UsdLux stages: {tally:?}");
        assert!(tally.errors > 15 && tally.renders > 15, "{tally:?}");
    });
}

/// `n` lights of the kinds a light tree holds (points, balls, spots,
/// rects, discs), as `[[light]]` tables: spread over and around the
/// cloud, or all at one place (`stacked`: a tree whose clusters have no
/// extent), their intensities ordinary or from 1e-30 to 1e27 and zero
/// (`extreme`: the largest a light takes, whose importances overflow f32).
fn many_lights(rng: &mut SplitMix64, n: usize, stacked: bool, extreme: bool) -> String {
    let mut text = format!("[[volume]]\nfile = {:?}\n", cloud());
    let kinds = ["point", "sphere", "spot", "rect", "disk"];
    for _ in 0..n {
        let kind = pick(rng, &kinds);
        let p = if stacked {
            [150.0, 80.0, 100.0]
        } else {
            [0, 1, 2].map(|_| rng.unit() * 400.0 - 50.0)
        };
        let intensity = if extreme {
            pick(rng, &["0.0", "1e-30", "1e-7", "1.0", "1e12", "1e27"]).to_string()
        } else {
            format!("{}", 100.0 + 1000.0 * rng.unit())
        };
        text += &format!(
            "[[light]]\ntype = \"{kind}\"\nposition = [{}, {}, {}]\nintensity = {intensity}\n",
            p[0], p[1], p[2]
        );
        match kind {
            "sphere" => text += "radius = 2\n",
            "spot" => text += "direction = [0.3, -1, 0.2]\ncone_angle = 30\n",
            "rect" | "disk" => {
                let d = [0, 1, 2].map(|_| rng.unit() * 2.0 - 1.0);
                let size = if kind == "rect" {
                    "width = 20\nheight = 10"
                } else {
                    "radius = 5"
                };
                text += &format!("direction = [{}, {}, {}]\n{size}\n", d[0], d[1], d[2]);
            }
            _ => {}
        }
    }
    text
}

/// Scenes of 9 to 10,000 lights, the sizes past the few-light pick that
/// a light tree picks among (balanced, stacked at one point, with
/// overflowing strengths), error cleanly or render finite images: never a
/// panic or a hang; the ordinary ones are not black.
#[test]
fn thousands_of_lights_render_finite_images() {
    within_budget(|| {
        let d = dir("many");
        let mut rng = SplitMix64(52);
        let mut tally = Tally::default();
        for n in [9, 33, 1000, 10_000] {
            for (stacked, extreme) in [(false, false), (true, false), (false, true)] {
                let p = d.join(format!("many{n}_{stacked}_{extreme}.toml"));
                std::fs::write(&p, many_lights(&mut rng, n, stacked, extreme)).unwrap();
                let black = tally.black;
                run_case(&p, &mut tally);
                if !stacked && !extreme {
                    assert_eq!(tally.black, black, "{n} lights: a black image");
                }
            }
        }
        eprintln!("many lights: {tally:?}");
        assert_eq!(tally.renders, 12, "{tally:?}");
    });
}
