//! Loading the volumes of a scene: each volume's plan (file, grids,
//! transform, medium, world box) and the [`VolumeCache`] of files and
//! grids read for it, each read once however many instances (or renders)
//! use it, with the bytes it cost.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use cirrus_bricks::{BrickVolume, DBounds3, Precision, VelocityGrid};
use cirrus_kernel::medium::BrickField;
use cirrus_kernel::medium::Extinction;
use cirrus_render::{
    Blackbody, DensityField, Emission, IntegratorKind, Medium, Phase, Shutter, Velocity,
    VelocityUnit,
};
use cirrus_vdb::VolumeFile;
use glam::{DMat3, DMat4, DVec3, Vec3};

use crate::description::{Colour, ScaleSpec, VolumeSpec};
use crate::error::{Error, Result};
use crate::grids::{
    choose_grid, choose_velocity, is_cbrk, read_bricks_at, read_cbrk_file, read_render_bricks,
    read_velocity,
};

/// A moving volume's pose table and the shell of bricks bounding its
/// density over every pose.
pub type Pose = (Arc<cirrus_kernel::transform_motion::PoseTable>, BrickVolume);

/// One volume's plan: where its grids are and how it is placed.
pub struct Plan {
    pub file: PathBuf,
    cbrk: bool,
    /// How its `.vdb`/`.nvdb` grids are stored once read.
    precision: GridPrecision,
    density: usize,
    temperature: Option<usize>,
    emission: Option<usize>,
    /// The velocity grid, when the shutter is open and the file has one.
    velocity: Option<usize>,
    velocity_unit: VelocityUnit,
    velocity_scale: f32,
    pub(crate) object_to_world: DMat4,
    /// From the grid header, when the file says.
    pub world_box: Option<DBounds3>,
    density_scale: Option<Colour>,
    albedo: Vec3,
    phase: Phase,
    blackbody: Blackbody,
    emission_colour: Vec3,
    /// A matte (compositing).
    holdout: bool,
}

impl Plan {
    fn grid_key(&self, index: usize) -> GridKey {
        (self.file.clone(), index, self.precision)
    }

    pub fn emits(&self) -> bool {
        self.temperature.is_some() || self.emission.is_some()
    }

    /// Object to world.
    pub fn object_to_world(&self) -> DMat4 {
        self.object_to_world
    }
}

/// How a grid read from a `.vdb` or `.nvdb` is stored for rendering (a
/// `.cbrk` keeps the precision it was converted at).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GridPrecision {
    /// 32-bit floats.
    F32,
    /// [`cirrus_bricks::RENDER_PRECISION`] (f16), or f32 where the
    /// densities do not fit in f16.
    Render,
}

fn object_to_world(v: &VolumeSpec) -> DMat4 {
    let t = &v.transform;
    if let Some(m) = &t.matrix {
        return crate::timeline::to_dmat4(m);
    }
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

/// The plan of volume `v` (its file already relative to the working
/// directory); opens its file, reading the index only. `moving`: the
/// shutter reaches away from the frame's instant, so a velocity grid is
/// looked for.
pub fn plan(
    v: &VolumeSpec,
    files: &mut VolumeCache,
    moving: bool,
    precision: GridPrecision,
) -> Result<Plan> {
    let path = v.file.clone();
    let object_to_world = object_to_world(v);
    if !object_to_world.is_finite() || object_to_world.determinant().abs() < 1e-300 {
        return Err(Error::input(format!(
            "{}: the transform is singular",
            v.file.display()
        )));
    }
    let cbrk = is_cbrk(&path);
    let (density, temperature, emission, world_box) = if cbrk {
        if v.temperature.is_some() || v.emission.is_some() || (moving && v.velocity.is_some()) {
            return Err(Error::input(format!(
                "{}: a .cbrk holds one density grid; temperature, emission and velocity need the .vdb",
                path.display()
            )));
        }
        (0, None, None, None)
    } else {
        let f = files.open(&path)?;
        let density = choose_grid(f, v.grid.as_deref())?;
        let named = |n: &Option<String>| -> Result<Option<usize>> {
            n.as_ref()
                .map(|n| f.find_grid(n).map_err(|e| Error::input(e.to_string())))
                .transpose()
        };
        let temperature = named(&v.temperature)?;
        let emission = named(&v.emission)?;
        let header = f.grid_bounds(density)?;
        let world_box = header.map(|(t, lo, hi)| {
            // Trilinear support reaches one voxel past the active box.
            let lo = DVec3::from_array(lo.map(f64::from)) - 1.0;
            let hi = DVec3::from_array(hi.map(f64::from)) + 1.0;
            DBounds3::new(lo, hi).transformed(object_to_world * t.index_to_world_matrix())
        });
        (density, temperature, emission, world_box)
    };
    let velocity = match (moving, cbrk) {
        (true, false) => choose_velocity(files.open(&path)?, v.velocity.as_deref())?,
        _ => None,
    };
    if let Some(w) = velocity_warning(v, moving, cbrk, velocity, files)? {
        files.warnings.push(w);
    }
    let velocity_scale = v.velocity_scale();
    if !velocity_scale.is_finite() {
        return Err(Error::input(format!(
            "{}: velocity scale must be finite, got {velocity_scale}",
            path.display()
        )));
    }
    let bb = &v.blackbody;
    Ok(Plan {
        file: path,
        cbrk,
        precision,
        density,
        temperature,
        emission,
        velocity,
        velocity_unit: v.velocity_unit(),
        velocity_scale,
        object_to_world,
        world_box,
        density_scale: v.density_scale,
        albedo: v.albedo().vec3(),
        phase: phase_of(v)?,
        blackbody: Blackbody {
            scale: bb.scale.unwrap_or(1.0),
            offset: bb.offset.unwrap_or(0.0),
            temperature_scale: bb.temperature_scale.unwrap_or(1.0),
        },
        emission_colour: Vec3::from_array(v.emission_color.unwrap_or([1.0; 3]))
            * v.emission_scale.unwrap_or(1.0),
        holdout: v.holdout.unwrap_or(false),
    })
}

/// What to say when the shutter is open and a volume's density cannot
/// move: no velocity grid was found (the file's vector grids listed, any
/// of which `--velocity` can name), or a `.cbrk` holds none.
fn velocity_warning(
    v: &VolumeSpec,
    moving: bool,
    cbrk: bool,
    found: Option<usize>,
    files: &mut VolumeCache,
) -> Result<Option<String>> {
    let path = v.file.display();
    if !moving {
        return Ok(None);
    }
    // A time-sampled transform moves the volume whole: no velocity needed.
    if found.is_some() || v.transform.samples.is_some() {
        return Ok(None);
    }
    if cbrk {
        return Ok(Some(format!(
            "{path}: the shutter is open but a .cbrk holds no velocity grid: no motion blur \
             (render the .vdb for it)"
        )));
    }
    let vectors = vector_grids(files.open(&v.file)?);
    let listed = match vectors.is_empty() {
        true => "the file has no vector grid".to_string(),
        false => format!(
            "its vector grids: {}; name one with --velocity NAME",
            vectors.join(", ")
        ),
    };
    Ok(Some(format!(
        "{path}: the shutter is open but no velocity grid was found (looked for {}): its \
         density does not move (no motion blur from it); {listed}",
        crate::grids::VELOCITY_GRIDS.join(", ")
    )))
}

/// The names of a file's vec3 grids.
fn vector_grids(f: &VolumeFile) -> Vec<String> {
    f.grids()
        .iter()
        .filter(|g| {
            matches!(
                g.value_type,
                Some(cirrus_vdb::ValueType::Vec3f | cirrus_vdb::ValueType::Vec3d)
            )
        })
        .map(|g| format!("{:?}", g.name))
        .collect()
}

/// The phase function a volume names, with the defaults filled in.
pub fn phase_of(v: &VolumeSpec) -> Result<Phase> {
    let g = v.g();
    let name = v.phase();
    let phase = match name.as_str() {
        "hg" => Ok(Phase::hg(g)),
        "hg2" => Phase::hg2(g, v.g2(), v.lobe_weight()),
        "draine" => Phase::draine(g, v.draine_alpha()),
        "mie" => Phase::mie(v.droplet_diameter()),
        "rayleigh" => Ok(Phase::rayleigh()),
        _ => match name.strip_prefix("table:") {
            // The table's own errors name its file.
            Some(path) => return Ok(Phase::read_table(path)?),
            None => Err(cirrus_render::Error::invalid(format!(
                "phase {name:?}: expected hg, hg2, draine, mie, rayleigh or table:FILE"
            ))),
        },
    };
    phase.map_err(|e| Error::from(e).within(v.file.display()))
}

/// `field` moving with `velocity` over `shutter`, if it has one.
fn moved<'v>(
    field: BrickField<'v>,
    velocity: Option<&Velocity>,
    shutter: Shutter,
    file: &Path,
) -> Result<BrickField<'v>> {
    match velocity {
        Some(v) => field
            .with_motion(v, shutter)
            .map_err(|e| Error::input(format!("{}: {e}", file.display()))),
        None => Ok(field),
    }
}

/// Open files and loaded grids, shared by the volumes that use them (two
/// instances of one file read it once) and kept across the renders of one
/// cache (a preview's passes), with what reading them cost.
#[derive(Default)]
pub struct VolumeCache {
    open: HashMap<PathBuf, VolumeFile>,
    grids: HashMap<GridKey, BrickVolume>,
    velocities: HashMap<(PathBuf, usize), Arc<VelocityGrid>>,
    cbrk_bytes: u64,
    /// What planning and loading found wrong but could render, not yet
    /// handed to a prepared scene.
    pub(crate) warnings: Vec<String>,
    /// The pose tables and shells of the last prepared scene's moving
    /// volumes, per kept volume (`moving.rs`).
    pub(crate) poses: Vec<Option<Pose>>,
}

/// A grid of a file as it is stored: file, grid index, precision.
type GridKey = (PathBuf, usize, GridPrecision);

impl VolumeCache {
    fn open(&mut self, path: &Path) -> Result<&VolumeFile> {
        if !self.open.contains_key(path) {
            let f = VolumeFile::open(path)?;
            self.open.insert(path.to_path_buf(), f);
        }
        Ok(&self.open[path])
    }

    /// Reads grid `index` of a plan's file once.
    fn grid(&mut self, p: &Plan, index: usize) -> Result<&BrickVolume> {
        let key = p.grid_key(index);
        if !self.grids.contains_key(&key) {
            let path = &p.file;
            let volume = if p.cbrk {
                self.cbrk_bytes += std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
                read_cbrk_file(path)?
            } else {
                let f = self.open(path)?;
                match p.precision {
                    GridPrecision::F32 => read_bricks_at(f, index, Precision::F32)?,
                    GridPrecision::Render => read_render_bricks(f, index)?,
                }
            };
            let bad = volume.info.sanitized_voxels;
            if bad > 0 {
                self.warnings.push(format!(
                    "{}: grid {:?}: {bad} voxels are NaN, infinite or negative; they render \
                     as density 0 (empty space)",
                    path.display(),
                    volume.info.grid_name
                ));
            }
            self.grids.insert(key.clone(), volume);
        }
        Ok(&self.grids[&key])
    }

    /// A plan's density grid, loading it.
    pub fn density(&mut self, p: &Plan) -> Result<&BrickVolume> {
        self.grid(p, p.density)
    }

    /// A plan's loaded density grid.
    pub(crate) fn density_volume(&self, p: &Plan) -> &BrickVolume {
        &self.grids[&p.grid_key(p.density)]
    }

    /// The world box of a plan's density grid, loading it.
    pub fn density_box(&mut self, p: &Plan) -> Result<DBounds3> {
        let v = self.grid(p, p.density)?;
        let m = p.object_to_world * v.local_from_world().inverse();
        Ok(DBounds3::new(DVec3::ZERO, v.local_extent().as_dvec3()).transformed(m))
    }

    /// A plan's velocity (its grid read once), if it moves.
    fn velocity(&mut self, p: &Plan) -> Result<Option<Velocity>> {
        let Some(index) = p.velocity else {
            return Ok(None);
        };
        let key = (p.file.clone(), index);
        if !self.velocities.contains_key(&key) {
            let grid = read_velocity(self.open(&p.file)?, index)?;
            self.velocities.insert(key.clone(), Arc::new(grid));
        }
        Ok(Some(Velocity {
            grid: self.velocities[&key].clone(),
            unit: p.velocity_unit,
            scale: p.velocity_scale,
        }))
    }

    /// `world_box` (a plan's box) grown by the farthest its density can
    /// move over `shutter`, for culling.
    pub fn motion_box(
        &mut self,
        p: &Plan,
        world_box: DBounds3,
        shutter: Shutter,
    ) -> Result<DBounds3> {
        let Some(v) = self.velocity(p)? else {
            return Ok(world_box);
        };
        let abs = |m: DMat3| DMat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        let from_value = match v.unit {
            VelocityUnit::World => DMat3::IDENTITY,
            VelocityUnit::Voxels => abs(DMat3::from_mat4(v.grid.index_to_world)),
        };
        let reach = f64::from(v.scale.abs() * shutter.max_abs_time());
        let pad = abs(DMat3::from_mat4(p.object_to_world))
            * (from_value * v.grid.max_abs().as_dvec3())
            * reach;
        Ok(DBounds3::new(world_box.min - pad, world_box.max + pad))
    }

    pub fn load_grids(&mut self, p: &Plan) -> Result<()> {
        self.velocity(p)?;
        self.grid(p, p.density)?;
        for index in [p.temperature, p.emission].into_iter().flatten() {
            self.grid(p, index)?;
        }
        Ok(())
    }

    /// The instance of a plan whose grids are loaded, placed in render
    /// space (world minus `centre`).
    /// Its majorant cells are refined for its density scale, as a lone
    /// volume's are (`refine`: the optical depth a cell may waste).
    /// Moving (`shutter`, the plan's velocity) when its velocity is loaded.
    pub fn instance(
        &self,
        p: &Plan,
        centre: DVec3,
        integrator: IntegratorKind,
        refine: f32,
        shutter: Shutter,
    ) -> Result<Medium<BrickField<'_>>> {
        let velocity = p.velocity.map(|index| Velocity {
            grid: self.velocities[&(p.file.clone(), index)].clone(),
            unit: p.velocity_unit,
            scale: p.velocity_scale,
        });
        let moved = |f| moved(f, velocity.as_ref(), shutter, &p.file);
        let field = |index: usize| {
            let v = &self.grids[&p.grid_key(index)];
            BrickField::new(v, p.object_to_world, centre)
        };
        let density = field(p.density);
        let extinction = extinction(&p.file, p.density_scale, density.voxel_size())?;
        if !p.albedo.is_finite() || p.albedo.min_element() < 0.0 || p.albedo.max_element() > 1.0 {
            return Err(Error::input(format!(
                "{}: albedo must lie in [0, 1], got {}",
                p.file.display(),
                p.albedo
            )));
        }
        let density = moved(walk_cells(density, integrator, extinction.scale, refine))?;
        let mut inst = Medium::new(density, extinction.scale, p.albedo, 0.0)
            .with_phase(p.phase.clone())
            .with_extinction_tint(extinction.tint);
        inst.holdout = p.holdout;
        if p.emits() {
            inst.emission = Some(Emission {
                temperature: p
                    .temperature
                    .map(|i| moved(field(i)).map(|f| (f, p.blackbody)))
                    .transpose()?,
                grid: p
                    .emission
                    .map(|i| moved(field(i)).map(|f| (f, p.emission_colour)))
                    .transpose()?,
            });
        }
        Ok(inst)
    }

    /// The field whose segments bound a moving plan's density over every
    /// pose: its `shell` placed as the plan is, walked as its density is.
    pub(crate) fn bound_field<'v>(
        &'v self,
        p: &Plan,
        shell: &'v BrickVolume,
        centre: DVec3,
        settings: &crate::settings::SceneSettings,
        shutter: Shutter,
    ) -> Result<BrickField<'v>> {
        let field = BrickField::new(shell, p.object_to_world, centre);
        let extinction = extinction(&p.file, p.density_scale, field.voxel_size())?;
        let field = walk_cells(
            field,
            settings.render.integrator,
            extinction.scale,
            settings.refine_optical_depth,
        );
        let velocity = self.velocity_of(p);
        moved(field, velocity.as_ref(), shutter, &p.file)
    }

    fn velocity_of(&self, p: &Plan) -> Option<Velocity> {
        p.velocity.map(|index| Velocity {
            grid: self.velocities[&(p.file.clone(), index)].clone(),
            unit: p.velocity_unit,
            scale: p.velocity_scale,
        })
    }

    pub fn bytes_read(&self) -> u64 {
        self.open.values().map(|f| f.bytes_read()).sum::<u64>() + self.cbrk_bytes
    }

    pub fn grids_loaded(&self) -> u64 {
        self.grids.len() as u64
    }
}

/// A volume's default extinction per unit density is this over its voxel
/// size: density 1 is half a mean free path per voxel.
pub const DENSITY_SCALE_PER_VOXEL: f32 = 0.5;

/// A volume's extinction per unit density: the given scale (one number or
/// one per channel, each finite and >= 0), or the default for its voxel
/// size; split for the renderer ([`Extinction`]).
pub(crate) fn extinction(
    file: &Path,
    given: Option<Colour>,
    voxel_size: f32,
) -> Result<Extinction> {
    let rgb = given.map_or(
        Vec3::splat(DENSITY_SCALE_PER_VOXEL / voxel_size),
        Colour::vec3,
    );
    if !rgb.is_finite() || rgb.min_element() < 0.0 {
        return Err(Error::input(format!(
            "{}: density scale must be finite and >= 0 in every channel, got {}",
            file.display(),
            given.map_or(rgb.to_string(), |c| c.to_string())
        )));
    }
    Ok(Extinction::split(rgb))
}

/// The cells a density field's walk visits for `integrator`: occupancy
/// cells for the marchers, majorant cells refined by `refine` (the optical
/// depth a cell may waste) for the trackers.
pub(crate) fn walk_cells(
    field: BrickField<'_>,
    integrator: IntegratorKind,
    density_scale: f32,
    refine: f32,
) -> BrickField<'_> {
    if integrator.marches() {
        field.for_marching()
    } else {
        field.with_refinement(density_scale, refine)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extinction_splits_channels_and_refuses_bad_ones() {
        let f = Path::new("cloud.vdb");
        let grey = extinction(f, Some(Colour::Grey(20.0)), 0.1).unwrap();
        assert_eq!((grey.scale, grey.tint), (20.0, Vec3::ONE));
        let rgb = extinction(f, Some(Colour::Rgb([10.0, 40.0, 20.0])), 0.1).unwrap();
        assert_eq!((rgb.scale, rgb.tint), (40.0, Vec3::new(0.25, 1.0, 0.5)));
        let default = extinction(f, None, 0.25).unwrap();
        assert_eq!(default.scale, DENSITY_SCALE_PER_VOXEL / 0.25);
        for bad in [
            [1.0, -1.0, 1.0],
            [1.0, f32::NAN, 1.0],
            [f32::INFINITY, 1.0, 1.0],
        ] {
            let e = extinction(f, Some(Colour::Rgb(bad)), 0.1)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("cloud.vdb") && e.contains("density scale"),
                "{e}"
            );
        }
    }
}
