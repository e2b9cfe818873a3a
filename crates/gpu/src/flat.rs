//! The flat form of a prepared scene: plain arrays and one block of
//! parameters, the layout the WGSL kernels read (`shaders/common.wgsl`
//! declares the same structs). Built once per render on the host,
//! uploaded once.
//!
//! - `map`: the brick map, one `tag:2 | index:30` word a brick, x-major
//!   (`crates/bricks/src/layout.rs`).
//! - `atlas`: stored bricks' voxels as u32 words (uploaded in chunks of
//!   whole bricks, one a binding, as large as a binding may be): f32 bits one a word, or
//!   two f16 a word (the lower half the even voxel), 512 voxels a brick.
//! - `constants`: constant bricks' values.
//! - `pyramid`: every level of the bounds pyramid
//!   (`crates/bricks/src/bounds.rs`), (min, max) pairs in density units,
//!   x-major, level after level (`Params::levels` says where each starts).
//! - `partition`: the cell partition the CPU's walk reads
//!   (`crates/bricks/src/partition.rs`), its byte codes four to a word.
//! - `lights`: tagged records, one a light (suns, a constant sky, sphere,
//!   point and spot lights; [`LightRecord`] says each kind's fields).
//! - `phase_table`: a tabulated phase function's cosines, values and
//!   sampling CDF (`crates/kernel/src/phase/table.rs`).
//! - `Params`: the render-to-local transform, the camera's basis, the
//!   medium (density scale, albedo, HG g), sizes, the window, the seed,
//!   the walk's majorants and shadow rays' estimator.

use bytemuck::{Pod, Zeroable};
use cirrus_bricks::{Atlas, BrickVolume, CellPartition, MAX_LEVELS};
use cirrus_render::{
    AreaShape, Camera, Light, MajorantMode, Medium, Phase, TransmittanceEstimator,
};
use glam::Vec3;

/// Light record tags (`shaders/lights.wgsl`).
pub const LIGHT_SUN: u32 = 0;
pub const LIGHT_SKY: u32 = 1;
pub const LIGHT_SPHERE: u32 = 2;
pub const LIGHT_AREA: u32 = 3;

/// Area light shapes (`shaders/area_light.wgsl`).
pub const AREA_RECT: u32 = 0;
pub const AREA_DISK: u32 = 1;
pub const AREA_CYLINDER: u32 = 2;

/// Means `max_depth` is unlimited.
pub const UNLIMITED_DEPTH: u32 = u32::MAX;

/// The kernel's parameters (a uniform block: vec4-sized fields only).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct Params {
    /// Column-major render-to-local (index space) matrix.
    pub local_from_render: [[f32; 4]; 4],
    pub cam_origin: [f32; 4],
    /// Camera ray direction before normalisation: `forward + sx right +
    /// sy up` for `sx, sy` in [-1, 1] across the image.
    pub cam_forward: [f32; 4],
    pub cam_right: [f32; 4],
    pub cam_up: [f32; 4],
    /// Albedo (xyz) and density scale (w).
    pub albedo: [f32; 4],
    /// Local extent of the brick grid in voxels (xyz).
    pub extent: [f32; 4],
    /// The phase function's first lobe: g, alpha, norm, and (w) its
    /// weight (`shaders/phase.wgsl`).
    pub phase: [f32; 4],
    /// Its second lobe: g, alpha, norm.
    pub phase_b: [f32; 4],
    /// Bricks per axis (xyz), atlas precision (w: 0 f32, 1 f16).
    pub map_dims: [u32; 4],
    /// Light count (x), stored bricks per atlas chunk (y, set at upload),
    /// a tabulated phase function's rows (z).
    pub counts: [u32; 4],
    /// Full image width and height, window origin x0, y0.
    pub image: [u32; 4],
    /// Window width and height, first sample of the pass, samples in it.
    pub window: [u32; 4],
    /// Seed (low, high word), max depth ([`UNLIMITED_DEPTH`]: none).
    pub seed: [u32; 4],
    /// The slack past which a finest cell is walked voxel by voxel (x),
    /// the volume's largest density (y).
    pub walk: [f32; 4],
    /// Majorants (x: [`WALK_HIERARCHY`] or [`WALK_GLOBAL`]), shadow rays'
    /// estimator (y: `TRANSMITTANCE_*`), [`VOXEL_CELL_CORNERS`] (z).
    pub walk_mode: [u32; 4],
    /// Level-1 cells of the partition per axis.
    pub part_dims: [u32; 4],
    /// Per pyramid level: cells per axis, its first float in `pyramid`.
    pub levels: [[u32; 4]; MAX_LEVELS],
    /// Each channel's share of the extinction (xyz, the medium's
    /// `extinction_tint`), and (w) 1 where it is chromatic (tracked per
    /// channel, `shaders/spectral.wgsl`), 0 where grey.
    pub tint: [f32; 4],
}

/// The corners of a voxel cell, a parameter rather than a constant in the
/// kernel so that its loops over them stay rolled (`corners` in
/// `shaders/common.wgsl` says why).
pub const VOXEL_CELL_CORNERS: u32 = 8;

/// Majorant modes (`shaders/walk.wgsl`).
pub const WALK_HIERARCHY: u32 = 0;
pub const WALK_GLOBAL: u32 = 1;

/// Shadow rays' estimators (`shaders/ratio.wgsl`).
pub const TRANSMITTANCE_RATIO: u32 = 0;
pub const TRANSMITTANCE_RESIDUAL: u32 = 1;
pub const TRANSMITTANCE_TRACK_LENGTH: u32 = 2;

/// The walk the kernel takes: majorants and shadow rays' estimator, as
/// the settings name them (`Auto` majorants resolved by the caller).
#[derive(Clone, Copy, Debug)]
pub struct WalkChoice {
    pub majorant: MajorantMode,
    pub transmittance: TransmittanceEstimator,
}

/// One light, the same five vec4 for every kind (`shaders/lights.wgsl`
/// and `shaders/sphere_light.wgsl` read them).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct LightRecord {
    /// x: [`LIGHT_SUN`], [`LIGHT_SKY`], [`LIGHT_SPHERE`] or
    /// [`LIGHT_AREA`]; y: 1 where camera rays see its surface; z: 1 for a
    /// sphere light's soft falloff (the disc facing the lit point), an
    /// area light's shape (`AREA_*`).
    pub tag: [u32; 4],
    /// Sun: direction from the light (xyz), `1 - cos` of its half angle (w).
    /// Sphere: centre (xyz), radius (w, 0 for a point). Area: centre
    /// (xyz), area (w).
    pub dir: [f32; 4],
    /// Sun: irradiance (xyz), solid angle (w, 0 for a delta sun).
    /// Sky: radiance (xyz). Sphere: its surface's radiance `I / (pi
    /// r^2)` (xyz), a point's intensity `I`. Area: radiance (xyz).
    pub radiance: [f32; 4],
    /// Sphere: the spot's axis (xyz) and the cosine of its outer angle
    /// (w; -2 without a spot, so that nothing falls off), then the cosine
    /// of its inner angle (`[1].x`). Area: its half axes u and v (a
    /// cylinder's: half its length along the axis, its radius across),
    /// its unit normal (a cylinder's axis).
    pub shape: [[f32; 4]; 3],
}

/// The scene as arrays, ready to upload.
pub struct FlatScene {
    pub params: Params,
    pub map: Vec<u32>,
    pub atlas: Vec<u32>,
    pub constants: Vec<f32>,
    pub pyramid: Vec<f32>,
    pub partition: Vec<u32>,
    pub lights: Vec<LightRecord>,
    /// A tabulated phase function's rows (`phase_table`).
    pub phase_table: Vec<f32>,
}

impl FlatScene {
    /// The flat form of one medium over `volume`, placed by
    /// `local_ray` (render-space origin and direction to local ones), seen
    /// by `camera` and lit by `lights` (lights at infinity only: the
    /// caller has refused the rest), walked over `partition`'s cells (the
    /// field's own) as `walk` says.
    pub fn new<F>(
        medium: &Medium<F>,
        volume: &BrickVolume,
        partition: &CellPartition,
        local_ray: impl Fn(Vec3, Vec3) -> (Vec3, Vec3),
        camera: &Camera,
        lights: &[Light],
        walk: WalkChoice,
    ) -> Self {
        // An empty volume has no pyramid (and an empty box: no walk
        // reaches a cell).
        let mut pyramid = Vec::new();
        let mut levels = [[0u32; 4]; MAX_LEVELS];
        for (info, level) in levels.iter_mut().zip(&volume.levels) {
            *info = [
                level.dims[0],
                level.dims[1],
                level.dims[2],
                pyramid.len() as u32,
            ];
            pyramid.extend_from_slice(&level.cells);
        }
        let codes = partition.codes();
        let partition_words = codes
            .chunks(4)
            .map(|c| {
                c.iter()
                    .enumerate()
                    .fold(0u32, |w, (k, &b)| w | u32::from(b) << (8 * k))
            })
            .collect();
        let pd = partition.dims();
        let (phase, phase_b) = phase_lobes(&medium.phase);
        let phase_table = phase_table(&medium.phase);
        let table_rows = match &medium.phase {
            Phase::Table(t) => t.len() as u32,
            _ => 0,
        };
        let (atlas, precision) = atlas_words(volume.atlas());
        let lights: Vec<LightRecord> = lights.iter().map(light_record).collect();
        let extent = volume.local_extent();
        let params = Params {
            local_from_render: local_matrix(local_ray),
            albedo: [
                medium.albedo.x,
                medium.albedo.y,
                medium.albedo.z,
                medium.density_scale,
            ],
            extent: [extent.x, extent.y, extent.z, 0.0],
            phase,
            phase_b,
            map_dims: [volume.dims[0], volume.dims[1], volume.dims[2], precision],
            counts: [lights.len() as u32, 0, table_rows, 0],
            walk: [
                partition.voxel_split().min(f32::MAX),
                volume.max_density(),
                0.0,
                0.0,
            ],
            walk_mode: [
                walk_mode(walk.majorant),
                estimator(walk.transmittance),
                VOXEL_CELL_CORNERS,
                0,
            ],
            part_dims: [pd[0], pd[1], pd[2], 0],
            levels,
            tint: [
                medium.extinction_tint.x,
                medium.extinction_tint.y,
                medium.extinction_tint.z,
                if medium.extinction_tint == Vec3::ONE {
                    0.0
                } else {
                    1.0
                },
            ],
            ..camera_params(camera)
        };
        Self {
            params,
            map: non_empty(volume.map_words().to_vec(), 0),
            atlas: non_empty(atlas, 0),
            constants: non_empty(volume.constants().to_vec(), 0.0),
            pyramid: non_empty(pyramid, 0.0),
            partition: non_empty(partition_words, 0),
            lights: non_empty(lights, LightRecord::default()),
            phase_table,
        }
    }

    /// Words of one stored brick in the atlas (512 f32, or 256 pairs of
    /// f16).
    pub fn brick_words(&self) -> usize {
        if self.params.map_dims[3] == 1 {
            256
        } else {
            512
        }
    }

    /// Bytes of every array uploaded.
    pub fn bytes(&self) -> u64 {
        let lights = self.lights.len() * std::mem::size_of::<LightRecord>();
        let words = self.map.len()
            + self.atlas.len()
            + self.constants.len()
            + self.pyramid.len()
            + self.phase_table.len();
        (4 * (words + self.partition.len()) + lights + std::mem::size_of::<Params>()) as u64
    }

    /// Bytes of the largest array but the atlas (which is split over as
    /// many bindings as it needs): what one storage binding must hold.
    pub fn largest_binding(&self) -> u64 {
        [
            self.map.len() * 4,
            self.constants.len() * 4,
            self.pyramid.len() * 4,
            self.partition.len() * 4,
            self.phase_table.len() * 4,
            self.lights.len() * std::mem::size_of::<LightRecord>(),
        ]
        .into_iter()
        .max()
        .unwrap_or(0) as u64
    }
}

/// A Draine lobe `(g, alpha, norm, 0)`: HG at alpha 0 (draine.rs's
/// normaliser, in f64 as there).
fn lobe(g: f32, alpha: f32) -> [f32; 4] {
    let (g64, a64) = (f64::from(g), f64::from(alpha));
    let norm = 1.0 / (1.0 + a64 * (1.0 + 2.0 * g64 * g64) / 3.0);
    [g, alpha, norm as f32, 0.0]
}

/// `phase` as a blend of two Draine lobes (`shaders/phase.wgsl`), the
/// first's weight in its `w`: every phase function but a table, which
/// flags the second lobe (`w` 1) and keeps its density's scale there
/// (`x`), its rows in `FlatScene::phase_table`.
pub fn phase_lobes(phase: &Phase) -> ([f32; 4], [f32; 4]) {
    let (a, b, w) = match phase {
        Phase::Hg(h) => (lobe(h.g(), 0.0), lobe(0.0, 0.0), 1.0),
        Phase::TwoHg(blend) => {
            let (a, b) = blend.lobes();
            (lobe(a.g(), 0.0), lobe(b.g(), 0.0), blend.weight())
        }
        Phase::Draine(d) => (lobe(d.g(), d.alpha()), lobe(0.0, 0.0), 1.0),
        Phase::HgDraine(blend) => {
            let (a, b) = blend.lobes();
            (lobe(a.g(), 0.0), lobe(b.g(), b.alpha()), blend.weight())
        }
        Phase::Rayleigh(_) => (lobe(0.0, 1.0), lobe(0.0, 0.0), 1.0),
        // The table's own (`shaders/table_phase.wgsl`): its density's
        // scale over cosines, and the flag.
        Phase::Table(t) => {
            let (_, _, _, mu_density) = t.rows();
            (lobe(0.0, 0.0), [mu_density as f32, 0.0, 0.0, 1.0], 1.0)
        }
    };
    ([a[0], a[1], a[2], w], b)
}

/// A tabulated phase function as the kernel reads it: the rows' cosines,
/// values and sampling CDF one after another (a placeholder for the
/// others).
fn phase_table(phase: &Phase) -> Vec<f32> {
    match phase {
        Phase::Table(t) => {
            let (mu, value, cdf, _) = t.rows();
            let mut words = Vec::with_capacity(3 * mu.len());
            words.extend_from_slice(mu);
            words.extend_from_slice(value);
            words.extend(cdf.iter().map(|&c| c as f32));
            words
        }
        _ => vec![0.0],
    }
}

fn walk_mode(mode: MajorantMode) -> u32 {
    match mode {
        MajorantMode::Global => WALK_GLOBAL,
        MajorantMode::Hierarchy | MajorantMode::Auto => WALK_HIERARCHY,
    }
}

fn estimator(e: TransmittanceEstimator) -> u32 {
    match e {
        TransmittanceEstimator::Ratio => TRANSMITTANCE_RATIO,
        TransmittanceEstimator::Residual => TRANSMITTANCE_RESIDUAL,
        TransmittanceEstimator::TrackLength => TRANSMITTANCE_TRACK_LENGTH,
    }
}

/// A storage binding may not be empty: one placeholder element.
fn non_empty<T: Clone>(mut v: Vec<T>, fill: T) -> Vec<T> {
    if v.is_empty() {
        v.push(fill);
    }
    v
}

/// The atlas as u32 words, and its precision code.
fn atlas_words(atlas: &Atlas) -> (Vec<u32>, u32) {
    match atlas {
        Atlas::F32(a) => (a.iter().map(|v| v.to_bits()).collect(), 0),
        Atlas::F16(a) => (
            a.chunks(2)
                .map(|p| u32::from(p[0]) | u32::from(*p.get(1).unwrap_or(&0)) << 16)
                .collect(),
            1,
        ),
        // Refused before flattening (`support.rs`).
        Atlas::U8(_) => (Vec::new(), 2),
    }
}

/// The affine render-to-local map, read back from `local_ray` (which maps
/// a render-space origin and direction): its columns are the images of
/// the axes, its translation the image of the origin.
fn local_matrix(local_ray: impl Fn(Vec3, Vec3) -> (Vec3, Vec3)) -> [[f32; 4]; 4] {
    let (o, x) = local_ray(Vec3::ZERO, Vec3::X);
    let (_, y) = local_ray(Vec3::ZERO, Vec3::Y);
    let (_, z) = local_ray(Vec3::ZERO, Vec3::Z);
    [
        [x.x, x.y, x.z, 0.0],
        [y.x, y.y, y.z, 0.0],
        [z.x, z.y, z.z, 0.0],
        [o.x, o.y, o.z, 1.0],
    ]
}

/// The camera's origin and basis, read back from its own rays so that the
/// kernel's rays are the CPU's (`crates/kernel/src/camera.rs`, `ray`): the
/// ray through the middle of the right edge is `forward + right` and the
/// one through the middle of the top edge `forward + up`, normalised.
fn camera_params(camera: &Camera) -> Params {
    let (w, h) = (camera.width() as f32, camera.height() as f32);
    let forward = camera.forward();
    let unscaled = |d: Vec3| d / d.dot(forward) - forward;
    let centre = camera.ray(0.5 * w, 0.5 * h);
    let right = unscaled(camera.ray(w, 0.5 * h).dir);
    let up = unscaled(camera.ray(0.5 * w, 0.0).dir);
    let v4 = |v: Vec3| [v.x, v.y, v.z, 0.0];
    Params {
        cam_origin: v4(centre.origin),
        cam_forward: v4(forward),
        cam_right: v4(right),
        cam_up: v4(up),
        ..Default::default()
    }
}

/// A light as a record (a dome's map, refused before by `support.rs`,
/// would be its constant radiance).
fn light_record(light: &Light) -> LightRecord {
    let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
    match light {
        Light::Distant(sun) => LightRecord {
            tag: [LIGHT_SUN, 0, 0, 0],
            dir: v4(sun.direction(), sun.one_minus_cos_half_angle()),
            radiance: v4(sun.irradiance(), sun.solid_angle()),
            ..Default::default()
        },
        Light::Dome(env) => LightRecord {
            tag: [LIGHT_SKY, 0, 0, 0],
            dir: [0.0; 4],
            radiance: v4(env.radiance, 0.0),
            ..Default::default()
        },
        Light::Sphere(s) => {
            let radiance = if s.is_point() {
                s.intensity()
            } else {
                s.radiance()
            };
            let (axis, (cos_outer, cos_inner)) = match s.spot() {
                Some(spot) => (spot.axis(), spot.cosines()),
                None => (Vec3::Z, (-2.0, -2.0)),
            };
            LightRecord {
                tag: [
                    LIGHT_SPHERE,
                    u32::from(s.camera_visible()),
                    u32::from(s.soft_falloff()),
                    0,
                ],
                dir: v4(s.position(), s.radius()),
                radiance: v4(radiance, 0.0),
                shape: [v4(axis, cos_outer), [cos_inner, 0.0, 0.0, 0.0], [0.0; 4]],
            }
        }
        Light::Area(a) => {
            let (half_u, half_v) = a.half_axes();
            let shape = match a.shape() {
                AreaShape::Rect => AREA_RECT,
                AreaShape::Disk => AREA_DISK,
                AreaShape::Cylinder => AREA_CYLINDER,
            };
            LightRecord {
                tag: [LIGHT_AREA, u32::from(a.camera_visible()), shape, 0],
                dir: v4(a.centre(), a.area()),
                radiance: v4(a.radiance(), 0.0),
                shape: [v4(half_u, 0.0), v4(half_v, 0.0), v4(a.normal(), 0.0)],
            }
        }
    }
}
