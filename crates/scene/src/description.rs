//! Every setting, declared once ([`declare_settings!`](crate::declare)):
//! its table and key in a scene file, its flag, its type, its default, its
//! help and its Python keyword. From this one declaration come the scene
//! description (exactly the TOML format of a scene file, and the JSON form
//! the Python bindings pass for a dict), the [`Overrides`] written over it,
//! the command line's flags, the defaults and the README's table.
//!
//! Every setting is optional in a description; its getter applies the
//! declared default. Unknown keys and wrong types are errors that name the
//! file, the key, and its line and column (serde's `deny_unknown_fields`;
//! toml's errors carry the span).

use std::path::{Path, PathBuf};

use cirrus_render::exr_layers::Aov;
use cirrus_render::{
    DistanceSampling, IntegratorKind, LightSampling, MajorantMode, SamplerKind, Sunward,
    TransmittanceEstimator, VelocityUnit,
};

use crate::declare::declare_settings;
use crate::device::Device;
use crate::error::{Error, Result};
use crate::light_keys::LightKey;
#[cfg(feature = "clap")]
use crate::parse;
use crate::values::{check_samples, finite_matrix};
pub use crate::values::{
    AxisAngle, BlackbodySpec, Colour, FileSample, Matrix, MatrixSample, ScaleSpec, TransformSpec,
};

declare_settings! {
    /// `[output]`: where the image goes.
    table output: OutputSpec, OutputFlags, one {
    /// Output image, its format told by its extension: OpenEXR (`.exr`:
    /// RGBA f32, alpha = 1 - camera-ray transmittance, and the layers), or
    /// a PNG (`.png`, as `--png`); written whole or not at all.
    output as "exr": PathBuf, flag(short, long),
        unset("none: a library caller keeps the image"),
        example(PathBuf::from("a.exr"));
    /// Also write an sRGB PNG preview (given alone: a PNG-only render).
    png: PathBuf, flag(long), example(PathBuf::from("a.png"));
    /// Exposure of the PNG preview, in stops.
    exposure: f32, flag(long, allow_hyphen_values = true), default(0.0), example(1.5);
    /// Write render statistics as JSON.
    stats: PathBuf, flag(long), example(PathBuf::from("a.json"));
    /// AOV layers to add to the EXR: albedo, depth, emission, direct,
    /// samples.
    aov: Vec<Aov>, flag(long, value_delimiter = ',', value_enum),
        unset("none"), example(vec![Aov::Depth]);
    /// Render only the pixels [x0, x1) x [y0, y1) into a full-size EXR with
    /// a data window (merge tiles with `cirrus merge`).
    crop: [u32; 4], flag(long, value_parser = parse::crop),
        unset("the whole image"), example([0, 0, 4, 4]);
    /// Light-group layers (`sun`, `sky`, `emission`) beside the beauty,
    /// summing to it (also `--aov lights`).
    light_groups: bool, flag(long, num_args = 0, default_missing_value = "true"),
        default(false), example(true);
    /// Cryptomatte ID mattes: `CryptoObject` (per volume's name) and
    /// `CryptoAsset` (per volume file) layers (also `--aov cryptomatte`).
    cryptomatte: bool, flag(long, num_args = 0, default_missing_value = "true"),
        default(false), example(true);
    /// A deep scanline EXR (Z, ZBack, R, G, B, A) of the camera rays'
    /// volumetric samples (path tracer).
    deep: PathBuf, flag(long), unset("none"), example(PathBuf::from("deep.exr"));
    /// Deep samples per pixel at most, merged by optical depth (plus one
    /// for the background).
    deep_samples: u32, flag(long), default(cirrus_render::compositing::DEFAULT_DEEP_SAMPLES),
        example(4);
    }

    /// `[render]`: how to render.
    table render: RenderSpec, RenderFlags, one {
    /// Samples per pixel.
    spp: u32, flag(long, conflicts_with = "time"), default(cirrus_render::DEFAULT_SPP), example(3);
    /// Render passes until this many seconds are spent (instead of spp).
    time: f64, flag(long), unset("off"), example(0.5);
    /// Same seed, same image, on any thread count.
    seed: u64, flag(long), default(cirrus_render::DEFAULT_SEED), example(7);
    /// Sample numbers: Owen-scrambled Sobol points for the first path
    /// vertices, or independent random numbers.
    sampler: SamplerKind, flag(long, value_enum), default(SamplerKind::default()),
        example(SamplerKind::Random);
    /// Adaptive sampling: a pixel stops once the relative standard error
    /// of its mean is below this (e.g. 0.02); with --time, passes go to the
    /// pixels of highest error.
    noise_threshold: f32, flag(long), unset("off"), example(0.05);
    /// Samples every pixel takes before adaptive sampling may stop it.
    min_spp: u32, flag(long), default(cirrus_render::Adaptive::DEFAULT_MIN_SPP), example(4);
    /// The integrator: unbiased path tracing, or ray marching (single
    /// scattering; two-pass over a cached light grid).
    integrator: IntegratorKind, flag(long, value_enum), default(IntegratorKind::default()),
        example(IntegratorKind::RayMarch);
    /// Shadow-ray transmittance estimator.
    transmittance: TransmittanceEstimator, flag(long, value_enum),
        default(TransmittanceEstimator::default()), example(TransmittanceEstimator::Ratio);
    /// Majorants for tracking: the brick hierarchy, one global majorant
    /// (Mitsuba-like), or whichever a probe of the scene finds cheaper.
    majorant: MajorantMode, flag(long, value_enum), default(MajorantMode::default()),
        example(MajorantMode::Global);
    /// Next-event estimation at each scattering vertex: a shadow ray to
    /// one light picked by its in-scattered light there seen through the
    /// media (a coarse shadow grid; half the shadow rays under a sun and a
    /// sky, and few deep in a thick cloud), or to every light; `auto` picks
    /// one under constant domes (a constant sky), every light under a map,
    /// and one past 8 lights, picked by a light tree
    /// (`uniform`: one picked uniformly, the baseline).
    light_sampling: LightSampling, flag(long, value_enum), default(LightSampling::default()),
        example(LightSampling::All);
    /// Sunward scattering: at each scattering vertex, also scatter toward
    /// the sun (the brightest distant light) and gather its light at the
    /// next vertex, weighed against
    /// the path's own next vertex (unbiased; about twice the shadow rays
    /// of the vertices it runs at, for much less noise under a
    /// forward-scattering phase function); `auto` runs it where the phase
    /// function's mean cosine is at least 0.6, where it was measured to
    /// pay.
    sunward: Sunward, flag(long, value_enum), default(Sunward::default()), example(Sunward::Off);
    /// Where the render runs: cpu; auto (a hardware GPU where there is
    /// one, else the CPU; a scene the GPU does not render goes to the CPU,
    /// saying why); gpu (any Vulkan adapter, lavapipe included; an error
    /// naming what the GPU does not render). The GPU renders the path
    /// tracer over one volume lit by suns, a constant sky, sphere, point,
    /// spot and area lights (README, "On a GPU").
    device: Device, flag(long, value_enum), default(Device::Cpu), example(Device::Auto);
    /// Where light scatters along a ray: free flights and equi-angular
    /// sampling toward sphere, point and spot lights weighed by MIS (what
    /// makes a beam in fog converge), or free flights alone; `auto`
    /// samples equi-angularly where the media are thin (under 3 mean free
    /// paths across at their densest).
    distance_sampling: DistanceSampling, flag(long, value_enum),
        default(DistanceSampling::default()), example(DistanceSampling::FreeFlight);
    /// Real scattering events per path (0: only the sky through the volume,
    /// 1: single scattering).
    max_depth: u32, flag(long), unset("unlimited, ended by Russian roulette"), example(1);
    /// Ray-march step in voxels.
    step: f32, flag(long), default(cirrus_render::DEFAULT_STEP_VOXELS), example(2.0);
    /// The ray marchers' shadow-ray step in voxels, as vdb_render's
    /// -shadowstep.
    shadow_step: f32, flag(long), unset("the step"), example(3.0);
    /// Majorant cells are refined while crossing one would cost more than
    /// this many extra null collisions (optical depth; Blender Cycles uses
    /// 1.442; 0 refines to the finest 4^3 cells).
    refine_optical_depth: f32, flag(long), default(1.0), example(0.0);
    /// Denoise with Intel Open Image Denoise 2.x (guided by the albedo
    /// AOV), blended with the noisy image by their estimated errors; the
    /// EXR keeps the noisy image as `noisy.R/G/B`, the plain denoised one
    /// as `denoised.R/G/B` and the blend's weights as `blend.weight`. A
    /// crop keeps the denoiser's inputs instead, and `cirrus merge`
    /// denoises the whole image.
    denoise: bool, flag(long, num_args = 0, default_missing_value = "true"),
        default(false), example(true);
    /// Motion blur: the shutter's open and close times in frames around
    /// the frame, e.g. -0.25,0.25 (centred) or 0,0.5.
    shutter: [f32; 2], flag(long, value_parser = parse::shutter, allow_hyphen_values = true),
        default(cirrus_render::Shutter::INSTANT.times()), example([-0.25, 0.25]);
    /// Frames A-B[:STEP]: the frame number replaces `####` or `%04d` in
    /// every input and output path.
    frames: String, flag(long), unset("one frame, no pattern"), example("1-2".into());
    /// A camera-space depth image (planar depth, as Blender's Z pass) of
    /// the same camera and size, FILE.exr[:CHANNEL] (in a scene file
    /// relative to the file): camera rays end there, so the cloud renders
    /// behind geometry it was never given.
    holdout_depth: String, flag(long), unset("none; channel: Z, or the one ending in .Z"),
        example("depth.exr".into());
    /// Holdout depths at or beyond this are no depth (Blender's
    /// background).
    holdout_far: f32, flag(long), default(cirrus_render::compositing::DEFAULT_FAR),
        example(5.0);
    @file_only {
        /// The frame a single render shows: where time-sampled values
        /// (`transform.samples`, `[camera] samples`, `file_samples`) are
        /// read. `--frames` sets it to each frame; default 0.
        frame: Option<f64>;
    }
    }

    /// `[camera]`: where the image is seen from.
    table camera: CameraSpec, CameraFlags, one {
    /// Image size, WxH.
    res: (u32, u32), serde(default, deserialize_with = "crate::parse::resolution_field"),
        flag(long, value_parser = parse::resolution), default((512, 512)), example((8, 6));
    /// Camera position (world space).
    camera_from as "from": [f64; 3], serde(default, deserialize_with = "crate::parse::triple_field"),
        flag(long, value_parser = parse::triple, allow_hyphen_values = true, requires = "camera_to"),
        unset("framed on the volumes"), example([400.0, 80.0, 500.0]);
    /// The point the camera looks at (world space).
    camera_to as "to": [f64; 3], serde(default, deserialize_with = "crate::parse::triple_field"),
        flag(long, value_parser = parse::triple, allow_hyphen_values = true, requires = "camera_from"),
        unset("framed on the volumes"), example([150.0, 80.0, 100.0]);
    /// The camera's up direction.
    camera_up as "up": [f32; 3], serde(default, deserialize_with = "crate::parse::triple_field"), flag(long, value_parser = parse::vector, allow_hyphen_values = true),
        default([0.0, 1.0, 0.0]), example([0.0, 0.0, 1.0]);
    /// Vertical field of view in degrees, of the given camera or of the
    /// one framed on the volumes.
    fov: f32, flag(long), default(40.0), example(25.0);
    @file_only {
        /// Camera to world, a 4x4 matrix (rows; column vectors, the
        /// translation in the last column): the camera looks along its -Z
        /// axis with +Y up, as in USD and Blender. Exclusive with
        /// `from`/`to`.
        matrix: Option<Matrix>;
        /// Time-sampled camera-to-world matrices, `[{ time, matrix }]`
        /// (frames), interpolated between samples: motion blur when the
        /// shutter is open.
        samples: Option<Vec<MatrixSample>>;
        /// Focal length (any one unit with the apertures, USD's tenths of
        /// a scene unit or millimetres): the field of view, instead of
        /// `fov`.
        focal_length: Option<f32>;
        /// Horizontal aperture, expanded to the image's aspect (USD's
        /// `expandAperture`).
        horizontal_aperture: Option<f32>;
        /// Vertical aperture.
        vertical_aperture: Option<f32>;
        /// `[near, far]` distances along the view axis: nothing nearer
        /// than `near` is seen (far is recorded and warned about, not
        /// clipped).
        clipping: Option<[f32; 2]>;
    }
    }

    /// `[sun]`: a directional light, optionally a small disc.
    table sun: SunSpec, SunFlags, optional {
    /// Whether there is a sun (`--no-sun`, Python `sun=False`: none).
    sun as "enabled": bool,
        flag(long = "no-sun", num_args = 0, default_missing_value = "false"),
        default(true), example(false);
    /// Direction the sunlight travels, from the sun toward the scene.
    sun_dir as "direction": [f32; 3], serde(default, deserialize_with = "crate::parse::triple_field"),
        flag(long, value_parser = parse::vector, allow_hyphen_values = true),
        default([0.7, -0.5, 0.5]), example([0.0, -1.0, 0.0]);
    /// Sun irradiance on a surface facing it (W/m^2 per channel, Mitsuba's
    /// `directional`).
    sun_irradiance as "irradiance": [f32; 3], serde(default, deserialize_with = "crate::parse::triple_field"),
        flag(long, value_parser = parse::vector, allow_hyphen_values = true),
        default([2.6, 2.5, 2.3]), example([1.0, 1.0, 1.0]);
    /// Angular diameter of the sun in degrees (0: a delta light).
    sun_angle as "angle": f32, flag(long), default(0.53), example(5.0);
    }

    /// `[environment]`: light from every direction, constant or a map.
    table environment: EnvironmentSpec, EnvironmentFlags, optional {
    /// Constant sky radiance (0,0,0 for none); ignored when a map is given.
    env_radiance as "radiance": [f32; 3], serde(default, deserialize_with = "crate::parse::triple_field"),
        flag(long, value_parser = parse::vector, allow_hyphen_values = true),
        default([0.16, 0.22, 0.34]), example([1.0, 1.0, 1.0]);
    /// A lat-long HDR sky (EXR) instead of the constant radiance (in a
    /// scene file: relative to the file).
    env_map as "map": PathBuf, flag(long), unset("none"),
        example(PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/sky.exr")));
    /// Rotation of the sky map about +Y, in degrees.
    env_rotation as "rotation": f32, flag(long, allow_hyphen_values = true), default(0.0),
        example(90.0);
    /// Multiplier of the sky map's radiance.
    env_intensity as "intensity": f32, flag(long), default(1.0), example(2.0);
    }

    /// `[[light]]`: one light of any kind, any number of them. A scene with
    /// a `[[light]]` has the sun and sky only where `[sun]` and
    /// `[environment]` (or their flags) are given.
    table lights as "light": LightSpec, LightFlags, each {
    @file_only {
        /// `distant`, `sphere`, `point` (a sphere of radius 0), `spot` (a
        /// sphere or point in a cone), `rect`, `disk` (one-sided area
        /// lights), `cylinder` (a cylinder's side, emitting outward) or
        /// `dome`.
        kind as "type": String;
        /// The light's name: its light-group layer where no `group` is
        /// given (unnamed lights join `sun`, `sky` or `lights` by kind).
        name: Option<String>;
        /// The light-group layer its light goes to.
        group: Option<String>;
        /// Where a sphere, point, spot or area light is (an area light's
        /// centre).
        position: Option<[f32; 3]> = serde(default, deserialize_with = "crate::parse::triple_field");
        /// Direction a distant light's light travels, a spot's axis, the
        /// side an area light emits toward, or a cylinder's axis.
        direction: Option<[f32; 3]> = serde(default, deserialize_with = "crate::parse::triple_field");
        /// An area light's second axis (its height's), turned square to
        /// `direction` (default +Y, or +Z along Y).
        up: Option<[f32; 3]> = serde(default, deserialize_with = "crate::parse::triple_field");
        /// A sphere or spot light's radius (sphere default 0.5, UsdLux's),
        /// or a disk's or cylinder's (default 0.5).
        radius: Option<f32>;
        /// A rect's width (default 1), or a disk's diameter across, an
        /// ellipse where it differs from `height`.
        width: Option<f32>;
        /// A rect's height (default 1), or a disk's diameter along `up`.
        height: Option<f32>;
        /// A cylinder's length along its axis (default 1, UsdLux's).
        length: Option<f32>;
        /// Colour, multiplying `intensity` (default 1,1,1).
        color: Option<[f32; 3]> = serde(default, deserialize_with = "crate::parse::triple_field");
        /// The light's strength (default 1), times `2^exposure` and
        /// `color`: a distant light's irradiance (W/m^2, as `[sun]`), a
        /// sphere's or area light's surface radiance (UsdLux; a point's
        /// radiant intensity, W/sr), a dome's radiance or its map's
        /// multiplier.
        intensity: Option<f32>;
        /// Stops (default 0): `intensity * 2^exposure`.
        exposure: Option<f32>;
        /// A sphere or area light's radiance divided by its area (`4 pi
        /// r^2` for a sphere, `2 pi r l` for a cylinder's side), so its
        /// power does not change with its size (UsdLux `normalize`).
        normalize: Option<bool>;
        /// A distant light's angular diameter in degrees (default 0.53).
        angle: Option<f32>;
        /// A spot's cone, half-angle off its axis in degrees (UsdLux
        /// `shaping:cone:angle`; Blender's spot size is twice it).
        cone_angle: Option<f32>;
        /// A spot's edge softness in [0, 1] (default 0; UsdLux
        /// `shaping:cone:softness`, Blender's spot blend).
        cone_softness: Option<f32>;
        /// Whether camera rays see a sphere, spot or area light's surface
        /// (default false, as Cycles' and Arnold's lamps: the light shows
        /// in the media it lights; scattered rays always meet it).
        visible_to_camera: Option<bool>;
        /// Whether a sphere or spot light lights each point from the disc
        /// of its radius through its centre facing the point rather than
        /// from its ball (default false: UsdLux's sphere; Blender's Soft
        /// Falloff, on by default for its point and spot lamps, which the
        /// add-on passes).
        soft_falloff: Option<bool>;
        /// A dome's lat-long HDR map (EXR, relative to the scene file).
        map: Option<PathBuf>;
        /// A dome map's rotation about +Y in degrees.
        rotation: Option<f32>;
        /// Values over time, `[{ time, position = [..], intensity = .. }]`
        /// (frames, increasing): each value keyed is interpolated linearly
        /// between the keys giving it and held outside them; motion blur
        /// where it changes while the shutter is open.
        keys: Option<Vec<LightKey>>;
    }
    }

    /// `[[volume]]`: one volume instance; a flag applies to every volume.
    table volumes as "volume": VolumeSpec, VolumeFlags, each {
    /// The density grid.
    grid as "density": String, flag(long),
        unset("\"density\", else the first float grid"), example("temperature".into());
    /// Extinction per unit density, in 1/world units: one number, or R,G,B
    /// for a chromatic medium.
    density_scale: Colour, flag(long, value_parser = parse::colour),
        unset("0.5 / voxel size: density 1 is half a mean free path per voxel"),
        example(Colour::Rgb([0.2, 0.3, 0.4]));
    /// Single-scattering albedo: one number or R,G,B.
    albedo: Colour, flag(long, value_parser = parse::colour), default(Colour::Grey(0.99)),
        example(Colour::Grey(0.5));
    /// Henyey-Greenstein asymmetry (of the first lobe of hg2; Draine's g).
    g: f32, flag(long, allow_hyphen_values = true), default(0.6), example(0.2);
    /// Phase function: hg, hg2 (two HG lobes), draine, mie (Jendersie and
    /// d'Eon 2023's fit by droplet diameter), rayleigh, or table:FILE (two
    /// columns, cos(theta) and value; in a scene file relative to the file).
    phase: String, flag(long), default("hg".into()), example("rayleigh".into());
    /// The second lobe of hg2.
    g2: f32, flag(long, allow_hyphen_values = true), default(-0.3), example(0.1);
    /// Weight of hg2's first lobe, in [0, 1].
    lobe_weight: f32, flag(long), default(0.8), example(0.5);
    /// Droplet diameter of mie, in micrometres (5 to 50).
    droplet_diameter: f32, flag(long), default(20.0), example(8.0);
    /// Draine's alpha.
    draine_alpha: f32, flag(long), default(1.0), example(0.5);
    /// The vec3 velocity grid moving the volume while the shutter is open.
    velocity: String, flag(long), unset("\"vel\", \"v\" or \"velocity\" if the file has one"),
        example("velocity".into());
    /// What velocity values measure: world units or velocity-grid voxels,
    /// per frame.
    velocity_unit: VelocityUnit, flag(long, value_enum), default(VelocityUnit::World),
        example(VelocityUnit::Voxels);
    /// Multiplies velocity values, e.g. 0.041667 (1/24) for per-second
    /// velocities at 24 fps.
    velocity_scale: f32, flag(long), default(1.0), example(2.0);
    @file_only {
        /// A .vdb, .nvdb or .cbrk file, relative to the scene file.
        file: PathBuf;
        /// The volume's name in the Cryptomatte manifest (default: the
        /// file's stem, made unique with `_2`, `_3`, ...).
        name: Option<String>;
        /// A matte: lights and shadows the other volumes, never seen by the
        /// camera (alpha cut where it stands in front).
        holdout: Option<bool>;
        /// Temperature grid name: blackbody emission.
        temperature: Option<String>;
        /// Blackbody parameters, `{ scale, offset, temperature_scale }`:
        /// `Le = scale * Blackbody((T - offset) * temperature_scale)`.
        blackbody: BlackbodySpec = serde(default);
        /// Emission grid name: `value * emission_color * emission_scale`.
        emission: Option<String>;
        /// The emission grid's colour.
        emission_color: Option<[f32; 3]> = serde(default, deserialize_with = "crate::parse::triple_field");
        /// The emission grid's multiplier.
        emission_scale: Option<f32>;
        /// Object to world: `{ translate, rotate = { axis, degrees } or
        /// euler = [x, y, z] (degrees, about X then Y then Z), scale }`,
        /// applied scale, then rotate, then translate.
        transform: TransformSpec = serde(default);
        /// Time-sampled files, `[{ time, file }]` (frames): the frame
        /// rendered reads the sample held at its time (the last at or
        /// before it, else the first).
        file_samples: Option<Vec<FileSample>>;
    }
    }
}

impl SceneDescription {
    /// Reads and parses `path`; errors name the file (toml's messages give
    /// the line, column and key).
    pub fn read(path: &Path) -> Result<SceneDescription> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::file(format!("{}: {e}", path.display())))?;
        Self::parse(&text).map_err(|e| Error::input(format!("{}: {e}", path.display())))
    }

    /// Parses the TOML form.
    pub fn parse(text: &str) -> std::result::Result<SceneDescription, String> {
        let file: SceneDescription = toml::from_str(text).map_err(|e| e.to_string())?;
        file.check()?;
        Ok(file)
    }

    /// Parses the JSON form (the same fields and nesting as the TOML).
    pub fn from_json(text: &str) -> std::result::Result<SceneDescription, String> {
        let file: SceneDescription = serde_json::from_str(text).map_err(|e| e.to_string())?;
        file.check()?;
        Ok(file)
    }

    /// Input paths (volumes, sky map) relative to `dir`, as a scene file's
    /// are relative to the file.
    pub fn rebase(&mut self, dir: &Path) {
        for v in &mut self.volumes {
            v.file = dir.join(&v.file);
            for s in v.file_samples.iter_mut().flatten() {
                s.file = dir.join(&s.file);
            }
            if let Some(table) = v.phase.as_deref().and_then(|p| p.strip_prefix("table:")) {
                v.phase = Some(format!("table:{}", dir.join(table).display()));
            }
        }
        if let Some(map) = self.environment.as_mut().and_then(|e| e.env_map.as_mut()) {
            *map = dir.join(&*map);
        }
        LightSpec::rebase_all(&mut self.lights, dir);
        if let Some(spec) = self.render.holdout_depth.as_mut() {
            let (file, channel) = crate::parse::split_depth_spec(spec);
            let file = dir.join(file).display().to_string();
            *spec = channel.map_or(file.clone(), |c| format!("{file}:{c}"));
        }
    }

    /// Every input and output path with its frame pattern replaced by `frame`.
    pub fn substitute_frame(&mut self, frame: i64) {
        use crate::frames::substitute;
        self.render.frame = Some(frame as f64);
        for v in &mut self.volumes {
            v.file = substitute(&v.file, frame);
            for s in v.file_samples.iter_mut().flatten() {
                s.file = substitute(&s.file, frame);
            }
        }
        self.hold_file_samples();
        if let Some(map) = self.environment.as_mut().and_then(|e| e.env_map.as_mut()) {
            *map = substitute(map, frame);
        }
        for map in self.lights.iter_mut().filter_map(|l| l.map.as_mut()) {
            *map = substitute(map, frame);
        }
        let o = &mut self.output;
        for path in [&mut o.output, &mut o.png, &mut o.stats, &mut o.deep]
            .into_iter()
            .flatten()
        {
            *path = substitute(path, frame);
        }
        if let Some(spec) = self.render.holdout_depth.as_mut() {
            *spec = substitute(Path::new(spec.as_str()), frame)
                .display()
                .to_string();
        }
    }

    /// The frame a render shows.
    pub fn frame(&self) -> f64 {
        self.render.frame.unwrap_or(0.0)
    }

    /// Sets each volume's `file` to its file sample held at the frame.
    pub fn hold_file_samples(&mut self) {
        let frame = self.frame();
        for v in &mut self.volumes {
            if let Some(samples) = v.file_samples.as_ref().filter(|s| !s.is_empty()) {
                let i = samples.partition_point(|s| s.time <= frame);
                v.file = samples[i.saturating_sub(1)].file.clone();
            }
        }
    }

    /// What serde cannot say: exclusive fields, ordered samples.
    fn check(&self) -> std::result::Result<(), String> {
        for (i, v) in self.volumes.iter().enumerate() {
            if v.transform.rotate.is_some() && v.transform.euler.is_some() {
                return Err(format!(
                    "volume {} ({}): give `rotate` or `euler`, not both",
                    i + 1,
                    v.file.display()
                ));
            }
            v.check()
                .map_err(|e| format!("volume {} ({}): {e}", i + 1, v.file.display()))?;
        }
        LightSpec::check_all(&self.lights)?;
        self.camera.check().map_err(|e| format!("[camera] {e}"))
    }
}

impl VolumeSpec {
    /// Checks the volume's transform and time-sampled fields and their
    /// exclusions.
    pub fn check(&self) -> std::result::Result<(), String> {
        let v = self;
        let t = &v.transform;
        let trs =
            t.translate.is_some() || t.rotate.is_some() || t.euler.is_some() || t.scale.is_some();
        if [trs, t.matrix.is_some(), t.samples.is_some()]
            .iter()
            .filter(|&&x| x)
            .count()
            > 1
        {
            return Err(
                "give the transform as translate/rotate/scale, `matrix` or `samples`, one of them"
                    .into(),
            );
        }
        if let Some(s) = &t.samples {
            check_samples(
                s.iter().map(|s| (s.time, finite_matrix(&s.matrix))),
                "transform samples",
            )?;
        }
        if let Some(m) = &t.matrix {
            if !finite_matrix(m) {
                return Err("the transform matrix must be finite".into());
            }
        }
        if let Some(s) = &v.file_samples {
            check_samples(s.iter().map(|s| (s.time, true)), "file_samples")?;
        }
        Ok(())
    }
}

impl CameraSpec {
    /// Checks the camera's matrix, samples and lens against each other.
    pub fn check(&self) -> std::result::Result<(), String> {
        let c = self;
        let placed = c.matrix.is_some() || c.samples.is_some();
        if placed && (c.camera_from.is_some() || c.camera_to.is_some()) {
            return Err("give `from`/`to` or `matrix`/`samples`, not both".into());
        }
        if c.matrix.is_some() && c.samples.is_some() {
            return Err("give `matrix` or `samples`, not both".into());
        }
        if let Some(m) = &c.matrix {
            if !finite_matrix(m) {
                return Err("the camera matrix must be finite".into());
            }
        }
        if let Some(s) = &c.samples {
            check_samples(
                s.iter().map(|s| (s.time, finite_matrix(&s.matrix))),
                "camera samples",
            )?;
        }
        if c.focal_length.is_some() && c.fov.is_some() {
            return Err("give `fov` or `focal_length`, not both".into());
        }
        let positive = |x: Option<f32>| x.is_none_or(|v| v.is_finite() && v > 0.0);
        if !positive(c.focal_length)
            || !positive(c.horizontal_aperture)
            || !positive(c.vertical_aperture)
        {
            return Err("focal length and apertures must be finite and > 0".into());
        }
        if let Some([near, far]) = c.clipping {
            if !(near.is_finite() && near >= 0.0 && far > near) {
                return Err(format!(
                    "clipping [{near}, {far}]: expected 0 <= near < far"
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_keys_and_wrong_types_name_the_key_and_line() {
        let e = SceneDescription::parse("[camera]\nfov = 30\nfocal = 2\n").unwrap_err();
        assert!(e.contains("line 3") && e.contains("focal"), "{e}");
        let e = SceneDescription::parse("[render]\nspp = \"many\"\n").unwrap_err();
        assert!(e.contains("line 2") && e.contains("spp"), "{e}");
        let e =
            SceneDescription::parse("[[volume]]\nfile = \"a.vdb\"\nalbedo = [1, 2]\n").unwrap_err();
        assert!(e.contains("line 3") && e.contains("albedo"), "{e}");
        let e = SceneDescription::parse("[camera]\nres = \"12by4\"\n").unwrap_err();
        assert!(e.contains("line 2") && e.contains("WxH"), "{e}");
    }

    #[test]
    fn a_full_scene_parses() {
        let s = SceneDescription::parse(
            r#"
            [output]
            exr = "a.exr"
            aov = ["albedo", "depth"]
            crop = [0, 0, 8, 8]
            [render]
            spp = 4
            integrator = "path"
            transmittance = "track-length"
            [camera]
            res = "32x16"
            from = [1, 2, 3]
            to = [0, 0, 0]
            [sun]
            enabled = false
            [environment]
            map = "sky.exr"
            rotation = 90
            [[volume]]
            file = "a.vdb"
            albedo = [0.9, 0.8, 0.7]
            density_scale = [30, 20, 10]
            transform = { translate = [1, 0, 0], rotate = { axis = [0, 1, 0], degrees = 45 }, scale = 2 }
            [[volume]]
            file = "b.vdb"
            temperature = "temperature"
            blackbody = { scale = 4, offset = 0, temperature_scale = 1000 }
            "#,
        )
        .unwrap();
        assert_eq!(s.volumes.len(), 2);
        assert_eq!(s.camera.res, Some((32, 16)));
        assert_eq!(
            s.render.transmittance,
            Some(TransmittanceEstimator::TrackLength)
        );
        assert_eq!(s.volumes[0].albedo.unwrap().rgb(), [0.9, 0.8, 0.7]);
        assert_eq!(
            s.volumes[0].density_scale,
            Some(Colour::Rgb([30.0, 20.0, 10.0]))
        );
        assert_eq!(s.volumes[1].density_scale, None);
        assert_eq!(s.volumes[1].blackbody.temperature_scale, Some(1000.0));
    }
}
