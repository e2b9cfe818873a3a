//! Streaming a grid without building its tree: the topology in one
//! sequential pass over a sliding window of the file, then the leaf buffers
//! in chunks of a few MiB decoded in parallel and handed to a [`LeafSink`].
//!
//! What is held: the window (4 MiB, more only for a record that needs it),
//! per leaf its origin and a 32-bit fingerprint of its value mask (16
//! bytes), the active tiles, and at most `2 x threads + 1` chunks of leaf
//! buffers in flight. Nothing is allocated for a count read from the file
//! before the count is checked against the bytes left in the grid.

use super::compression::{read_compressed_values, StreamContext};
use super::window::{Window, WINDOW};
use super::{read_transform, Archive};
use crate::bytes::ByteCursor;
use crate::error::{corrupt, unsupported, Error, ErrorKind, KindResult};
use crate::grid::GridClass;
use crate::mask::BitMask;
use crate::metadata::{meta_get, MetaMap, MetaValue};
use crate::source::FileSource;
use crate::tree::{Level, NodeCounts, LEAF_TOTAL, LOWER_TOTAL, UPPER_TOTAL};
use crate::{Coord, CoordBBox, Transform, Value, ValueType};
use std::collections::HashSet;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// An active tile of any level: the box it stands for and its value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActiveTile<V> {
    pub bbox: CoordBBox,
    pub value: V,
    /// [`Level::Lower`] (8^3 tiles), [`Level::Upper`] (128^3) or [`Level::Root`] (4096^3).
    pub level: Level,
}

/// What a grid's topology says, read without any leaf values.
#[derive(Clone, Debug)]
pub struct Topology<V> {
    pub background: V,
    /// Active tiles at every level, in file order.
    pub tiles: Vec<ActiveTile<V>>,
    /// Leaf origins in file order: the order [`GridStream::decode_leaves`]
    /// hands the leaves over, and the order of [`crate::Tree::leaves`] for
    /// the same grid read whole.
    pub leaf_origins: Vec<Coord>,
    /// Active voxels, tiles counted at their full volume.
    pub active_voxels: u64,
    /// As [`crate::Tree::active_bbox`].
    pub active_bbox: Option<CoordBBox>,
    pub node_counts: NodeCounts,
}

impl<V: Value> Topology<V> {
    /// Active tiles per level, as [`crate::Tree::active_tile_counts`].
    pub fn tile_counts(&self) -> crate::tree::TileCounts {
        let mut t = crate::tree::TileCounts::default();
        for tile in &self.tiles {
            match tile.level {
                Level::Lower => t.lower += 1,
                Level::Upper => t.upper += 1,
                _ => t.root += 1,
            }
        }
        t
    }
    /// Bytes the grid's tree would occupy read whole ([`crate::Tree::memory_bytes`]).
    pub fn memory_bytes(&self) -> usize {
        crate::tree::memory_bytes::<V>(self.node_counts)
    }
}

/// Receives decoded leaves. The stream splits it into one part per chunk
/// of leaves (in file order, so a part can own the slice of an output that
/// its leaves fill) and feeds the parts from several threads.
pub trait LeafSink<V>: Send + Sized {
    type Error: Send;
    /// Splits off the part for the next `n` leaves; `self` keeps the rest.
    fn split_front(&mut self, n: usize) -> Self;
    /// Leaf `index` (its place in [`Topology::leaf_origins`]): its value
    /// mask and all 512 values, inactive ones as the file restores them.
    fn leaf(
        &mut self,
        index: usize,
        mask: &BitMask<8>,
        values: &[V; 512],
    ) -> Result<(), Self::Error>;
    /// Called once a part has received all its leaves.
    fn finish(self) {}
}

/// Why streaming leaves stopped: the file, or the sink.
#[derive(Debug)]
pub enum DecodeError<E> {
    File(Error),
    Sink(E),
}

/// A grid whose header and topology are read; its leaf buffers are next.
pub struct GridStream<'f, V> {
    src: &'f FileSource,
    pub name: String,
    pub class: GridClass,
    pub transform: Transform,
    pub metadata: MetaMap,
    pub half_float: bool,
    pub topology: Topology<V>,
    hashes: Vec<u32>,
    ctx: StreamContext<V>,
    /// Bytes after the topology already read, and where they start.
    rest: Vec<u8>,
    rest_pos: u64,
    end: u64,
}

/// A 32-bit fingerprint of a leaf's value mask: the buffers repeat the
/// topology's mask, and a leaf whose two masks differ is refused.
fn mask_hash(m: &BitMask<8>) -> u32 {
    let mut h = 0x243F_6A88_85A3_08D3u64;
    for &w in m.words() {
        h = (h ^ w).wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(29);
    }
    (h >> 32) as u32
}

/// The inclusive box of a leaf mask's on bits, relative to the leaf origin.
fn mask_extent(m: &BitMask<8>) -> Option<(Coord, Coord)> {
    let w = m.words();
    let x0 = w.iter().position(|&v| v != 0)? as i32;
    let x1 = w.iter().rposition(|&v| v != 0)? as i32;
    // Bit b of word x is (y, z) = (b >> 3, b & 7): byte y of the union.
    let all = w.iter().fold(0u64, |a, &v| a | v);
    let bytes = all.to_le_bytes();
    let y0 = bytes.iter().position(|&b| b != 0)? as i32;
    let y1 = bytes.iter().rposition(|&b| b != 0)? as i32;
    let zs = bytes.iter().fold(0u8, |a, &b| a | b);
    let z0 = zs.trailing_zeros() as i32;
    let z1 = 7 - zs.leading_zeros() as i32;
    Some((Coord::new(x0, y0, z0), Coord::new(x1, y1, z1)))
}

/// The origin of child slot `n` of a node of `2^log2` children a side.
fn slot_origin(origin: Coord, n: usize, log2: u32, child_total: u32) -> Coord {
    let m = (1usize << log2) - 1;
    let (x, y, z) = (
        (n >> (2 * log2)) as i32,
        ((n >> log2) & m) as i32,
        (n & m) as i32,
    );
    origin + Coord::new(x << child_total, y << child_total, z << child_total)
}

/// An internal node's record: child mask, value mask (child slots cleared,
/// as the reader keeps it) and the tile values.
fn internal<V: Value, const W: usize>(
    cur: &mut ByteCursor,
    ctx: &StreamContext<V>,
    scratch: &mut Vec<u8>,
) -> KindResult<(BitMask<W>, BitMask<W>, Vec<V>)> {
    let child = BitMask::<W>::from_le_bytes(cur.take(BitMask::<W>::BYTES, "child mask")?);
    let mut value = BitMask::<W>::from_le_bytes(cur.take(BitMask::<W>::BYTES, "value mask")?);
    let mut tiles = vec![ctx.background; BitMask::<W>::BITS];
    read_compressed_values(cur, ctx, &value, Some(&mut tiles), scratch)?;
    for n in child.iter_on() {
        value.set(n, false);
    }
    Ok((child, value, tiles))
}

struct TopologyBuilder<V> {
    topo: Topology<V>,
    hashes: Vec<u32>,
}

impl<V: Value> TopologyBuilder<V> {
    fn tile(&mut self, origin: Coord, total: u32, value: V, level: Level) {
        let bbox = CoordBBox::from_origin(origin, 1 << total);
        self.topo.active_voxels += bbox.volume();
        self.grow(bbox);
        self.topo.tiles.push(ActiveTile { bbox, value, level });
    }
    fn grow(&mut self, b: CoordBBox) {
        let t = &mut self.topo;
        t.active_bbox = Some(t.active_bbox.map_or(b, |a| a.union(b)));
    }
    fn leaf(&mut self, origin: Coord, mask: &BitMask<8>) {
        self.topo.active_voxels += mask.count_on() as u64;
        if let Some((lo, hi)) = mask_extent(mask) {
            self.grow(CoordBBox::new(origin + lo, origin + hi));
        }
        self.topo.leaf_origins.push(origin);
        self.hashes.push(mask_hash(mask));
    }

    /// Reads the upper internal node at `origin` with its lower nodes and
    /// their leaves' value masks, adding their tiles and leaves.
    fn upper(
        &mut self,
        win: &mut Window,
        origin: Coord,
        c: &StreamContext<V>,
        scratch: &mut Vec<u8>,
    ) -> KindResult<()> {
        let (child, value, tiles) = win.record(|cur| internal::<V, 512>(cur, c, scratch))?;
        self.topo.node_counts.upper += 1;
        for n in value.iter_on() {
            let o = slot_origin(origin, n, 5, LOWER_TOTAL);
            self.tile(o, LOWER_TOTAL, tiles[n], Level::Upper);
        }
        drop(tiles);
        let slots: Vec<usize> = child.iter_on().collect();
        win.ensure(slots.len() as u64, 2 * 512, "lower nodes")?;
        for n in slots {
            let lower_origin = slot_origin(origin, n, 5, LOWER_TOTAL);
            let (lchild, lvalue, ltiles, masks) = win.record(|cur| {
                let (child, value, tiles) = internal::<V, 64>(cur, c, scratch)?;
                let count = child.count_on() as u64;
                cur.ensure(count, 64, "leaf masks")?;
                let masks: Vec<BitMask<8>> = (0..count)
                    .map(|_| cur.take(64, "leaf value mask").map(BitMask::from_le_bytes))
                    .collect::<KindResult<_>>()?;
                Ok((child, value, tiles, masks))
            })?;
            self.topo.node_counts.lower += 1;
            for k in lvalue.iter_on() {
                let o = slot_origin(lower_origin, k, 4, LEAF_TOTAL);
                self.tile(o, LEAF_TOTAL, ltiles[k], Level::Lower);
            }
            for (k, mask) in lchild.iter_on().zip(&masks) {
                self.leaf(slot_origin(lower_origin, k, 4, LEAF_TOTAL), mask);
            }
        }
        Ok(())
    }
}

/// Reads the topology (`Tree::readTopology`) at the window's position.
fn read_topology<V: Value>(
    win: &mut Window,
    compression: u32,
    half: bool,
) -> KindResult<(Topology<V>, Vec<u32>, StreamContext<V>)> {
    let (buffer_count, background) = win.record(|cur| {
        Ok((
            cur.i32("tree buffer count")?,
            V::from_le(cur.take(V::SIZE, "background value")?),
        ))
    })?;
    if buffer_count != 1 {
        return Err(unsupported(format!("tree with {buffer_count} buffers")));
    }
    let c = StreamContext {
        compression,
        background,
        half,
    };
    let mut b = TopologyBuilder {
        topo: Topology {
            background,
            tiles: Vec::new(),
            leaf_origins: Vec::new(),
            active_voxels: 0,
            active_bbox: None,
            node_counts: NodeCounts::default(),
        },
        hashes: Vec::new(),
    };
    let (num_tiles, num_children) =
        win.record(|cur| Ok((cur.u32("root tile count")?, cur.u32("root child count")?)))?;
    win.ensure(num_tiles as u64, 12 + V::SIZE as u64 + 1, "root tiles")?;
    let mut seen = HashSet::new();
    let mut root_entry = |origin: Coord| -> KindResult<()> {
        if origin.node_origin(UPPER_TOTAL) != origin {
            return Err(corrupt(format!(
                "root entry origin {origin:?} is not a multiple of 4096"
            )));
        }
        if !seen.insert(origin) {
            return Err(corrupt(format!("two root entries at {origin:?}")));
        }
        Ok(())
    };
    for _ in 0..num_tiles {
        let (origin, value, active) = win.record(|cur| {
            Ok((
                cur.coord("root tile origin")?,
                V::from_le(cur.take(V::SIZE, "root tile value")?),
                cur.u8("root tile state")? != 0,
            ))
        })?;
        root_entry(origin)?;
        if active {
            b.tile(origin, UPPER_TOTAL, value, Level::Root);
        }
    }
    win.ensure(num_children as u64, 12 + 2 * 4096, "root children")?;
    let mut scratch = Vec::new();
    for _ in 0..num_children {
        let origin = win.record(|cur| cur.coord("root child origin"))?;
        if origin.node_origin(UPPER_TOTAL) != origin {
            return Err(corrupt(format!(
                "root child origin {origin:?} is not a multiple of 4096"
            )));
        }
        root_entry(origin)?;
        b.upper(win, origin, &c, &mut scratch)?;
    }
    b.topo.node_counts.root_entries = num_tiles as u64 + num_children as u64;
    b.topo.node_counts.leaves = b.topo.leaf_origins.len() as u64;
    Ok((b.topo, b.hashes, c))
}

/// Reads a grid record's start: compression, metadata, transform. Values
/// of metadata types the reader does not decode are skipped unread:
/// OpenVDB's `file_delayed_load` holds bytes per leaf (megabytes for a
/// large grid) that nothing here needs.
fn grid_header(win: &mut Window) -> KindResult<(u32, MetaMap, Transform)> {
    let compression = win.record(|cur| cur.u32("grid compression"))?;
    let count = win.record(|cur| cur.u32("metadata count"))?;
    // Each entry has at least three u32 lengths.
    win.ensure(count as u64, 12, "metadata entries")?;
    let mut metadata = Vec::new();
    for _ in 0..count {
        let (name, type_name, size) = win.record(|cur| {
            Ok((
                cur.string("metadata name")?,
                cur.string("metadata type")?,
                cur.u32("metadata size")? as usize,
            ))
        })?;
        let value = if MetaValue::decodes(&type_name) {
            win.record(|cur| {
                Ok(MetaValue::decode(
                    &type_name,
                    cur.take(size, "metadata value")?,
                ))
            })?
        } else {
            win.skip(size as u64, "metadata value")?;
            MetaValue::Other {
                type_name,
                len: size,
            }
        };
        metadata.push((name, value));
    }
    let transform = win.record(read_transform)?;
    Ok((compression, metadata, transform))
}

impl Archive {
    /// Reads grid `index`'s header and topology, ready to stream its leaves.
    pub fn stream_grid<'f, V: Value>(
        &self,
        src: &'f FileSource,
        index: usize,
    ) -> KindResult<GridStream<'f, V>> {
        let entry = &self.grids[index];
        let vt = entry.info.value_type;
        if vt != Some(V::VALUE_TYPE) || matches!(vt, Some(ValueType::Bool | ValueType::Mask)) {
            return Err(unsupported(format!(
                "streaming grid type {} as {} values",
                entry.info.type_name,
                V::VALUE_TYPE.name()
            )));
        }
        let mut win = Window::new(src, entry.grid_pos, entry.end_pos);
        let (mut compression, metadata, transform) = grid_header(&mut win)?;
        let mut end = entry.end_pos;
        let mut half = entry.info.half_float;
        if !entry.instance_parent.is_empty() {
            // An instance shares its parent's tree; stream the parent's record.
            let parent = &self.grids[self.instance_parent(entry)?];
            win = Window::new(src, parent.grid_pos, parent.end_pos);
            compression = grid_header(&mut win)?.0;
            end = parent.end_pos;
            half = parent.info.half_float;
        }
        let class = meta_get(&metadata, "class")
            .and_then(|v| v.as_str())
            .map_or(GridClass::Unknown, GridClass::from_name);
        let (topology, hashes, ctx) = read_topology::<V>(&mut win, compression, half)?;
        let (rest, rest_pos) = win.into_rest();
        Ok(GridStream {
            src,
            name: entry.info.name.clone(),
            class,
            transform,
            metadata,
            half_float: entry.info.half_float,
            topology,
            hashes,
            ctx,
            rest,
            rest_pos,
            end,
        })
    }

    /// Grid `index`'s metadata and transform, read from its first bytes.
    pub fn read_grid_header(
        &self,
        src: &FileSource,
        index: usize,
    ) -> KindResult<(MetaMap, Transform)> {
        let entry = &self.grids[index];
        let mut win = Window::new(src, entry.grid_pos, entry.end_pos);
        let (_, metadata, transform) = grid_header(&mut win)?;
        Ok((metadata, transform))
    }

    /// Grid `index`'s metadata, transform and background value (its
    /// tree's, for an instance), read from the few bytes before its tree.
    pub fn header_and_background<V: Value>(
        &self,
        src: &FileSource,
        index: usize,
    ) -> KindResult<(MetaMap, Transform, V)> {
        let mut entry = &self.grids[index];
        let mut win = Window::new(src, entry.grid_pos, entry.end_pos);
        let (_, metadata, transform) = grid_header(&mut win)?;
        if !entry.instance_parent.is_empty() {
            entry = &self.grids[self.instance_parent(entry)?];
            win = Window::new(src, entry.grid_pos, entry.end_pos);
            grid_header(&mut win)?;
        }
        let background = win.record(|cur| {
            cur.i32("tree buffer count")?;
            Ok(V::from_le(cur.take(V::SIZE, "background value")?))
        })?;
        Ok((metadata, transform, background))
    }
}

/// Skips one leaf buffer record: value mask, then its compressed values.
fn skip_leaf<V: Value>(cur: &mut ByteCursor, ctx: &StreamContext<V>) -> KindResult<()> {
    let mask = BitMask::<8>::from_le_bytes(cur.take(64, "leaf value mask")?);
    read_compressed_values::<V, 8>(cur, ctx, &mask, None, &mut Vec::new())
}

/// How many of the next `remaining` leaf records fit whole in `buf` (at
/// file offset `pos`), and the bytes they take; a record cut off by the
/// window's end is left for the next window where the file goes on
/// (`more`), and is an error where it does not.
fn fitting_leaves<V: Value>(
    buf: &[u8],
    pos: u64,
    ctx: &StreamContext<V>,
    remaining: usize,
    more: bool,
) -> KindResult<(usize, usize)> {
    let mut cur = ByteCursor::new(buf, pos);
    let (mut count, mut used) = (0usize, 0usize);
    while count < remaining {
        match skip_leaf(&mut cur, ctx) {
            Ok(()) => {
                count += 1;
                used = cur.position();
            }
            Err(ErrorKind::Truncated { .. }) if more => break,
            Err(kind) => return Err(kind),
        }
    }
    Ok((count, used))
}

/// The first error of a parallel decode, and whether one happened (the
/// other tasks stop at their next chunk).
struct FirstFailure<E> {
    stop: AtomicBool,
    failure: Mutex<Option<E>>,
}

impl<E> Default for FirstFailure<E> {
    fn default() -> Self {
        Self {
            stop: AtomicBool::new(false),
            failure: Mutex::new(None),
        }
    }
}

impl<E> FirstFailure<E> {
    fn record(&self, e: E) {
        self.stop.store(true, Ordering::Relaxed);
        let mut f = self.failure.lock().unwrap_or_else(|e| e.into_inner());
        if f.is_none() {
            *f = Some(e);
        }
    }

    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    fn into_inner(self) -> Option<E> {
        self.failure.into_inner().unwrap_or_else(|e| e.into_inner())
    }
}

/// What stopped a chunk's decode: its bytes, or the sink.
enum ChunkError<E> {
    File(ErrorKind),
    Sink(E),
}

/// Decodes the leaf records of `chunk` (at file offset `base`), leaves
/// `leaves` of the topology, checking each value mask against the
/// topology's fingerprint, and hands each leaf to `part`.
fn decode_chunk<V: Value, S: LeafSink<V>>(
    chunk: &[u8],
    base: u64,
    leaves: std::ops::Range<usize>,
    hashes: &[u32],
    ctx: &StreamContext<V>,
    part: &mut S,
) -> Result<(), ChunkError<S::Error>> {
    let mut cur = ByteCursor::new(chunk, base);
    let mut values = Box::new([ctx.background; 512]);
    let mut scratch = Vec::new();
    for (index, &hash) in leaves.clone().zip(&hashes[leaves]) {
        let mask =
            BitMask::<8>::from_le_bytes(cur.take(64, "leaf value mask").map_err(ChunkError::File)?);
        if mask_hash(&mask) != hash {
            return Err(ChunkError::File(corrupt(format!(
                "leaf {index}'s value mask in the buffers differs from the topology's"
            ))));
        }
        read_compressed_values(&mut cur, ctx, &mask, Some(&mut values[..]), &mut scratch)
            .map_err(ChunkError::File)?;
        part.leaf(index, &mask, &values).map_err(ChunkError::Sink)?;
    }
    Ok(())
}

impl<'f, V: Value> GridStream<'f, V> {
    pub fn path(&self) -> &std::path::Path {
        self.src.path()
    }

    /// The window of leaf buffers from `pos`: [`WINDOW`] bytes, or what
    /// is left of them.
    fn window_at(&self, pos: u64) -> KindResult<Vec<u8>> {
        let len = WINDOW.min(self.end.saturating_sub(pos));
        self.src.read_at(pos, len, "leaf buffers")
    }

    /// Decodes every leaf buffer and hands the leaves to `sink`, in chunks
    /// of about 4 MiB of file decoded in parallel (rayon). Reads the buffers
    /// once, in order; holds at most `2 x threads + 1` chunks at a time.
    pub fn decode_leaves<S: LeafSink<V>>(mut self, sink: S) -> Result<(), DecodeError<S::Error>> {
        let path = self.src.path();
        let file_err = |kind| DecodeError::File(Error::new(path, kind));
        let n_leaves = self.hashes.len();
        let limit = 2 * rayon::current_num_threads();
        let in_flight = AtomicUsize::new(0);
        let failure = FirstFailure::default();
        let fail = |e| failure.record(e);
        let (hashes, ctx) = (&self.hashes, &self.ctx);
        let decode = |chunk: &[u8], base: u64, first: usize, count: usize, mut part: S| {
            if failure.stopped() {
                return;
            }
            let leaves = first..first + count;
            match decode_chunk(chunk, base, leaves, hashes, ctx, &mut part) {
                Ok(()) => part.finish(),
                Err(ChunkError::File(kind)) => fail(file_err(kind)),
                Err(ChunkError::Sink(e)) => fail(DecodeError::Sink(e)),
            }
        };
        let mut next = 0usize;
        let mut pos = self.rest_pos;
        let mut pending = Some(std::mem::take(&mut self.rest));
        rayon::scope(|s| {
            let mut rest = sink;
            while next < n_leaves && !failure.stopped() {
                let buf = match pending.take().filter(|b| !b.is_empty()) {
                    Some(b) => b,
                    None => match self.window_at(pos) {
                        Ok(b) => b,
                        Err(kind) => return fail(file_err(kind)),
                    },
                };
                let window_end = pos + buf.len() as u64;
                let full = buf.len() as u64 >= WINDOW || window_end >= self.end;
                let more = window_end < self.end;
                let (count, used) = match fitting_leaves(&buf, pos, ctx, n_leaves - next, more) {
                    Ok(fit) => fit,
                    Err(kind) => return fail(file_err(kind)),
                };
                if count == 0 && !full {
                    // A short piece left from the topology's window: read a whole window.
                    continue;
                }
                if count == 0 {
                    // With chunk sizes bounded (read_data), a leaf record is
                    // a few KiB: one that does not fit a window is corrupt.
                    return fail(file_err(corrupt(format!(
                        "leaf buffer at offset {pos} does not fit in {WINDOW} bytes"
                    ))));
                }
                let part = rest.split_front(count);
                let (first, base) = (next, pos);
                next += count;
                pos += used as u64;
                let mut buf = buf;
                buf.truncate(used);
                if in_flight.load(Ordering::Relaxed) < limit {
                    in_flight.fetch_add(1, Ordering::Relaxed);
                    let (decode, in_flight) = (&decode, &in_flight);
                    s.spawn(move |_| {
                        decode(&buf, base, first, count, part);
                        in_flight.fetch_sub(1, Ordering::Relaxed);
                    });
                } else {
                    // Enough chunks are queued: decode this one here, which
                    // also keeps the bytes in flight bounded.
                    decode(&buf, base, first, count, part);
                }
            }
        });
        if let Some(e) = failure.into_inner() {
            return Err(e);
        }
        if next < n_leaves {
            return Err(file_err(ErrorKind::Truncated {
                what: "leaf buffers",
                offset: pos,
                needed: 64 + 1,
                available: self.end.saturating_sub(pos),
            }));
        }
        Ok(())
    }
}
