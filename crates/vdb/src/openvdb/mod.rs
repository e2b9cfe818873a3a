//! The OpenVDB file format (`.vdb`, file versions 222 to 224).
//!
//! Layout, from `io/Archive`, `io/File` and `io/GridDescriptor` of OpenVDB:
//!
//! ```text
//! header:   i64 magic 0x56444220 | u32 file version | u32 u32 library version
//!           | u8 has grid offsets | 36-byte ASCII UUID
//! metadata: u32 count, then per entry: string name, string type, u32 size, bytes
//! grids:    u32 count, then per grid:
//!             descriptor: string unique name, string type name ("_HalfFloat" suffix
//!                         = values stored as half), string instance parent,
//!                         i64 grid offset, i64 block offset, i64 end offset
//!             grid:       u32 compression, metadata, transform, topology, buffers
//! ```
//! The next descriptor starts at the previous grid's end offset, so listing
//! the grids reads only descriptors, and reading one grid reads only its range.

pub(crate) mod blosc;
mod compression;
pub mod stream;
mod tree_reader;
mod window;

use crate::bytes::ByteCursor;
use crate::error::{corrupt, unsupported, ErrorKind, KindResult};
use crate::grid::{Grid, GridClass, GridInfo, GridTree};
use crate::metadata::{meta_get, MetaMap, MetaValue};
use crate::source::FileSource;
use crate::transform::{MapKind, Transform};
use crate::ValueType;
use glam::{DMat4, DVec3};
use tree_reader::{read_tree, LeafKind};

pub const MAGIC: [u8; 8] = [0x20, 0x42, 0x44, 0x56, 0, 0, 0, 0];
/// Oldest version read: node-mask compression (222) changed the node layout.
const MIN_VERSION: u32 = 222;
const HALF_SUFFIX: &str = "_HalfFloat";

/// Where one grid sits in the file.
#[derive(Clone, Debug)]
pub struct GridEntry {
    pub info: GridInfo,
    pub instance_parent: String,
    grid_pos: u64,
    end_pos: u64,
}

/// The header and grid index of an OpenVDB file.
#[derive(Clone, Debug)]
pub struct Archive {
    pub file_version: u32,
    pub library_version: (u32, u32),
    pub metadata: MetaMap,
    pub grids: Vec<GridEntry>,
}

pub fn read_meta_map(cur: &mut ByteCursor) -> KindResult<MetaMap> {
    let count = cur.u32("metadata count")?;
    // Each entry has at least three u32 lengths.
    cur.ensure(count as u64, 12, "metadata entries")?;
    let mut map = Vec::with_capacity(count as usize);
    for _ in 0..count {
        let name = cur.string("metadata name")?;
        let type_name = cur.string("metadata type")?;
        let size = cur.u32("metadata size")? as usize;
        let bytes = cur.take(size, "metadata value")?;
        map.push((name, MetaValue::decode(&type_name, bytes)));
    }
    Ok(map)
}

impl Archive {
    /// Reads the header, file metadata and every grid descriptor.
    pub fn open(src: &FileSource) -> KindResult<Archive> {
        let ((file_version, library_version, metadata, count), used) =
            src.parse_at(0, "file header", |cur| {
                let magic = cur.array::<8>("magic")?;
                if magic != MAGIC {
                    return Err(ErrorKind::BadMagic(magic.to_vec()));
                }
                let version = cur.u32("file version")?;
                if version < MIN_VERSION {
                    return Err(unsupported(format!(
                        "OpenVDB file version {version} (older than {MIN_VERSION})"
                    )));
                }
                let lib = (cur.u32("library version")?, cur.u32("library version")?);
                let has_offsets = cur.u8("grid offsets flag")? != 0;
                if !has_offsets {
                    return Err(unsupported("stream-written file without grid offsets"));
                }
                cur.skip(36, "uuid")?;
                let meta = read_meta_map(cur)?;
                let count = cur.i32("grid count")?;
                Ok((version, lib, meta, count))
            })?;
        if count < 0 {
            return Err(corrupt(format!("negative grid count {count}")));
        }
        let mut grids = Vec::new();
        let mut pos = used;
        for i in 0..count {
            let (entry, _) = src.parse_at(pos, "grid descriptor", |cur| {
                read_descriptor(cur, src.len())
            })?;
            if entry.grid_pos < pos || entry.end_pos <= entry.grid_pos {
                return Err(corrupt(format!(
                    "grid descriptor {i} has offsets out of order"
                )));
            }
            pos = entry.end_pos;
            grids.push(entry);
        }
        Ok(Archive {
            file_version,
            library_version,
            metadata,
            grids,
        })
    }

    /// The index of the grid whose tree instance `entry` shares: the
    /// non-instance grid named by its `instance_parent`.
    pub(crate) fn instance_parent(&self, entry: &GridEntry) -> KindResult<usize> {
        self.grids
            .iter()
            .position(|g| {
                g.info.unique_name == entry.instance_parent && g.instance_parent.is_empty()
            })
            .ok_or_else(|| {
                corrupt(format!(
                    "instance of missing grid {:?}",
                    entry.instance_parent
                ))
            })
    }

    /// Reads grid `index`: its metadata, transform and tree.
    pub fn read_grid(&self, src: &FileSource, index: usize) -> KindResult<Grid> {
        let entry = &self.grids[index];
        let bytes = src.read_at(entry.grid_pos, entry.end_pos - entry.grid_pos, "grid data")?;
        let mut cur = ByteCursor::new(&bytes, entry.grid_pos);
        let compression = cur.u32("grid compression")?;
        let metadata = read_meta_map(&mut cur)?;
        let transform = read_transform(&mut cur)?;
        let class = meta_get(&metadata, "class")
            .and_then(|v| v.as_str())
            .map_or(GridClass::Unknown, GridClass::from_name);
        let tree = if entry.instance_parent.is_empty() {
            let vt = entry
                .info
                .value_type
                .ok_or_else(|| unsupported(format!("grid type {}", entry.info.type_name)))?;
            read_grid_tree(&mut cur, vt, compression, entry.info.half_float)?
        } else {
            // An instance shares its parent's tree; its own record stops after the transform.
            self.read_grid(src, self.instance_parent(entry)?)?.tree
        };
        Ok(Grid {
            name: entry.info.name.clone(),
            class,
            transform,
            metadata,
            tree,
            half_float: entry.info.half_float,
        })
    }
}

fn read_descriptor(cur: &mut ByteCursor, file_len: u64) -> KindResult<GridEntry> {
    let unique_name = cur.string("grid name")?;
    let mut type_name = cur.string("grid type")?;
    let half_float = type_name.ends_with(HALF_SUFFIX);
    if half_float {
        type_name.truncate(type_name.len() - HALF_SUFFIX.len());
    }
    let instance_parent = cur.string("instance parent")?;
    let mut offset = |what| -> KindResult<u64> {
        let v = cur.i64(what)?;
        u64::try_from(v)
            .ok()
            .filter(|&v| v <= file_len)
            .ok_or_else(|| corrupt(format!("{what} {v} lies outside the file")))
    };
    let grid_pos = offset("grid offset")?;
    let _block_pos = offset("block offset")?;
    let end_pos = offset("end offset")?;
    // OpenVDB separates a duplicate name's counter with ASCII record separator 0x1e.
    let name = unique_name.split('\u{1e}').next().unwrap_or("").to_string();
    let value_type = value_type_of(&type_name);
    Ok(GridEntry {
        info: GridInfo {
            name,
            unique_name,
            type_name,
            value_type,
            half_float,
            byte_len: end_pos.saturating_sub(grid_pos),
        },
        instance_parent,
        grid_pos,
        end_pos,
    })
}

/// Value type of an OpenVDB tree type name such as `Tree_float_5_4_3`.
fn value_type_of(type_name: &str) -> Option<ValueType> {
    let inner = type_name.strip_prefix("Tree_")?.strip_suffix("_5_4_3")?;
    Some(match inner {
        "float" => ValueType::Float,
        "double" => ValueType::Double,
        "int32" => ValueType::Int32,
        "int64" => ValueType::Int64,
        "bool" => ValueType::Bool,
        "mask" => ValueType::Mask,
        "vec3s" => ValueType::Vec3f,
        "vec3d" => ValueType::Vec3d,
        _ => return None,
    })
}

fn read_grid_tree(
    cur: &mut ByteCursor,
    vt: ValueType,
    compression: u32,
    half: bool,
) -> KindResult<GridTree> {
    use LeafKind::*;
    Ok(match vt {
        ValueType::Float => GridTree::Float(read_tree(cur, compression, half, Values)?),
        ValueType::Double => GridTree::Double(read_tree(cur, compression, half, Values)?),
        ValueType::Int32 => GridTree::Int32(read_tree(cur, compression, false, Values)?),
        ValueType::Int64 => GridTree::Int64(read_tree(cur, compression, false, Values)?),
        ValueType::Bool => GridTree::Bool(read_tree(cur, compression, false, Bool)?),
        ValueType::Mask => GridTree::Mask(read_tree(cur, compression, false, Mask)?),
        ValueType::Vec3f => GridTree::Vec3f(read_tree(cur, compression, half, Values)?),
        ValueType::Vec3d => GridTree::Vec3d(read_tree(cur, compression, half, Values)?),
    })
}

/// Reads a transform record: the map's type name, then its fields
/// (math/Maps.h, each map's `read`).
fn read_transform(cur: &mut ByteCursor) -> KindResult<Transform> {
    let name = cur.string("transform type")?;
    let kind = MapKind::from_name(&name).ok_or_else(|| unsupported(format!("transform {name}")))?;
    let t = match kind {
        MapKind::UniformScale | MapKind::Scale => {
            let scale = DVec3::from(cur.vec3d("scale")?);
            // voxel size, inverse scale, inverse scale squared, inverse twice scale: derived.
            cur.skip(4 * 24, "scale map")?;
            Transform::scale_translate(kind, scale, DVec3::ZERO)
        }
        MapKind::UniformScaleTranslate | MapKind::ScaleTranslate => {
            let translation = DVec3::from(cur.vec3d("translation")?);
            let scale = DVec3::from(cur.vec3d("scale")?);
            cur.skip(4 * 24, "scale-translate map")?;
            Transform::scale_translate(kind, scale, translation)
        }
        MapKind::Translation => {
            Transform::scale_translate(kind, DVec3::ONE, DVec3::from(cur.vec3d("translation")?))
        }
        MapKind::Affine | MapKind::Unitary => {
            let mut m = [0.0f64; 16];
            for v in m.iter_mut() {
                *v = cur.f64("affine matrix")?;
            }
            // OpenVDB stores row-major for row vectors (p' = p M, translation in
            // row 3): its rows are glam's columns.
            Transform::from_matrix(kind, DMat4::from_cols_array(&m))
        }
    };
    t.ok_or_else(|| corrupt(format!("{name} is singular or not finite")))
}
