//! The NanoVDB file format (`.nvdb`), major version 32.
//!
//! A file is a sequence of records read until the end of the file:
//!
//! ```text
//! segment:  FileHeader    u64 magic "NanoVDB0" or "NanoVDB2" | u32 version | u16 grid count | u16 codec
//!           grid count x  FileMetaData (176 bytes: u64 grid size, u64 file size, u64 name hash,
//!                         u64 voxel count, u32 type, u32 class, world bbox, index bbox, voxel
//!                         size, u32 name size, node and tile counts, u16 codec, u16 pad, u32 version)
//!                         then the name (name size bytes, NUL included)
//!           grid count x  the grid buffer as the codec frames it:
//!                         NONE   the buffer itself (grid size bytes)
//!                         ZIP    u64 n, then n bytes of one zlib stream
//!                         BLOSC  per 1 GiB of buffer: u64 n, then an n-byte blosc chunk
//! raw grid: a bare grid buffer, magic "NanoVDB0" or "NanoVDB1" (files written from
//!           a grid handle since NanoVDB 32.6)
//! ```
//!
//! A grid buffer is `GridData` (672 bytes), `TreeData` (64), then the root,
//! upper and lower internal nodes and leaves, found through byte offsets;
//! `grid.rs` decodes it and `layout.rs` holds the offsets per grid type.
//!
//! Versions. NanoVDB ties its ABI, and so its file layout, to the major
//! version, and reads any 32.x file (`Version::isCompatible` compares only the
//! major number); this reader does the same. Within 32.x what changed is the
//! magic: writers before 32.6 use "NanoVDB0" for segments and grids; 32.6 and
//! later use "NanoVDB0" too or, built with `NANOVDB_USE_NEW_MAGIC_NUMBERS`,
//! "NanoVDB2" for segments and "NanoVDB1" for grids, and can also write raw
//! grid buffers as files. All of these are read. Other major versions (29.x
//! and other pre-32 files also start with "NanoVDB0", with another layout) are
//! refused as unsupported, naming the version.
//!
//! Verified against: the NanoVDB 32.4.2 headers installed by Debian
//! (`NanoVDB.h`, `util/IO.h`; struct offsets printed with `offsetof`), files
//! written by its `nanovdb_convert` and `io::writeGrids` and values read by
//! its accessor (tests/fixtures/README.md), and the published newer
//! definitions in the OpenVDB repository: `FileHeader`, `FileMetaData` and the
//! raw-buffer reader of 32.7 (`nanovdb/nanovdb/NanoVDB.h`, `io/IO.h`), and the
//! node offset tables of `PNanoVDB.h` 32.9, equal to 32.4.2's for every type
//! read here. No 32.6+ writer was run: the "NanoVDB2"/"NanoVDB1" and raw-buffer
//! tests rewrite 32.4.2 files into those layouts.
//!
//! Grid types read: Float, Double, Int32, Int64, Vec3f, Vec3d, Boolean, Mask,
//! and the quantised Fp4, Fp8, Fp16 and FpN (widened to f32, `half_float`
//! set). Others (Half, Int16, UInt32, UInt8, RGBA8, Vec4f/d, index and point
//! grids) are listed but refused on read with the type's name.

mod buf;
mod grid;
mod layout;
mod walk;

use crate::error::{corrupt, unsupported, ErrorKind, KindResult};
use crate::grid::{Grid, GridInfo};
use crate::source::FileSource;
use buf::Buf;
use grid::{version_parts, version_string};
use layout::{FILE_HEADER_SIZE, FILE_META_SIZE, GRID_DATA_SIZE, TREE_DATA_SIZE};
use std::collections::HashMap;

/// The first eight bytes of a NanoVDB file: "NanoVDB0" (segments and grids,
/// every 32.x version), "NanoVDB1" (a raw grid buffer, 32.6+) and "NanoVDB2"
/// (segments, 32.6+ with the new magic numbers).
pub const MAGICS: [&[u8; 8]; 3] = [b"NanoVDB0", b"NanoVDB1", b"NanoVDB2"];

/// `io::Internal::MAX_SIZE`: blosc frames a buffer in chunks of at most 1 GiB.
const BLOSC_CHUNK: u64 = 1 << 30;
/// A grid buffer this many times larger than its compressed bytes cannot be
/// real (zlib peaks near 1032:1, LZ4 near 255:1), so it is refused before
/// anything is allocated for it.
const MAX_RATIO: u64 = 1100;
const MIN_GRID_SIZE: u64 = (GRID_DATA_SIZE + TREE_DATA_SIZE) as u64;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Codec {
    /// A grid buffer stored bare, in a segment or as a raw-buffer file.
    None,
    Zip,
    Blosc,
    Other(u16),
}

/// Where one grid's bytes sit in the file and how they are framed.
#[derive(Clone, Debug)]
struct GridLoc {
    data_pos: u64,
    /// Bytes of the file the framed grid occupies.
    file_size: u64,
    /// Bytes of the decoded grid buffer.
    grid_size: u64,
    codec: Codec,
}

/// The grids of a NanoVDB file and where each one's data sits.
#[derive(Clone, Debug)]
pub struct NanoIndex {
    pub grids: Vec<GridInfo>,
    locs: Vec<GridLoc>,
}

fn grid_info(name: String, grid_type: u32, byte_len: u64) -> GridInfo {
    let lay = layout::Layout::of(grid_type);
    GridInfo {
        unique_name: name.clone(),
        name,
        type_name: layout::grid_type_name(grid_type),
        value_type: lay.map(|l| l.value_type),
        half_float: lay.is_some_and(|l| l.quantised),
        byte_len,
    }
}

impl NanoIndex {
    /// Reads every segment header, grid metadata and name (or, for raw grid
    /// buffers, each `GridData`), skipping the grid data, to the end of the file.
    pub fn open(src: &FileSource) -> KindResult<NanoIndex> {
        let len = src.len();
        let (mut grids, mut locs) = (Vec::new(), Vec::new());
        let mut pos = 0u64;
        while pos < len {
            let head = src.read_window(pos, 24, "NanoVDB header")?;
            if head.len() < FILE_HEADER_SIZE {
                return Err(ErrorKind::Truncated {
                    what: "NanoVDB segment header",
                    offset: pos,
                    needed: FILE_HEADER_SIZE as u64,
                    available: head.len() as u64,
                });
            }
            let magic = &head[..8];
            if !MAGICS.iter().any(|m| magic == m.as_slice()) {
                return Err(corrupt(format!(
                    "no NanoVDB segment at byte {pos} (found {magic:02x?})"
                )));
            }
            let word = |at: usize| {
                head.get(at..at + 4)
                    .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            };
            let segment_version = word(8).unwrap_or(0);
            let grid_version = word(16).unwrap_or(0);
            // "NanoVDB0" starts both segments and raw grids: a segment has its
            // version at byte 8 and its codec at 14, a grid has its checksum at
            // 8..16 and its version at 16. Should both versions read as 32.x,
            // a codec that no writer uses says the bytes are a checksum.
            let grid_magic = magic == b"NanoVDB1";
            let version = if grid_magic {
                grid_version
            } else {
                segment_version
            };
            let codec = u16::from_le_bytes([head[14], head[15]]);
            let segment = !grid_magic && version_parts(segment_version).0 == 32;
            let raw = magic != b"NanoVDB2" && version_parts(grid_version).0 == 32;
            if segment && (!raw || codec < 3) {
                pos = read_segment(src, pos, &mut grids, &mut locs)?;
            } else if raw {
                pos = read_raw_grid(src, pos, &mut grids, &mut locs)?;
            } else {
                return Err(unsupported(format!(
                    "NanoVDB file version {} at byte {pos} (only major version 32 is read)",
                    version_string(version)
                )));
            }
        }
        // As OpenVDB does, tell duplicate names apart with a record separator and a counter.
        let mut count: HashMap<String, usize> = HashMap::new();
        for g in &grids {
            *count.entry(g.name.clone()).or_default() += 1;
        }
        let mut seen: HashMap<String, usize> = HashMap::new();
        for g in &mut grids {
            if count[&g.name] > 1 {
                let k = seen.entry(g.name.clone()).or_default();
                g.unique_name = format!("{}\u{1e}{}", g.name, k);
                *k += 1;
            }
        }
        Ok(NanoIndex { grids, locs })
    }

    /// Reads and decodes grid `index`, reading only that grid's bytes.
    pub fn read_grid(&self, src: &FileSource, index: usize) -> KindResult<Grid> {
        let (info, loc) = (&self.grids[index], &self.locs[index]);
        let buffer = match loc.codec {
            Codec::None => src.read_at(loc.data_pos, loc.grid_size, "grid buffer")?,
            Codec::Zip => inflate(&src.read_at(loc.data_pos, loc.file_size, "zip grid")?, loc)?,
            Codec::Blosc => unblosc(
                &src.read_at(loc.data_pos, loc.file_size, "blosc grid")?,
                loc,
            )?,
            Codec::Other(c) => return Err(unsupported(format!("NanoVDB codec {c}"))),
        };
        let header = grid::read_header(&buffer)?;
        if layout::grid_type_name(header.grid_type) != info.type_name {
            return Err(corrupt(format!(
                "grid is of type {}, its file metadata says {}",
                layout::grid_type_name(header.grid_type),
                info.type_name
            )));
        }
        grid::parse_grid(&buffer, info.name.clone())
    }
}

/// Reads one segment's header and metadata at `pos`; returns where the next record starts.
fn read_segment(
    src: &FileSource,
    pos: u64,
    grids: &mut Vec<GridInfo>,
    locs: &mut Vec<GridLoc>,
) -> KindResult<u64> {
    let head = src.read_at(pos, FILE_HEADER_SIZE as u64, "NanoVDB segment header")?;
    let count = u16::from_le_bytes([head[12], head[13]]);
    let codec = match u16::from_le_bytes([head[14], head[15]]) {
        0 => Codec::None,
        1 => Codec::Zip,
        2 => Codec::Blosc,
        c => Codec::Other(c),
    };
    let mut at = pos + FILE_HEADER_SIZE as u64;
    let mut metas = Vec::new();
    for _ in 0..count {
        let meta = src.read_at(at, FILE_META_SIZE as u64, "NanoVDB grid metadata")?;
        let m = Buf(&meta);
        let name_size = m.u32(136, "name size")? as u64;
        let name = src.read_at(at + FILE_META_SIZE as u64, name_size, "NanoVDB grid name")?;
        let name = &name[..name.iter().position(|&c| c == 0).unwrap_or(name.len())];
        metas.push((
            m.u64(0, "grid size")?,
            m.u64(8, "file size")?,
            m.u32(32, "grid type")?,
            String::from_utf8_lossy(name).into_owned(),
        ));
        at += FILE_META_SIZE as u64 + name_size;
    }
    for (grid_size, file_size, grid_type, name) in metas {
        let end = at
            .checked_add(file_size)
            .filter(|&e| e <= src.len())
            .ok_or(ErrorKind::Truncated {
                what: "NanoVDB grid",
                offset: at,
                needed: file_size,
                available: src.len().saturating_sub(at),
            })?;
        let limit = if codec == Codec::None {
            file_size
        } else {
            file_size.saturating_mul(MAX_RATIO)
        };
        if grid_size < MIN_GRID_SIZE || grid_size > limit {
            return Err(corrupt(format!(
                "grid {name:?} claims {grid_size} bytes from {file_size} bytes of file"
            )));
        }
        grids.push(grid_info(name, grid_type, file_size));
        locs.push(GridLoc {
            data_pos: at,
            file_size,
            grid_size,
            codec,
        });
        at = end;
    }
    Ok(at)
}

/// Reads the `GridData` of a bare grid buffer at `pos`; returns where the next record starts.
fn read_raw_grid(
    src: &FileSource,
    pos: u64,
    grids: &mut Vec<GridInfo>,
    locs: &mut Vec<GridLoc>,
) -> KindResult<u64> {
    let head = src.read_at(pos, GRID_DATA_SIZE as u64, "grid header")?;
    let h = grid::read_header(&head)?;
    let end = pos.checked_add(h.grid_size).filter(|&e| e <= src.len());
    let end = end.ok_or(ErrorKind::Truncated {
        what: "NanoVDB grid",
        offset: pos,
        needed: h.grid_size,
        available: src.len() - pos,
    })?;
    if h.grid_size < MIN_GRID_SIZE {
        return Err(corrupt(format!(
            "grid {:?} claims only {} bytes",
            h.name, h.grid_size
        )));
    }
    grids.push(grid_info(h.name, h.grid_type, h.grid_size));
    locs.push(GridLoc {
        data_pos: pos,
        file_size: h.grid_size,
        grid_size: h.grid_size,
        codec: Codec::None,
    });
    Ok(end)
}

/// The u64 size prefix of a framed stream at `at`, and the stream it frames.
fn framed<'a>(bytes: &'a [u8], at: usize, what: &str) -> KindResult<&'a [u8]> {
    let size = bytes
        .get(at..at + 8)
        .map(|b| u64::from_le_bytes(b.try_into().unwrap()))
        .ok_or_else(|| corrupt(format!("{what} size runs past the grid's bytes")))?;
    usize::try_from(size)
        .ok()
        .and_then(|n| bytes.get(at + 8..(at + 8).checked_add(n)?))
        .ok_or_else(|| {
            corrupt(format!(
                "{what} of {size} bytes runs past the grid's {} bytes",
                bytes.len()
            ))
        })
}

/// ZIP: one zlib stream that must inflate to exactly the grid size.
fn inflate(bytes: &[u8], loc: &GridLoc) -> KindResult<Vec<u8>> {
    use std::io::Read;
    let stream = framed(bytes, 0, "zip stream")?;
    let mut out = vec![0u8; loc.grid_size as usize];
    let mut z = flate2::read::ZlibDecoder::new(stream);
    z.read_exact(&mut out)
        .map_err(|e| corrupt(format!("zip grid of {} bytes: {e}", loc.grid_size)))?;
    let mut extra = [0u8; 1];
    if z.read(&mut extra)
        .map_err(|e| corrupt(format!("zip grid: {e}")))?
        != 0
    {
        return Err(corrupt(format!(
            "zip grid inflates to more than its {} bytes",
            loc.grid_size
        )));
    }
    Ok(out)
}

/// BLOSC: chunks of at most 1 GiB of buffer, each size-prefixed.
fn unblosc(bytes: &[u8], loc: &GridLoc) -> KindResult<Vec<u8>> {
    let mut out = vec![0u8; loc.grid_size as usize];
    let (mut done, mut at) = (0usize, 0usize);
    while done < out.len() {
        let chunk = framed(bytes, at, "blosc chunk")?;
        let n = (out.len() - done).min(BLOSC_CHUNK as usize);
        crate::openvdb::blosc::decompress(chunk, &mut out[done..done + n])?;
        done += n;
        at += 8 + chunk.len();
    }
    Ok(out)
}
