//! `cirrus render SCENE.toml`: a scene file of any number of volumes.
//!
//! Steps: the file ([`SceneFile`]) and the command line are merged (a flag
//! given on the command line wins, told apart from clap's defaults by
//! `ArgMatches::value_source`); each volume's file is opened (its index
//! only) and its world box found from the grid header when the file says
//! (OpenVDB's `file_bbox_*` metadata), else by loading it; the camera is
//! placed; [`needed`] decides which volumes can matter; only those, and
//! only the grids the scene names, are read and converted; the instances
//! go into [`Volumes`] and render through `render_media`. Planning and
//! loading are in `scene_load`, the rule of what to load in `scene_cull`.
//!
//! Input paths in the file (volumes, sky map) are relative to the file;
//! output paths are relative to the working directory, like the flags.

use std::path::{Path, PathBuf};
use std::time::Instant;

use cirrus_render::exr_layers::Aov;
use cirrus_render::{render_media, Camera, Crop, Volumes};
use clap::parser::ValueSource;
use clap::ArgMatches;
use glam::{DVec3, Vec3};

use super::render::{lights, settings, write_outputs, Outputs, RenderArgs, SceneArgs};
use super::scene_cull::{in_frustum, needed, WorldBox};
use super::scene_file::{IntegratorName, MajorantName, SceneFile, TransmittanceName};
use super::scene_load::{plan, Files};
use super::CliResult;

pub fn run(args: &RenderArgs, m: &ArgMatches) -> CliResult {
    let start = Instant::now();
    let path = &args.scene.file;
    let file = SceneFile::read(path)?;
    if file.volumes.is_empty() {
        return Err(format!("{}: no [[volume]] in the scene", path.display()).into());
    }
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let given = |id: &str| m.value_source(id) == Some(ValueSource::CommandLine);
    let scene = merged_args(&args.scene, &file, dir, &given)?;
    let out = merged_outputs(args, &file, &given)?;

    let lights = lights(&scene)?;
    let mut settings = settings(&scene)?;
    settings.aovs = !out.aovs.is_empty();
    settings.crop = out.crop;
    if let Some(c) = &out.crop {
        c.validate(scene.res.0, scene.res.1)?;
    }

    // Plan every volume: its files, grids, transform and world box.
    let mut files = Files::default();
    let plans = file
        .volumes
        .iter()
        .map(|v| plan(v, dir, &scene, &given, &mut files))
        .collect::<Result<Vec<_>, _>>()?;
    let boxes: Vec<WorldBox> = plans
        .iter()
        .map(|p| match p.world_box {
            Some(b) => Ok(b),
            None => files.density_box(p),
        })
        .collect::<Result<_, String>>()?;
    let union = boxes.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), b| (lo.min(b.0), hi.max(b.1)),
    );
    // Render space: world minus the scene's centre, in f64.
    let centre = 0.5 * (union.0 + union.1);
    let to_render = |p: DVec3| (p - centre).as_vec3();
    let render_box = |b: &WorldBox| (to_render(b.0), to_render(b.1));
    let (w, h) = scene.res;
    let camera = match (scene.camera_from, scene.camera_to) {
        (Some(from), Some(to)) => Camera::new(
            to_render(from),
            to_render(to),
            scene.camera_up,
            scene.fov,
            w,
            h,
        ),
        _ => Camera::framing(render_box(&union), w, h),
    };
    let window = out.crop.unwrap_or(Crop {
        x0: 0,
        y0: 0,
        x1: w,
        y1: h,
    });
    let visible: Vec<bool> = boxes
        .iter()
        .map(|b| in_frustum(&camera, window, render_box(b)))
        .collect();
    let any_emission = plans.iter().any(|p| p.emits());
    let keep = needed(&visible, &boxes, &lights, any_emission, settings.max_depth);

    // Read what is needed, then place it.
    for (p, _) in plans.iter().zip(&keep).filter(|(_, k)| **k) {
        files.load_grids(p)?;
    }
    let mut instances = Vec::new();
    for (p, _) in plans.iter().zip(&keep).filter(|(_, k)| **k) {
        instances.push(files.instance(p, centre)?);
    }
    let skipped = keep.iter().filter(|k| !**k).count();
    if skipped > 0 {
        eprintln!("{skipped} volume(s) neither the camera nor the lights can reach: not loaded");
    }
    let volumes = Volumes::new(instances);
    if volumes.instances().is_empty() {
        return Err("no volume is visible and none can light one: nothing to render".into());
    }
    let load_seconds = start.elapsed().as_secs_f64();
    let mut rendered = render_media(&volumes, &camera, &lights, &settings);
    rendered.stats.bytes_read = files.bytes_read();
    rendered.stats.grids_loaded = files.grids_loaded();
    let outputs = Outputs {
        exr: &out.exr,
        png: out.png.as_deref(),
        exposure: out.exposure,
        stats: out.stats.as_deref(),
        aovs: &out.aovs,
    };
    write_outputs(&rendered, &outputs, load_seconds)
}

/// The outputs after merging the file's `[output]` with the flags.
struct MergedOutputs {
    exr: PathBuf,
    png: Option<PathBuf>,
    exposure: f32,
    stats: Option<PathBuf>,
    aovs: Vec<Aov>,
    crop: Option<Crop>,
}

fn merged_outputs(
    args: &RenderArgs,
    file: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) -> Result<MergedOutputs, String> {
    let o = &file.output;
    let pick = |id: &str, flag: Option<PathBuf>, f: &Option<PathBuf>| {
        if given(id) {
            flag
        } else {
            f.clone().or(flag)
        }
    };
    let exr = pick("output", args.output.clone(), &o.exr)
        .ok_or("an output file is required: -o OUT.exr or [output] exr = \"...\"")?;
    let aovs = match (&o.aov, given("aov")) {
        (Some(names), false) => names
            .iter()
            .map(|n| Aov::parse(n).map_err(|e| format!("[output] aov: {e}")))
            .collect::<Result<_, _>>()?,
        _ => args.aov.clone(),
    };
    let crop = match (o.crop, given("crop")) {
        (Some([x0, y0, x1, y1]), false) => Some(Crop { x0, y0, x1, y1 }),
        _ => args.crop,
    };
    Ok(MergedOutputs {
        exr,
        png: pick("png", args.png.clone(), &o.png),
        exposure: match (o.exposure, given("exposure")) {
            (Some(e), false) => e,
            _ => args.exposure,
        },
        stats: pick("stats", args.stats.clone(), &o.stats),
        aovs,
        crop,
    })
}

/// The scene flags after applying the file where no flag was given.
fn merged_args(
    args: &SceneArgs,
    file: &SceneFile,
    dir: &Path,
    given: &dyn Fn(&str) -> bool,
) -> Result<SceneArgs, String> {
    let mut s = args.clone();
    fn set<T>(given: bool, slot: &mut T, value: Option<T>) {
        if let (false, Some(v)) = (given, value) {
            *slot = v;
        }
    }
    let v3 = |a: Option<[f32; 3]>| a.map(Vec3::from_array);
    let c = &file.camera;
    set(given("res"), &mut s.res, c.res);
    match (c.from, c.to) {
        (Some(f), Some(t)) if !given("camera_from") => {
            s.camera_from = Some(DVec3::from_array(f));
            s.camera_to = Some(DVec3::from_array(t));
        }
        (Some(_), None) | (None, Some(_)) => {
            return Err("[camera] needs both `from` and `to` (or neither)".into())
        }
        _ => {}
    }
    set(given("camera_up"), &mut s.camera_up, v3(c.up));
    set(given("fov"), &mut s.fov, c.fov);
    if let Some(sun) = &file.sun {
        set(given("no_sun"), &mut s.no_sun, sun.enabled.map(|e| !e));
        set(given("sun_dir"), &mut s.sun_dir, v3(sun.direction));
        set(
            given("sun_irradiance"),
            &mut s.sun_irradiance,
            v3(sun.irradiance),
        );
        set(given("sun_angle"), &mut s.sun_angle, sun.angle);
    }
    if let Some(env) = &file.environment {
        set(given("env_radiance"), &mut s.env_radiance, v3(env.radiance));
        if !given("env_map") {
            if let Some(map) = &env.map {
                s.env_map = Some(dir.join(map));
            }
        }
        set(given("env_rotation"), &mut s.env_rotation, env.rotation);
        set(given("env_intensity"), &mut s.env_intensity, env.intensity);
    }
    let r = &file.render;
    if !given("spp") && !given("time") {
        match (r.spp, r.time) {
            (Some(_), Some(_)) => return Err("[render] give `spp` or `time`, not both".into()),
            (spp, time) => {
                s.spp = spp.or(s.spp);
                s.time = time.or(s.time);
            }
        }
    }
    set(given("seed"), &mut s.seed, r.seed);
    let integrator = r.integrator.map(|i| match i {
        IntegratorName::Path => "path",
        IntegratorName::Raymarch => "raymarch",
        IntegratorName::Raymarch2pass => "raymarch2pass",
    });
    set(
        given("integrator"),
        &mut s.integrator,
        integrator.map(String::from),
    );
    let transmittance = r.transmittance.map(|t| match t {
        TransmittanceName::Ratio => "ratio",
        TransmittanceName::Residual => "residual",
        TransmittanceName::TrackLength => "track-length",
    });
    set(
        given("transmittance"),
        &mut s.transmittance,
        transmittance.map(String::from),
    );
    let majorant = r.majorant.map(|m| match m {
        MajorantName::Hierarchy => "hierarchy",
        MajorantName::Global => "global",
    });
    set(
        given("majorant"),
        &mut s.majorant,
        majorant.map(String::from),
    );
    set(given("max_depth"), &mut s.max_depth, r.max_depth.map(Some));
    set(given("step"), &mut s.step, r.step);
    Ok(s)
}
