//! The `.cbrk` file: a converted volume, loadable by memory map without a
//! copy and without re-deriving anything.
//!
//! ```text
//! offset 0   header, 1024 bytes, little-endian:
//!            magic "CIRRUSBK" | u32 version (1) | u32 precision (0 f32, 1 f16, 2 u8)
//!            | i32[3] origin | u32[3] dims | u32 level count
//!            | f64[16] index-to-world (column-major)
//!            | u64 active voxels, bricks stored, constant, empty, sanitised | f32 max error
//!            | u32 crc32 of the whole file with this field zeroed
//!            | section table: SECTIONS x (u64 offset, u64 byte length)
//!            | u32[3] dims per level (MAX_LEVELS of them)
//! then       the sections, each starting on a 64-byte boundary:
//!            grid name (utf-8), brick map (u32), constants (f32), u8 ranges (f32),
//!            voxel atlas (f32, u16 or u8), then one (min, max) f32 section per level
//! ```
//! Sections start 64-byte aligned and the map itself is page-aligned, so
//! each casts in place to its element type. Loading checks the magic, the
//! version, the checksum, every section's bounds and size against the
//! dimensions, and every brick reference against the tables: a corrupt or
//! truncated file is an error, never a panic.

use crate::bounds::{BoundsLevel, CELL_LOG2, MAX_LEVELS};
use crate::layout::{BrickRef, Precision};
use crate::section::Section;
use crate::volume::{Atlas, BrickVolume, SourceInfo};
use crate::BrickError;
use glam::{DMat4, IVec3};
use std::io::Write;
use std::path::Path;
use std::sync::Arc;

pub const MAGIC: &[u8; 8] = b"CIRRUSBK";
pub const VERSION: u32 = 1;
const HEADER: usize = 1024;
const ALIGN: usize = 64;
/// name, map, constants, ranges, atlas, then one per level.
const SECTIONS: usize = 5 + MAX_LEVELS;
const CRC_AT: usize = 8 + 4 + 4 + 12 + 12 + 4 + 128 + 5 * 8 + 4;
const TABLE_AT: usize = CRC_AT + 4;
const LEVEL_DIMS_AT: usize = TABLE_AT + SECTIONS * 16;
const _: () = assert!(LEVEL_DIMS_AT + MAX_LEVELS * 12 <= HEADER);

fn err(path: &Path, msg: impl Into<String>) -> BrickError {
    BrickError::File {
        path: path.to_path_buf(),
        msg: msg.into(),
    }
}

/// Writes `volume` to `path`, whole or not at all (a temporary file in the
/// same folder, renamed into place). The sections go to the file from
/// where they lie, never copied into one buffer: writing a volume costs no
/// memory beside it.
pub fn write_cbrk(volume: &BrickVolume, path: &Path) -> Result<(), BrickError> {
    let (header, sections) = encode(volume);
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let tmp = dir.join(format!(
        ".{}.tmp{}",
        path.file_name().and_then(|n| n.to_str()).unwrap_or("out"),
        std::process::id()
    ));
    let io = |e: std::io::Error| err(path, e.to_string());
    let result = (|| {
        let mut f = std::io::BufWriter::with_capacity(1 << 20, std::fs::File::create(&tmp)?);
        f.write_all(&header)?;
        let mut at = HEADER;
        for (s, offset) in &sections {
            f.write_all(&vec![0u8; offset - at])?;
            f.write_all(s)?;
            at = offset + s.len();
        }
        f.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(io)
}

/// The header (checksum included) and each section with its offset.
fn encode(v: &BrickVolume) -> (Vec<u8>, Vec<(&[u8], usize)>) {
    let mut sections: Vec<&[u8]> = vec![
        v.info.grid_name.as_bytes(),
        bytemuck::cast_slice(&v.map),
        bytemuck::cast_slice(&v.constants),
        bytemuck::cast_slice(&v.ranges),
        match &v.atlas {
            Atlas::F32(a) => bytemuck::cast_slice(a),
            Atlas::F16(a) => bytemuck::cast_slice(a),
            Atlas::U8(a) => a,
        },
    ];
    sections.extend(
        v.levels
            .iter()
            .map(|l| bytemuck::cast_slice::<f32, u8>(&l.cells)),
    );
    let mut h = Vec::with_capacity(HEADER);
    h.extend_from_slice(MAGIC);
    h.extend(VERSION.to_le_bytes());
    h.extend(v.precision().code().to_le_bytes());
    v.origin
        .to_array()
        .iter()
        .for_each(|x| h.extend(x.to_le_bytes()));
    v.dims.iter().for_each(|x| h.extend(x.to_le_bytes()));
    h.extend((v.levels.len() as u32).to_le_bytes());
    v.index_to_world
        .to_cols_array()
        .iter()
        .for_each(|x| h.extend(x.to_le_bytes()));
    let i = &v.info;
    for x in [
        i.active_voxels,
        i.bricks_stored,
        i.bricks_constant,
        i.bricks_empty,
        i.sanitized_voxels,
    ] {
        h.extend(x.to_le_bytes());
    }
    h.extend(i.max_error.to_le_bytes());
    debug_assert_eq!(h.len(), CRC_AT);
    h.extend([0u8; 4]);
    let mut offset = HEADER;
    let mut placed = Vec::new();
    for k in 0..SECTIONS {
        let len = sections.get(k).map_or(0, |s| s.len());
        offset = offset.next_multiple_of(ALIGN);
        h.extend((offset as u64).to_le_bytes());
        h.extend((len as u64).to_le_bytes());
        placed.push(offset);
        offset += len;
    }
    for k in 0..MAX_LEVELS {
        let dims = v.levels.get(k).map_or([0; 3], |l| l.dims);
        dims.iter().for_each(|x| h.extend(x.to_le_bytes()));
    }
    h.resize(HEADER, 0);
    // The checksum covers the file as written, padding included.
    let mut crc = crc32fast::Hasher::new();
    crc.update(&h);
    let mut at = HEADER;
    let mut placed: Vec<(&[u8], usize)> = sections.into_iter().zip(placed).collect();
    // The file ends where the last (possibly empty) section would start.
    placed.push((&[], offset));
    for &(s, offset) in &placed {
        crc.update(&vec![0u8; offset - at]);
        crc.update(s);
        at = offset + s.len();
    }
    h[CRC_AT..CRC_AT + 4].copy_from_slice(&crc.finalize().to_le_bytes());
    (h, placed)
}

/// Little-endian field reader over the header (bounds already checked).
struct Fields<'a>(&'a [u8], usize);
impl Fields<'_> {
    fn u32(&mut self) -> u32 {
        self.1 += 4;
        u32::from_le_bytes(self.0[self.1 - 4..self.1].try_into().unwrap())
    }
    fn u64(&mut self) -> u64 {
        self.1 += 8;
        u64::from_le_bytes(self.0[self.1 - 8..self.1].try_into().unwrap())
    }
    fn f64(&mut self) -> f64 {
        f64::from_bits(self.u64())
    }
}

/// Loads a `.cbrk` by memory map; the volume's data stays in the map.
pub fn read_cbrk(path: &Path) -> Result<BrickVolume, BrickError> {
    let map = map_checked(path)?;
    let header = Header::read(&map, path)?;
    let map = Arc::new(map);
    let mut f = Fields(&map, TABLE_AT);
    let mut table = Vec::new();
    for k in 0..SECTIONS {
        let (off, len) = (f.u64(), f.u64());
        let end = off.checked_add(len).filter(|&e| e <= map.len() as u64);
        if end.is_none() || off % ALIGN as u64 != 0 {
            return Err(err(
                path,
                format!("section {k} [{off}, +{len}) lies outside the file or is misaligned"),
            ));
        }
        table.push((off as usize, len as usize));
    }
    sections(header, &map, &table, path)
}

/// The file mapped, its length, magic, version and checksum checked.
fn map_checked(path: &Path) -> Result<memmap2::Mmap, BrickError> {
    let file = std::fs::File::open(path).map_err(|e| err(path, e.to_string()))?;
    // SAFETY: the map is read-only; like every reader of a mapped file we
    // rely on no other process truncating or rewriting it while it is open
    // (cirrus itself only ever replaces .cbrk files by rename, which leaves
    // an open map intact).
    let map = unsafe { memmap2::Mmap::map(&file) }.map_err(|e| err(path, e.to_string()))?;
    if map.len() < HEADER {
        return Err(err(
            path,
            format!(
                "file of {} bytes is shorter than the {HEADER}-byte header",
                map.len()
            ),
        ));
    }
    if &map[..8] != MAGIC {
        return Err(err(path, "not a cirrus brick file (bad magic)"));
    }
    let version = Fields(&map, 8).u32();
    if version != VERSION {
        return Err(err(
            path,
            format!("brick file version {version}, this build reads {VERSION}"),
        ));
    }
    let stored_crc = u32::from_le_bytes(map[CRC_AT..CRC_AT + 4].try_into().unwrap());
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&map[..CRC_AT]);
    hasher.update(&[0u8; 4]);
    hasher.update(&map[CRC_AT + 4..]);
    if hasher.finalize() != stored_crc {
        return Err(err(
            path,
            "checksum mismatch: the file is corrupt or truncated",
        ));
    }
    Ok(map)
}

/// The header's fixed fields, checked.
struct Header {
    precision: Precision,
    origin: IVec3,
    dims: [u32; 3],
    level_count: usize,
    index_to_world: DMat4,
    info: SourceInfo,
}

impl Header {
    fn read(map: &[u8], path: &Path) -> Result<Self, BrickError> {
        let mut f = Fields(map, 12);
        let precision =
            Precision::from_code(f.u32()).ok_or_else(|| err(path, "unknown precision code"))?;
        let origin = IVec3::new(f.u32() as i32, f.u32() as i32, f.u32() as i32);
        let dims = [f.u32(), f.u32(), f.u32()];
        let level_count = f.u32() as usize;
        let mut m = [0f64; 16];
        m.iter_mut().for_each(|x| *x = f.f64());
        let mut info = SourceInfo {
            active_voxels: f.u64(),
            bricks_stored: f.u64(),
            bricks_constant: f.u64(),
            bricks_empty: f.u64(),
            sanitized_voxels: f.u64(),
            ..Default::default()
        };
        info.max_error = f32::from_bits(f.u32());
        if level_count > MAX_LEVELS {
            return Err(err(
                path,
                format!("{level_count} levels (at most {MAX_LEVELS})"),
            ));
        }
        let index_to_world = DMat4::from_cols_array(&m);
        if !m.iter().all(|x| x.is_finite()) || index_to_world.determinant() == 0.0 {
            return Err(err(path, "transform is singular or not finite"));
        }
        Ok(Self {
            precision,
            origin,
            dims,
            level_count,
            index_to_world,
            info,
        })
    }
}

/// Section `(offset, len)` of the map as `count` values of `T`.
fn section<T: bytemuck::Pod>(
    map: &Arc<memmap2::Mmap>,
    (offset, len): (usize, usize),
    count: usize,
    what: &str,
    path: &Path,
) -> Result<Section<T>, BrickError> {
    if len != count.saturating_mul(std::mem::size_of::<T>()) {
        return Err(err(
            path,
            format!("{what} holds {len} bytes, expected {count} values"),
        ));
    }
    Ok(Section::mapped(map.clone(), offset, len))
}

/// The volume over the map's sections (`table`), each checked against
/// the header: sizes, brick references, the bounds levels' dims.
fn sections(
    header: Header,
    map: &Arc<memmap2::Mmap>,
    table: &[(usize, usize)],
    path: &Path,
) -> Result<BrickVolume, BrickError> {
    let Header {
        precision,
        origin,
        dims,
        level_count,
        index_to_world,
        mut info,
    } = header;
    let mut f = Fields(map, LEVEL_DIMS_AT);
    let level_dims: Vec<[u32; 3]> = (0..MAX_LEVELS)
        .map(|_| [f.u32(), f.u32(), f.u32()])
        .collect();
    let bricks = dims
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d as usize))
        .ok_or_else(|| err(path, "dims overflow"))?;
    info.grid_name =
        String::from_utf8_lossy(&map[table[0].0..table[0].0 + table[0].1]).into_owned();
    let map_s: Section<u32> = section(map, table[1], bricks, "brick map", path)?;
    let elem = precision.bytes_per_voxel();
    let stored = table[4].1 / (512 * elem);
    let constants: Section<f32> = section(map, table[2], table[2].1 / 4, "constants", path)?;
    let range_count = if precision == Precision::U8 {
        2 * stored
    } else {
        0
    };
    let ranges: Section<f32> = section(map, table[3], range_count, "ranges", path)?;
    let atlas = match precision {
        Precision::F32 => Atlas::F32(section(map, table[4], stored * 512, "atlas", path)?),
        Precision::F16 => Atlas::F16(section(map, table[4], stored * 512, "atlas", path)?),
        Precision::U8 => Atlas::U8(section(map, table[4], stored * 512, "atlas", path)?),
    };
    for &bits in map_s.iter() {
        let ok = match BrickRef::decode(bits) {
            BrickRef::Empty => true,
            BrickRef::Constant(k) => (k as usize) < constants.len(),
            BrickRef::Stored(b) => (b as usize) < stored,
        };
        if !ok {
            return Err(err(path, "a brick refers past the end of its table"));
        }
    }
    let mut levels = Vec::new();
    let mut expect = dims.map(|d| d << (crate::layout::BRICK_LOG2 - CELL_LOG2));
    for (k, &ld) in level_dims.iter().enumerate().take(level_count) {
        if ld != expect {
            return Err(err(
                path,
                format!("level {k} has dims {ld:?}, expected {expect:?}"),
            ));
        }
        let cells = ld.iter().map(|&d| d as usize).product::<usize>();
        levels.push(BoundsLevel {
            dims: ld,
            cells: section(map, table[5 + k], 2 * cells, "bounds level", path)?,
        });
        expect = ld.map(|d| d.div_ceil(2));
    }
    Ok(BrickVolume {
        origin,
        dims,
        index_to_world,
        map: map_s,
        constants,
        ranges,
        atlas,
        levels,
        info,
        finest_partition: Default::default(),
    })
}
