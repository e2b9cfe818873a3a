//! Every default of a render, written once: the command line's `--help`,
//! scene files and the bindings all fall back to these.
//!
//! Chosen for a daylight cloud: a single HG lobe at 0.85 (a cloud's Mie
//! mean cosine) made sunlit paths visibly speckled, 0.6 keeps the silver
//! lining at a fraction of the noise; density 1 is half a mean free path
//! per voxel.

use cirrus_render::{
    IntegratorKind, MajorantMode, SamplerKind, TransmittanceEstimator, VelocityUnit,
};

pub const RES: (u32, u32) = (512, 512);
pub const SPP: u32 = 64;
pub const SEED: u64 = 0;
pub const CAMERA_UP: [f32; 3] = [0.0, 1.0, 0.0];
/// Vertical field of view, degrees.
pub const FOV: f32 = 40.0;
/// The direction sunlight travels, from the sun toward the scene.
pub const SUN_DIRECTION: [f32; 3] = [0.7, -0.5, 0.5];
/// Irradiance on a surface facing the sun (Mitsuba's `directional`).
pub const SUN_IRRADIANCE: [f32; 3] = [2.6, 2.5, 2.3];
/// Angular diameter, degrees (the real sun's).
pub const SUN_ANGLE: f32 = 0.53;
pub const SKY_RADIANCE: [f32; 3] = [0.16, 0.22, 0.34];
pub const SKY_ROTATION: f32 = 0.0;
pub const SKY_INTENSITY: f32 = 1.0;
/// Extinction per unit density is this over the voxel size.
pub const DENSITY_SCALE_PER_VOXEL: f32 = 0.5;
pub const ALBEDO: f32 = 0.99;
pub const G: f32 = 0.6;
/// The back lobe of a two-lobe HG mix and the first lobe's weight.
pub const G2: f32 = -0.3;
pub const LOBE_WEIGHT: f32 = 0.8;
/// Draine's alpha (1 gives Cornette and Shanks' form).
pub const DRAINE_ALPHA: f32 = 1.0;
/// A typical cloud droplet, micrometres.
pub const DROPLET_DIAMETER: f32 = 20.0;
pub const INTEGRATOR: IntegratorKind = IntegratorKind::Path;
pub const SAMPLER: SamplerKind = SamplerKind::Sobol;
/// Samples a pixel takes before adaptive sampling may stop it.
pub const MIN_SPP: u32 = 16;
pub const TRANSMITTANCE: TransmittanceEstimator = TransmittanceEstimator::Residual;
/// The path tracer probes both structures on the scene and takes the
/// cheaper (`cirrus_render::majorant_choice`); the marchers walk the
/// hierarchy's cells.
pub const MAJORANT: MajorantMode = MajorantMode::Auto;
/// Majorant cells are refined while crossing one would cost more than this
/// many extra null collisions (Blender Cycles uses 1.442).
pub const REFINE_OPTICAL_DEPTH: f32 = 1.0;
/// Ray-march step, voxels.
pub const STEP: f32 = 0.5;
/// PNG preview exposure, stops.
pub const EXPOSURE: f32 = 0.0;
/// Grid names looked for when none is given.
pub const DENSITY_GRID: &str = "density";
/// The shutter, in frames around the frame (`--shutter`): closed, no
/// motion blur.
pub const SHUTTER: [f32; 2] = [0.0, 0.0];
/// Velocity grids used when the shutter is open and none is named
/// (`--velocity`): the first vec3 grid with one of these names.
pub const VELOCITY_GRIDS: [&str; 2] = ["vel", "v"];
/// Velocity values are world units per frame (`--velocity-unit`)...
pub const VELOCITY_UNIT: VelocityUnit = VelocityUnit::World;
/// ...times this (`--velocity-scale`; 1/24 for per-second values at 24 fps).
pub const VELOCITY_SCALE: f32 = 1.0;
