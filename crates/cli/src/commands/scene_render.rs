//! `cirrus render SCENE.toml`: a scene file of any number of volumes.
//!
//! Steps: the file ([`SceneFile`]) and the command line are merged (a flag
//! given on the command line wins, told apart from clap's defaults by
//! `ArgMatches::value_source`); each volume's file is opened (its index
//! only) and its world box found from the grid header when the file says
//! (OpenVDB's `file_bbox_*` metadata), else by loading it; the camera is
//! placed; [`needed`] decides which volumes can matter; only those, and
//! only the grids the scene names, are read and converted; the instances
//! go into [`Volumes`] and render through `render_media`.
//!
//! Input paths in the file (volumes, sky map) are relative to the file;
//! output paths are relative to the working directory, like the flags.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use cirrus_bricks::{convert, read_cbrk, BrickVolume, Precision};
use cirrus_render::exr_layers::Aov;
use cirrus_render::medium::BrickField;
use cirrus_render::{render_media, Blackbody, Camera, Crop, DensityField, VolumeInstance, Volumes};
use cirrus_vdb::VolumeFile;
use clap::parser::ValueSource;
use clap::ArgMatches;
use glam::{DMat4, DVec3, Vec3};

use super::render::{lights, settings, write_outputs, Outputs, RenderArgs, SceneArgs};
use super::scene_cull::{in_frustum, needed, WorldBox};
use super::scene_file::{
    IntegratorName, MajorantName, ScaleSpec, SceneFile, TransmittanceName, VolumeSpec,
};
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

/// One volume's plan: where its grids are and how it is placed.
struct Plan {
    file: PathBuf,
    cbrk: bool,
    density: usize,
    temperature: Option<usize>,
    emission: Option<usize>,
    object_to_world: DMat4,
    world_box: Option<WorldBox>,
    density_scale: Option<f32>,
    albedo: Vec3,
    g: f32,
    blackbody: Blackbody,
    emission_colour: Vec3,
}

impl Plan {
    fn emits(&self) -> bool {
        self.temperature.is_some() || self.emission.is_some()
    }
}

fn object_to_world(v: &VolumeSpec) -> DMat4 {
    let t = &v.transform;
    let translate = DMat4::from_translation(DVec3::from_array(t.translate.unwrap_or([0.0; 3])));
    let rotate = match (&t.rotate, t.euler) {
        (Some(r), _) => {
            let axis = DVec3::from_array(r.axis).normalize_or(DVec3::Y);
            DMat4::from_axis_angle(axis, r.degrees.to_radians())
        }
        (None, Some([x, y, z])) => {
            DMat4::from_rotation_z(z.to_radians())
                * DMat4::from_rotation_y(y.to_radians())
                * DMat4::from_rotation_x(x.to_radians())
        }
        (None, None) => DMat4::IDENTITY,
    };
    let scale = match t.scale {
        None => DVec3::ONE,
        Some(ScaleSpec::Uniform(s)) => DVec3::splat(s),
        Some(ScaleSpec::Axes(a)) => DVec3::from_array(a),
    };
    translate * rotate * DMat4::from_scale(scale)
}

fn plan(
    v: &VolumeSpec,
    dir: &Path,
    scene: &SceneArgs,
    given: &dyn Fn(&str) -> bool,
    files: &mut Files,
) -> Result<Plan, String> {
    let path = dir.join(&v.file);
    let object_to_world = object_to_world(v);
    if !object_to_world.is_finite() || object_to_world.determinant().abs() < 1e-300 {
        return Err(format!("{}: the transform is singular", v.file.display()));
    }
    let density_name = if given("grid") {
        scene.grid.clone()
    } else {
        v.density.clone().or(scene.grid.clone())
    };
    let cbrk = path.extension().is_some_and(|e| e == "cbrk");
    let (density, temperature, emission, world_box) = if cbrk {
        if v.temperature.is_some() || v.emission.is_some() {
            return Err(format!(
                "{}: a .cbrk holds one density grid; temperature and emission need the .vdb",
                path.display()
            ));
        }
        (0, None, None, None)
    } else {
        let f = files.open(&path)?;
        let err = |e: Box<dyn std::error::Error>| e.to_string();
        let density = super::convert::choose_grid(f, density_name.as_deref()).map_err(err)?;
        let named = |n: &Option<String>| -> Result<Option<usize>, String> {
            n.as_ref()
                .map(|n| f.find_grid(n).map_err(|e| e.to_string()))
                .transpose()
        };
        let temperature = named(&v.temperature)?;
        let emission = named(&v.emission)?;
        let header = f.grid_bounds(density).map_err(|e| e.to_string())?;
        let world_box = header.map(|(t, lo, hi)| {
            // Trilinear support reaches one voxel past the active box.
            let lo = DVec3::from_array(lo.map(f64::from)) - 1.0;
            let hi = DVec3::from_array(hi.map(f64::from)) + 1.0;
            world_box_of(object_to_world * t.index_to_world_matrix(), lo, hi)
        });
        (density, temperature, emission, world_box)
    };
    let bb = &v.blackbody;
    Ok(Plan {
        file: path,
        cbrk,
        density,
        temperature,
        emission,
        object_to_world,
        world_box,
        density_scale: if given("density_scale") {
            scene.density_scale
        } else {
            v.density_scale.or(scene.density_scale)
        },
        albedo: match (v.albedo, given("albedo")) {
            (Some(a), false) => Vec3::from_array(a.rgb()),
            _ => Vec3::splat(scene.albedo),
        },
        g: match (v.g, given("g")) {
            (Some(g), false) => g,
            _ => scene.g,
        },
        blackbody: Blackbody {
            scale: bb.scale.unwrap_or(1.0),
            offset: bb.offset.unwrap_or(0.0),
            temperature_scale: bb.temperature_scale.unwrap_or(1.0),
        },
        emission_colour: Vec3::from_array(v.emission_color.unwrap_or([1.0; 3]))
            * v.emission_scale.unwrap_or(1.0),
    })
}

/// The world box of the local box `[lo, hi]` under `m`.
fn world_box_of(m: DMat4, lo: DVec3, hi: DVec3) -> WorldBox {
    let mut b = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for k in 0..8 {
        let c = DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        );
        let p = m.transform_point3(c);
        b = (b.0.min(p), b.1.max(p));
    }
    b
}

/// Open files and loaded grids, shared by the volumes that use them (two
/// instances of one file read it once), with what reading them cost.
#[derive(Default)]
struct Files {
    open: HashMap<PathBuf, VolumeFile>,
    grids: HashMap<(PathBuf, usize), BrickVolume>,
    cbrk_bytes: u64,
}

impl Files {
    fn open(&mut self, path: &Path) -> Result<&VolumeFile, String> {
        if !self.open.contains_key(path) {
            let f = VolumeFile::open(path).map_err(|e| e.to_string())?;
            self.open.insert(path.to_path_buf(), f);
        }
        Ok(&self.open[path])
    }

    /// Reads grid `index` of `path` once.
    fn grid(&mut self, path: &Path, cbrk: bool, index: usize) -> Result<&BrickVolume, String> {
        let key = (path.to_path_buf(), index);
        if !self.grids.contains_key(&key) {
            let volume = if cbrk {
                self.cbrk_bytes += std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
                read_cbrk(path).map_err(|e| e.to_string())?
            } else {
                let f = self.open(path)?;
                let g = f.read_grid(index).map_err(|e| e.to_string())?;
                convert(&g, Precision::F32).map_err(|e| format!("{}: {e}", path.display()))?
            };
            self.grids.insert(key.clone(), volume);
        }
        Ok(&self.grids[&key])
    }

    /// The world box of a plan's density grid, loading it.
    fn density_box(&mut self, p: &Plan) -> Result<WorldBox, String> {
        let v = self.grid(&p.file, p.cbrk, p.density)?;
        let m = p.object_to_world * v.local_from_world().inverse();
        Ok(world_box_of(m, DVec3::ZERO, v.local_extent().as_dvec3()))
    }

    fn load_grids(&mut self, p: &Plan) -> Result<(), String> {
        self.grid(&p.file, p.cbrk, p.density)?;
        for index in [p.temperature, p.emission].into_iter().flatten() {
            self.grid(&p.file, p.cbrk, index)?;
        }
        Ok(())
    }

    /// The instance of a plan whose grids are loaded, placed in render
    /// space (world minus `centre`).
    fn instance(&self, p: &Plan, centre: DVec3) -> Result<VolumeInstance<BrickField<'_>>, String> {
        let field = |index: usize| {
            let v = &self.grids[&(p.file.clone(), index)];
            BrickField::new(v, p.object_to_world, centre)
        };
        let density = field(p.density);
        let density_scale = p
            .density_scale
            .unwrap_or_else(|| 0.5 / density.voxel_size());
        if !(density_scale.is_finite() && density_scale >= 0.0) {
            return Err(format!(
                "{}: density scale must be finite and >= 0, got {density_scale}",
                p.file.display()
            ));
        }
        if !p.albedo.is_finite() || p.albedo.min_element() < 0.0 || p.albedo.max_element() > 1.0 {
            return Err(format!(
                "{}: albedo must lie in [0, 1], got {}",
                p.file.display(),
                p.albedo
            ));
        }
        let mut inst = VolumeInstance::new(density, density_scale, p.albedo, p.g);
        if p.emits() {
            inst.emission = Some(cirrus_render::Emission {
                temperature: p.temperature.map(|i| (field(i), p.blackbody)),
                grid: p.emission.map(|i| (field(i), p.emission_colour)),
            });
        }
        Ok(inst)
    }

    fn bytes_read(&self) -> u64 {
        self.open.values().map(|f| f.bytes_read()).sum::<u64>() + self.cbrk_bytes
    }

    fn grids_loaded(&self) -> u64 {
        self.grids.len() as u64
    }
}
