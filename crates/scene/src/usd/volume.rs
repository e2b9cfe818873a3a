//! `UsdVolVolume` prims: their `field:NAME` relationships to
//! `OpenVDBAsset` prims (`filePath`, `fieldName`, `fieldIndex`), their world
//! transform and their bound material, as one `[[volume]]` each.
//!
//! A field's role comes from its relationship's name (`density`;
//! `temperature`; `velocity`, `vel` or `v`; `emission`, `heat` or `flame`),
//! else from its `fieldName`. Every role must live in one file (cirrus
//! reads a volume's grids from one file): fields elsewhere are dropped with
//! a warning, as are fields of roles cirrus does not render.

use std::path::PathBuf;

use cirrus_vdb::VolumeFile;
use openusd::schemas::vol;

use crate::description::{FileSample, VolumeSpec};
use crate::error::{Error, Result};

use super::values::{attr_asset, attr_number, attr_text, sample_times, type_name};
use super::{material, xform, Reader};

/// What a field is used for.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    Density,
    Temperature,
    Velocity,
    Emission,
}

fn role_of(name: &str) -> Option<Role> {
    match name.to_ascii_lowercase().as_str() {
        "density" => Some(Role::Density),
        "temperature" | "temp" => Some(Role::Temperature),
        "velocity" | "vel" | "v" => Some(Role::Velocity),
        "emission" | "heat" | "flame" => Some(Role::Emission),
        _ => None,
    }
}

/// One `OpenVDBAsset` a volume points at.
struct Field {
    relationship: String,
    prim: String,
    role: Option<Role>,
    /// The grid name: `fieldName`, else the grid at `fieldIndex`.
    grid: Option<String>,
    index: Option<usize>,
    /// The resolved file at the start frame.
    file: PathBuf,
    samples: Option<Vec<FileSample>>,
}

/// The `[[volume]]` of the `Volume` prim at `path`.
pub fn read(r: &mut Reader, path: &str) -> Result<VolumeSpec> {
    let fields = fields(r, path)?;
    let density = fields
        .iter()
        .find(|f| f.role == Some(Role::Density))
        .or_else(|| fields.first())
        .ok_or_else(|| {
            r.error(
                path,
                "the volume has no field:NAME relationship to an OpenVDBAsset",
            )
        })?;
    let mut spec = VolumeSpec {
        file: density.file.clone(),
        file_samples: density.samples.clone(),
        ..Default::default()
    };
    for f in &fields {
        let same_file = f.file == density.file && f.samples == density.samples;
        let grid = grid_name(r, path, f)?;
        match f.role {
            Some(_) if !same_file => r.warn(format!(
                "{path}: field:{} ({}) is in another file than the density: not rendered",
                f.relationship,
                f.file.display()
            )),
            Some(Role::Density) => spec.grid = Some(grid),
            Some(Role::Temperature) => spec.temperature = Some(grid),
            Some(Role::Velocity) => {
                spec.velocity = Some(grid);
                // USD velocities are per second; cirrus moves per frame.
                spec.velocity_scale = Some((1.0 / r.time.frames_per_second) as f32);
            }
            Some(Role::Emission) => spec.emission = Some(grid),
            None => r.warn(format!(
                "{path}: field:{} ({}) has no role cirrus renders (density, temperature, velocity, emission): not rendered",
                f.relationship, f.prim
            )),
        }
    }
    if spec.grid.is_none() {
        spec.grid = Some(grid_name(r, path, density)?);
    }
    spec.transform = xform::transform_spec(&r.stage, path, r.time.start)?;
    material::apply(r, path, &mut spec)?;
    spec.check().map_err(|e| r.error(path, e))?;
    Ok(spec)
}

/// The fields `path` points at, each checked against its file.
fn fields(r: &mut Reader, path: &str) -> Result<Vec<Field>> {
    let volume = vol::Volume::get(&r.stage, path)
        .map_err(|e| r.error(path, format!("{e:#}")))?
        .ok_or_else(|| r.error(path, "not a Volume"))?;
    let targets = volume
        .field_paths()
        .map_err(|e| r.error(path, format!("fields: {e:#}")))?;
    let mut out = Vec::new();
    for (relationship, target) in targets {
        let prim_path = target.as_str().to_string();
        let kind = type_name(&r.stage, &prim_path)?;
        if kind != "OpenVDBAsset" {
            r.warn(format!(
                "{path}: field:{relationship} targets {prim_path} ({}): only OpenVDBAsset fields are read",
                if kind.is_empty() { "no prim" } else { &kind }
            ));
            continue;
        }
        out.push(field(r, path, relationship, prim_path)?);
    }
    Ok(out)
}

fn field(r: &mut Reader, volume: &str, relationship: String, prim_path: String) -> Result<Field> {
    let prim = r.stage.prim(prim_path.as_str());
    let start = r.time.start;
    let grid = attr_text(&prim, "fieldName", start)?.filter(|n| !n.is_empty());
    let index = attr_number(&prim, "fieldIndex", start)?
        .map(|i| {
            usize::try_from(i as i64)
                .map_err(|_| r.error(&prim_path, format!("fieldIndex {i} is negative")))
        })
        .transpose()?;
    let role = role_of(&relationship).or_else(|| grid.as_deref().and_then(role_of));
    let resolve = |r: &Reader, time: f64| -> Result<PathBuf> {
        match attr_asset(&prim, "filePath", time)? {
            None => Err(r.error(&prim_path, format!("field:{relationship} of {volume} has no filePath"))),
            Some((authored, None)) => Err(Error::file(format!(
                "{}: {prim_path}: filePath @{authored}@ (field:{relationship} of {volume}) names no file that exists",
                r.file
            ))),
            Some((_, Some(p))) => super::package::extracted(&p)
                .map_err(|e| Error::file(format!("{}: {prim_path}: {e}", r.file))),
        }
    };
    let times = sample_times(&prim.attribute("filePath"))?;
    let samples = match times.len() {
        0 | 1 => None,
        _ => Some(
            times
                .iter()
                .map(|&t| {
                    Ok(FileSample {
                        time: t,
                        file: resolve(r, t)?,
                    })
                })
                .collect::<Result<Vec<_>>>()?,
        ),
    };
    // The file the start frame reads: the sample held then.
    let file = match &samples {
        Some(s) => {
            let i = s.partition_point(|x| x.time <= start);
            s[i.saturating_sub(1)].file.clone()
        }
        None => resolve(r, times.first().copied().unwrap_or(start))?,
    };
    Ok(Field {
        relationship,
        prim: prim_path,
        role,
        grid,
        index,
        file,
        samples,
    })
}

/// The grid a field names, checked against its file's header (no voxels read).
fn grid_name(r: &Reader, volume: &str, f: &Field) -> Result<String> {
    let file = VolumeFile::open(&f.file).map_err(|e| {
        Error::file(format!(
            "{}: {} (field:{} of {volume}): {e}",
            r.file, f.prim, f.relationship
        ))
    })?;
    let names: Vec<String> = file.grids().iter().map(|g| g.name.clone()).collect();
    let found = match (&f.grid, f.index) {
        (Some(name), _) => names.iter().any(|n| n == name).then(|| name.clone()),
        (None, Some(i)) => names.get(i).cloned(),
        (None, None) => names.first().cloned(),
    };
    found.ok_or_else(|| {
        let wanted = match (&f.grid, f.index) {
            (Some(n), _) => format!("no grid named {n:?}"),
            (None, Some(i)) => format!("no grid at fieldIndex {i}"),
            (None, None) => "no grid".into(),
        };
        Error::input(format!(
            "{}: {} (field:{} of {volume}): {} has {wanted} (grids: {})",
            r.file,
            f.prim,
            f.relationship,
            f.file.display(),
            names.join(", ")
        ))
    })
}
