//! USD stages (`.usda`, `.usdc`, `.usdz`) read into a scene description,
//! beside the TOML reader: the same [`SceneDescription`], so a stage
//! renders exactly as the scene file saying the same things would.
//!
//! The stage is opened and composed by the `openusd` crate (a native
//! reader: sublayers, references, payloads, inherits, specializes,
//! variants, instancing). Any composition error (a cyclic arc, a layer that
//! cannot be read or found) fails the read with the error, naming the prim
//! and the layer. What cirrus renders:
//!
//! - `Volume` prims and their `OpenVDBAsset` fields (`volume.rs`), each
//!   with its world transform (composed through its parents, instance
//!   proxies included: each instance of a prototype is its own volume) and
//!   bound material (`material.rs`);
//! - every `DistantLight`, `DomeLight`, `SphereLight`, `RectLight`,
//!   `DiskLight` and `CylinderLight` (`lights.rs`);
//! - the camera the `RenderSettings` name, else the first `Camera`, and the
//!   settings' resolution (`camera.rs`);
//! - time: the stage's `startTimeCode`-`endTimeCode` become the frames
//!   rendered (frames are time codes), and time-sampled transforms and
//!   `filePath`s become samples the renderer reads at each frame and over
//!   the camera's shutter (`shutter:open`, `shutter:close`).
//!
//! Every other prim (meshes, other lights, ...) is listed once in a
//! warning with its path and type: never fatal, never silently dropped.
//! VDBs and sky maps packaged inside a `.usdz` are copied out to the
//! temporary directory once (`package.rs`). The `openusd` reader is guarded: a stage is read first in a child
//! process (`isolate.rs`), so one that crashes or hangs it is an error
//! naming the file, and a panic inside it becomes an error too.

mod camera;
mod isolate;
mod lights;
pub mod material;
mod package;
mod values;
mod volume;
mod xform;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use openusd::usd::{PrimPredicate, Stage};

use cirrus_render::compositing::DEFAULT_LIGHT_GROUPS;

use crate::description::{EnvironmentSpec, SceneDescription, SunSpec};
use crate::error::{Error, Result};

/// A stage read into a description, with what the reader could not render.
pub struct StageScene {
    pub description: SceneDescription,
    pub warnings: Vec<String>,
}

/// Whether `path` names a USD file (by its extension).
pub fn is_usd(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| {
        matches!(
            e.to_ascii_lowercase().as_str(),
            "usd" | "usda" | "usdc" | "usdz"
        )
    })
}

/// The stage's clock.
pub struct Time {
    pub start: f64,
    pub end: f64,
    pub frames_per_second: f64,
    pub authored_range: bool,
}

/// A stage being read: what the readers of each prim type share.
pub struct Reader {
    pub stage: Stage,
    /// The stage file, as errors name it.
    pub file: String,
    pub time: Time,
    warnings: Vec<String>,
}

impl Reader {
    pub fn warn(&mut self, message: String) {
        if !self.warnings.contains(&message) {
            self.warnings.push(message);
        }
    }

    /// An input error naming the stage file and the prim.
    pub fn error(&self, prim: &str, what: impl std::fmt::Display) -> Error {
        values::prim_error(&self.file, prim, what)
    }
}

/// Reads the stage at `path`; see the module doc.
pub fn read(path: &Path) -> Result<StageScene> {
    let file = path.display().to_string();
    std::fs::metadata(path).map_err(|e| Error::file(format!("{file}: {e}")))?;
    let text = path
        .to_str()
        .ok_or_else(|| Error::file(format!("{file}: the path is not UTF-8")))?;
    // First in a child process (`isolate.rs`): a file that crashes or hangs
    // the reader fails here, naming it.
    isolate::trial(|| {
        read_guarded(text, &file)
            .map(drop)
            .map_err(|e| e.to_string())
    })
    .map_err(|why| Error::input(format!("{file}: {why}")))?;
    match catch_unwind(AssertUnwindSafe(|| read_guarded(text, &file))) {
        Ok(result) => result,
        Err(panic) => {
            let why = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown failure".into());
            Err(Error::input(format!(
                "{file}: the USD reader failed: {why}"
            )))
        }
    }
}

fn read_guarded(text: &str, file: &str) -> Result<StageScene> {
    let stage = Stage::open(text).map_err(|e| {
        let e = format!("{e:#}");
        // openusd 0.6's text parser takes no asset values in timeSamples.
        let hint = match e.contains("AssetRef") {
            true => " (time-sampled asset paths, such as a per-frame filePath, are read from .usdc layers, not .usda)",
            false => "",
        };
        Error::input(format!("{file}: {e}{hint}"))
    })?;
    let time = Time {
        start: stage.start_time_code(),
        end: stage.end_time_code(),
        frames_per_second: stage.frames_per_second(),
        authored_range: stage.has_authored_time_code_range(),
    };
    if !(time.start.is_finite() && time.end.is_finite() && time.end >= time.start) {
        return Err(Error::input(format!(
            "{file}: time codes {}-{}: expected finite start <= end",
            time.start, time.end
        )));
    }
    if !(time.frames_per_second.is_finite() && time.frames_per_second > 0.0) {
        return Err(Error::input(format!("{file}: framesPerSecond must be > 0")));
    }
    let mut reader = Reader {
        stage,
        file: file.to_string(),
        time,
        warnings: Vec::new(),
    };
    let prims = traverse(&reader).map_err(|e| in_stage(e, file))?;
    composition_errors(&reader)?;
    let description = describe(&mut reader, &prims).map_err(|e| in_stage(e, file))?;
    composition_errors(&reader)?;
    Ok(StageScene {
        description,
        warnings: reader.warnings,
    })
}

/// `e` with its message naming the stage file first, where the message
/// (from a value read off a prim) names only the prim.
fn in_stage(e: Error, file: &str) -> Error {
    let named = |message: String| match message.starts_with(file) {
        true => message,
        false => format!("{file}: {message}"),
    };
    match e {
        Error::Input { message, source } => Error::Input {
            message: named(message),
            source,
        },
        Error::File { message, source } => Error::File {
            message: named(message),
            source,
        },
        other => other,
    }
}

/// Every visible prim of the default traversal (instance proxies
/// included) with its type: a prim whose `visibility`, or an ancestor's,
/// is `invisible` at the stage's start is not rendered (UsdGeomImageable's
/// rule, which UsdLux lights and UsdVol volumes follow).
fn traverse(r: &Reader) -> Result<Vec<(String, String)>> {
    let mut paths = Vec::new();
    r.stage
        .traverse(PrimPredicate::DEFAULT_PROXIES, |p| {
            paths.push(p.as_str().to_string())
        })
        .map_err(|e| Error::input(format!("{}: {e:#}", r.file)))?;
    let mut hidden: Vec<String> = Vec::new();
    let mut visible = Vec::new();
    for p in paths {
        // The traversal is depth-first, parents first: a hidden parent is
        // met before its children.
        if hidden.iter().any(|h| p.starts_with(&format!("{h}/"))) {
            continue;
        }
        let prim = r.stage.prim(p.as_str());
        let visibility = values::attr_text(&prim, "visibility", r.time.start)?;
        if visibility.as_deref() == Some("invisible") {
            hidden.push(p);
            continue;
        }
        visible.push((p.clone(), values::type_name(&r.stage, &p)?));
    }
    Ok(visible)
}

/// Fails on the stage's composition errors, listing them.
fn composition_errors(r: &Reader) -> Result<()> {
    let errors = r.stage.composition_errors();
    if errors.is_empty() {
        return Ok(());
    }
    let listed: Vec<String> = errors.iter().map(|e| e.to_string()).collect();
    Err(Error::input(format!("{}: {}", r.file, listed.join("; "))))
}

/// Prim types that only organise or feed what cirrus reads.
const STRUCTURAL: [&str; 10] = [
    "",
    "Xform",
    "Scope",
    "Material",
    "Shader",
    "NodeGraph",
    "OpenVDBAsset",
    "RenderProduct",
    "RenderVar",
    "GeomSubset",
];

fn describe(r: &mut Reader, prims: &[(String, String)]) -> Result<SceneDescription> {
    let of = |kind: &[&str]| -> Vec<String> {
        prims
            .iter()
            .filter(|(_, t)| kind.contains(&t.as_str()))
            .map(|(p, _)| p.clone())
            .collect()
    };
    let unsupported: Vec<String> = prims
        .iter()
        .filter(|(_, t)| {
            !STRUCTURAL.contains(&t.as_str())
                && ![
                    "Volume",
                    "DistantLight",
                    "DomeLight",
                    "DomeLight_1",
                    "SphereLight",
                    "RectLight",
                    "DiskLight",
                    "CylinderLight",
                    "Camera",
                    "RenderSettings",
                ]
                .contains(&t.as_str())
        })
        .map(|(p, t)| format!("{p} ({t})"))
        .collect();
    if !unsupported.is_empty() {
        r.warn(format!(
            "{}: not rendered (cirrus renders volumes, distant, dome, sphere, rect, disk and cylinder lights and a camera): {}",
            r.file,
            unsupported.join(", ")
        ));
    }
    let mut desc = SceneDescription::default();
    for path in of(&["Volume"]) {
        desc.volumes.push(volume::read(r, &path)?);
    }
    if desc.volumes.is_empty() {
        return Err(Error::input(format!(
            "{}: the stage has no Volume prim to render",
            r.file
        )));
    }
    lights(
        r,
        &of(&["DistantLight"]),
        &of(&["DomeLight", "DomeLight_1"]),
        &of(&["SphereLight"]),
        &[
            of(&["RectLight"]),
            of(&["DiskLight"]),
            of(&["CylinderLight"]),
        ],
        &mut desc,
    )?;
    view(r, &of(&["Camera"]), &of(&["RenderSettings"]), &mut desc)?;
    if r.time.authored_range {
        let (first, last) = (r.time.start.ceil(), r.time.end.floor());
        if last >= first {
            desc.render.frames = Some(format!("{}-{}", first as i64, last as i64));
        }
    }
    desc.render.frame = Some(r.time.start);
    Ok(desc)
}

/// The first distant light is the sun, the first dome the sky; a stage
/// without one has none (no default sun or sky is added).
/// The first distant light as the sun and the first dome as the sky (none
/// where the stage has none), every other light as a `[[light]]` named
/// by its prim; where their names would make more light-group layers than
/// the film keeps, they share their kinds' layers instead.
fn lights(
    r: &mut Reader,
    suns: &[String],
    domes: &[String],
    spheres: &[String],
    [rects, disks, cylinders]: &[Vec<String>; 3],
    desc: &mut SceneDescription,
) -> Result<()> {
    // The first distant and dome lights are the sun and sky, unless they
    // change over time: then they are keyed `[[light]]`s in those layers.
    let start = r.time.start;
    let moves = |r: &Reader, p: &String| lights::change_times(r, p).map(|t| t.len() >= 2);
    let sun = suns
        .first()
        .map(|p| Ok::<_, Error>((p, moves(r, p)?)))
        .transpose()?;
    desc.sun = Some(match sun {
        Some((p, false)) => lights::distant(r, p, start)?,
        _ => SunSpec {
            sun: Some(false),
            ..Default::default()
        },
    });
    let sky = domes
        .first()
        .map(|p| Ok::<_, Error>((p, moves(r, p)?)))
        .transpose()?;
    desc.environment = Some(match sky {
        Some((p, false)) => lights::dome(r, p, start)?,
        _ => EnvironmentSpec {
            env_radiance: Some([0.0; 3]),
            ..Default::default()
        },
    });
    let name = |path: &str| path.rsplit('/').next().unwrap_or(path).to_string();
    if let Some((p, true)) = sun {
        let mut l = lights::keyed(r, p, |r, t| lights::extra_distant(r, p, &name(p), t))?;
        l.group = Some(DEFAULT_LIGHT_GROUPS[0].into());
        desc.lights.push(l);
    }
    if let Some((p, true)) = sky {
        let mut l = lights::keyed(r, p, |r, t| lights::extra_dome(r, p, &name(p), t))?;
        l.group = Some(DEFAULT_LIGHT_GROUPS[1].into());
        desc.lights.push(l);
    }
    for p in suns.iter().skip(1) {
        desc.lights.push(lights::keyed(r, p, |r, t| {
            lights::extra_distant(r, p, &name(p), t)
        })?);
    }
    for p in domes.iter().skip(1) {
        desc.lights.push(lights::keyed(r, p, |r, t| {
            lights::extra_dome(r, p, &name(p), t)
        })?);
    }
    for p in spheres {
        desc.lights.push(lights::keyed(r, p, |r, t| {
            lights::sphere(r, p, &name(p), t)
        })?);
    }
    for (kind, paths) in [("rect", rects), ("disk", disks)] {
        for p in paths {
            desc.lights.push(lights::keyed(r, p, |r, t| {
                lights::area(r, p, &name(p), kind, t)
            })?);
        }
    }
    for p in cylinders {
        desc.lights.push(lights::keyed(r, p, |r, t| {
            lights::cylinder(r, p, &name(p), t)
        })?);
    }
    if crate::lights::light_group_names(desc).is_err() {
        r.warn(format!(
            "{}: {} lights are more light-group layers than the film keeps: they share `sun`, `sky` and `lights`",
            r.file,
            desc.lights.len()
        ));
        for l in &mut desc.lights {
            l.group = Some(
                match l.kind.as_str() {
                    "distant" => "sun",
                    "dome" => "sky",
                    _ => "lights",
                }
                .into(),
            );
        }
    }
    if desc.lights.is_empty() && suns.is_empty() && domes.is_empty() {
        r.warn(format!(
            "{}: the stage has no DistantLight, DomeLight, SphereLight, RectLight, DiskLight or CylinderLight: the volumes are unlit",
            r.file
        ));
    }
    Ok(())
}

/// The camera and resolution.
fn view(
    r: &mut Reader,
    cameras: &[String],
    settings: &[String],
    desc: &mut SceneDescription,
) -> Result<()> {
    let settings = match settings.first() {
        Some(p) => Some(camera::render_settings(r, p)?),
        None => None,
    };
    let chosen = settings
        .as_ref()
        .and_then(|s| s.camera.clone())
        .or_else(|| cameras.first().cloned());
    if let Some(path) = chosen {
        if cameras.len() > 1 {
            r.warn(format!(
                "{}: rendering through {path}; other cameras: {}",
                r.file,
                cameras.len() - 1
            ));
        }
        let (spec, shutter) = camera::camera(r, &path)?;
        desc.camera = spec;
        desc.render.shutter = shutter;
    } else {
        r.warn(format!(
            "{}: the stage has no Camera: the volumes are framed",
            r.file
        ));
    }
    desc.camera.res = settings.and_then(|s| s.res);
    Ok(())
}
