//! One NanoVDB grid buffer into a [`Grid`]: `GridData` (name, map, class,
//! type) here, then the tree (`TreeData`, root table, internal nodes and
//! leaves) in `walk.rs`.

use super::buf::Buf;
use super::layout::{self, Layout};
use super::walk::build_tree;
use crate::error::{corrupt, unsupported, KindResult};
use crate::grid::{Grid, GridClass};
use crate::metadata::MetaValue;
use crate::transform::{MapKind, Transform};
use glam::{DMat4, DVec4};

pub const GRID_MAGICS: [&[u8; 8]; 2] = [b"NanoVDB0", b"NanoVDB1"];

/// `major.minor.patch` of a packed NanoVDB `Version` (11 + 11 + 10 bits).
pub fn version_parts(v: u32) -> (u32, u32, u32) {
    (v >> 21, (v >> 10) & 0x7ff, v & 0x3ff)
}

pub fn version_string(v: u32) -> String {
    let (a, b, c) = version_parts(v);
    format!("{a}.{b}.{c}")
}

/// The fields of `GridData` that the index needs.
#[derive(Clone, Debug)]
pub struct GridHeader {
    pub version: u32,
    pub grid_size: u64,
    pub name: String,
    pub grid_class: u32,
    pub grid_type: u32,
}

/// Reads and checks the `GridData` at the start of `buf`.
pub fn read_header(buf: &[u8]) -> KindResult<GridHeader> {
    let b = Buf(buf);
    let magic = b.bytes(layout::grid::MAGIC, 8, "grid magic")?;
    if !GRID_MAGICS.iter().any(|m| magic == m.as_slice()) {
        return Err(corrupt(format!(
            "grid buffer starts with {magic:02x?}, not a NanoVDB grid magic"
        )));
    }
    let version = b.u32(layout::grid::VERSION, "grid version")?;
    if version_parts(version).0 != 32 {
        return Err(unsupported(format!(
            "NanoVDB grid version {} (only major version 32 is read)",
            version_string(version)
        )));
    }
    let name = b.bytes(layout::grid::NAME, layout::grid::NAME_SIZE, "grid name")?;
    let name = &name[..name.iter().position(|&c| c == 0).unwrap_or(name.len())];
    Ok(GridHeader {
        version,
        grid_size: b.u64(layout::grid::GRID_SIZE, "grid size")?,
        name: String::from_utf8_lossy(name).into_owned(),
        grid_class: b.u32(layout::grid::GRID_CLASS, "grid class")?,
        grid_type: b.u32(layout::grid::GRID_TYPE, "grid type")?,
    })
}

/// NanoVDB's `GridClass`; classes OpenVDB does not have become `Unknown`.
pub fn grid_class(c: u32) -> GridClass {
    match c {
        1 => GridClass::LevelSet,
        2 => GridClass::FogVolume,
        3 => GridClass::Staggered,
        _ => GridClass::Unknown,
    }
}

/// The index-to-world map from `Map`'s double-precision 3x3 matrix (row-major,
/// `world = M * ijk + t`) and translation.
fn read_transform(b: Buf) -> KindResult<Transform> {
    let mut m = [0.0f64; 9];
    for (i, v) in m.iter_mut().enumerate() {
        *v = b.f64(layout::grid::MAT_D + 8 * i, "map matrix")?;
    }
    let mut t = [0.0f64; 3];
    for (i, v) in t.iter_mut().enumerate() {
        *v = b.f64(layout::grid::VEC_D + 8 * i, "map translation")?;
    }
    let off_diagonal = [m[1], m[2], m[3], m[5], m[6], m[7]]
        .iter()
        .any(|&v| v != 0.0);
    let uniform = m[0] == m[4] && m[0] == m[8];
    let translated = t.iter().any(|&v| v != 0.0);
    let kind = match (off_diagonal, uniform, translated) {
        (true, _, _) => MapKind::Affine,
        (false, true, false) => MapKind::UniformScale,
        (false, true, true) => MapKind::UniformScaleTranslate,
        (false, false, false) => MapKind::Scale,
        (false, false, true) => MapKind::ScaleTranslate,
    };
    let cols = DMat4::from_cols(
        DVec4::new(m[0], m[3], m[6], 0.0),
        DVec4::new(m[1], m[4], m[7], 0.0),
        DVec4::new(m[2], m[5], m[8], 0.0),
        DVec4::new(t[0], t[1], t[2], 1.0),
    );
    Transform::from_matrix(kind, cols)
        .ok_or_else(|| corrupt("NanoVDB map is singular or not finite"))
}

/// Parses grid buffer `buf` (exactly `GridData::mGridSize` bytes) into a grid named `name`.
pub fn parse_grid(buf: &[u8], name: String) -> KindResult<Grid> {
    let b = Buf(buf);
    let header = read_header(buf)?;
    if header.grid_size != buf.len() as u64 {
        return Err(corrupt(format!(
            "grid says it is {} bytes, its buffer has {}",
            header.grid_size,
            buf.len()
        )));
    }
    let type_name = layout::grid_type_name(header.grid_type);
    let lay = Layout::of(header.grid_type)
        .ok_or_else(|| unsupported(format!("NanoVDB grid type {type_name}")))?;
    let transform = read_transform(b)?;
    let class = grid_class(header.grid_class);
    let tree_at = layout::GRID_DATA_SIZE;
    let voxel_count = b.u64(tree_at + layout::tree::VOXEL_COUNT, "voxel count")?;
    let tree = build_tree(b, &lay)?;
    let metadata = vec![
        (
            "class".to_string(),
            MetaValue::String(class.name().to_string()),
        ),
        (
            "nanovdb_version".to_string(),
            MetaValue::String(version_string(header.version)),
        ),
        (
            "nanovdb_grid_type".to_string(),
            MetaValue::String(type_name),
        ),
        (
            "file_voxel_count".to_string(),
            MetaValue::Int64(voxel_count as i64),
        ),
    ];
    Ok(Grid {
        name,
        class,
        transform,
        metadata,
        tree,
        half_float: lay.quantised,
    })
}
