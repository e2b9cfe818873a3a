//! Building a brick volume from tiles and leaves, whatever they come from:
//! a tree read whole ([`crate::convert_tree`]) or a grid streamed from its
//! file ([`crate::convert_file`]). Both go through this builder, so both
//! give the same volume, bit for bit.
//!
//! 1. [`Builder::start`] sizes the brick map from the active box (the
//!    trilinear support: one voxel more on each side), all empty.
//! 2. [`Builder::tile`] marks the bricks an active tile covers,
//!    [`Builder::place_leaves`] the brick of each leaf (by its index in
//!    leaf order), both as provisional map codes.
//! 3. [`Builder::sink`] hands out a [`LeafWriter`]: a [`LeafSink`] whose
//!    parts own disjoint slices of the voxel atlas, so leaves are
//!    sanitised, quantised and written in parallel straight into their
//!    slot (slot = leaf index); a leaf whose voxels are all equal writes
//!    nothing and keeps its value.
//! 4. [`Builder::finish`] numbers the stored bricks in leaf order,
//!    compacts the atlas in place over the constant leaves' slots, turns
//!    the provisional codes into [`BrickRef`]s (constants numbered in map
//!    order) and builds the bounds pyramid.
//!
//! Memory: the map (4 bytes a brick), the atlas (one slot per leaf,
//! allocated zeroed so the slots of constant leaves are never touched),
//! 4 bytes of state per leaf, one f32 per tile.

use crate::bounds::build_pyramid;
use crate::cell_bounds::brick_bounds;
use crate::layout::{
    BrickRef, Precision, BRICK, BRICK_LOG2, BRICK_VOXELS, MAX_BRICK_INDEX, MAX_MAP_BRICKS,
};
use crate::stages::Stages;
use crate::volume::{Atlas, BrickVolume, SourceInfo};
use crate::BrickError;
use cirrus_vdb::{BitMask, Coord, CoordBBox, LeafSink};
use glam::IVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

/// Provisional map codes while building: `TILE | t` is tile `t`'s value,
/// `LEAF | i` is leaf `i`; 0 is empty.
const TILE: u32 = 1 << 30;
const LEAF: u32 = 3 << 30;
const INDEX: u32 = (1 << 30) - 1;
/// A leaf's state with this bit set is stored (low bits: its atlas index
/// once numbered); without it, the bits of its one value (never negative,
/// so the bit is free).
const STORED: u32 = 1 << 31;

/// The voxel atlas while building, one 512-voxel slot per leaf.
enum AtlasBuf {
    F32(Vec<f32>),
    F16(Vec<u16>),
    U8(Vec<u8>),
}

/// A part of the atlas: the slots of a run of consecutive leaves.
enum AtlasMut<'a> {
    F32(&'a mut [f32]),
    F16(&'a mut [u16]),
    U8(&'a mut [u8]),
}

impl AtlasMut<'_> {
    fn split_front(&mut self, n: usize) -> Self {
        fn split<'b, T>(s: &mut &'b mut [T], n: usize) -> &'b mut [T] {
            let (a, b) = std::mem::take(s).split_at_mut(n);
            *s = b;
            a
        }
        match self {
            AtlasMut::F32(s) => AtlasMut::F32(split(s, n)),
            AtlasMut::F16(s) => AtlasMut::F16(split(s, n)),
            AtlasMut::U8(s) => AtlasMut::U8(split(s, n)),
        }
    }
}

/// Conversion figures the leaf writers add up.
#[derive(Default)]
struct LeafStats {
    max_error_bits: AtomicU32,
    sanitized: AtomicU64,
}

/// A grid on its way to bricks; see the module doc.
pub(crate) struct Builder {
    precision: Precision,
    origin: IVec3,
    dims: [u32; 3],
    map: Vec<u32>,
    tile_values: Vec<f32>,
    info: SourceInfo,
    atlas: AtlasBuf,
    states: Vec<u32>,
    /// Per leaf (lo, step) of a u8 brick; empty at other precisions.
    ranges: Vec<[f32; 2]>,
    stats: LeafStats,
}

/// What [`Builder::start`] starts: nothing to build (no active voxel), or a build.
#[allow(clippy::large_enum_variant)] // made once per conversion
pub(crate) enum Start {
    Empty(BrickVolume),
    Build(Builder),
}

/// `n` zeroed values, allocated lazily by the system (pages cost memory
/// when first written), or an error if the system refuses.
fn zeroed<T: bytemuck::Zeroable>(n: usize) -> Result<Vec<T>, BrickError> {
    if n == 0 || std::mem::size_of::<T>() == 0 {
        return Ok(Vec::new());
    }
    let too_large = || {
        BrickError::TooLarge(format!(
            "cannot allocate {n} x {} bytes",
            std::mem::size_of::<T>()
        ))
    };
    let layout = std::alloc::Layout::array::<T>(n).map_err(|_| too_large())?;
    // SAFETY: the layout has a non-zero size; all-zero bytes are a valid T
    // (Zeroable); the pointer comes from the global allocator with the
    // layout of a Vec<T> of capacity n, which owns it from here on.
    unsafe {
        let ptr = std::alloc::alloc_zeroed(layout) as *mut T;
        if ptr.is_null() {
            return Err(too_large());
        }
        Ok(Vec::from_raw_parts(ptr, n, n))
    }
}

impl Builder {
    /// A builder for a grid with this active box, active voxel count and
    /// number of leaves (or the empty volume, when nothing is active).
    pub fn start(
        bbox: Option<CoordBBox>,
        active_voxels: u64,
        leaf_count: usize,
        precision: Precision,
    ) -> Result<Start, BrickError> {
        let Some(bbox) = bbox else {
            return Ok(Start::Empty(BrickVolume::empty(precision, active_voxels)));
        };
        // Trilinear support reaches one voxel past the active box on each side.
        let lo = IVec3::from_array(bbox.min.to_array()) - 1;
        let hi = IVec3::from_array(bbox.max.to_array()) + 1;
        let origin = lo.div_euclid(IVec3::splat(BRICK)) * BRICK;
        let end = hi.div_euclid(IVec3::splat(BRICK)) + 1;
        let dims_i = end - origin / BRICK;
        let dims = [dims_i.x as u32, dims_i.y as u32, dims_i.z as u32];
        let count: u64 = dims.iter().map(|&d| d as u64).product();
        if count > MAX_MAP_BRICKS {
            return Err(BrickError::TooLarge(format!(
                "{dims:?} bricks ({count}) exceed the limit of {MAX_MAP_BRICKS}"
            )));
        }
        if leaf_count as u64 > INDEX as u64 {
            return Err(BrickError::TooLarge(format!(
                "{leaf_count} leaves exceed 2^30"
            )));
        }
        let slots = leaf_count * BRICK_VOXELS;
        // Zeroed allocations come from the system untouched: a slot costs
        // memory only once a stored leaf writes it. One the system refuses
        // is an error, not an abort.
        let atlas = match precision {
            Precision::F32 => AtlasBuf::F32(zeroed(slots)?),
            Precision::F16 => AtlasBuf::F16(zeroed(slots)?),
            Precision::U8 => AtlasBuf::U8(zeroed(slots)?),
        };
        let ranges = if precision == Precision::U8 {
            vec![[0f32; 2]; leaf_count]
        } else {
            Vec::new()
        };
        Ok(Start::Build(Builder {
            precision,
            origin,
            dims,
            map: zeroed(count as usize)?,
            tile_values: Vec::new(),
            info: SourceInfo {
                active_voxels,
                ..Default::default()
            },
            atlas,
            states: vec![0u32; leaf_count],
            ranges,
            stats: LeafStats::default(),
        }))
    }

    /// The brick holding voxel `c`, if it lies in the map.
    fn brick_index(&self, c: Coord) -> Option<usize> {
        let b = (IVec3::from_array(c.to_array()) - self.origin) >> BRICK_LOG2 as i32;
        let [dx, dy, dz] = self.dims;
        let inside = b.x >= 0
            && b.y >= 0
            && b.z >= 0
            && (b.x as u32) < dx
            && (b.y as u32) < dy
            && (b.z as u32) < dz;
        inside.then(|| (b.x as usize * dy as usize + b.y as usize) * dz as usize + b.z as usize)
    }

    /// An active tile: its bricks become constant. NaN, infinite and
    /// negative values are stored as 0 and counted; tiles of 0 leave their
    /// bricks empty.
    pub fn tile(&mut self, bbox: CoordBBox, v: f32) -> Result<(), BrickError> {
        let v = if v.is_finite() && v >= 0.0 {
            v + 0.0
        } else {
            self.info.sanitized_voxels += bbox.volume();
            0.0
        };
        if v == 0.0 {
            return Ok(());
        }
        let t = self.tile_values.len() as u32;
        if t > INDEX {
            return Err(BrickError::TooLarge("more than 2^30 tiles".into()));
        }
        let (Some(_), Some(_)) = (self.brick_index(bbox.min), self.brick_index(bbox.max)) else {
            // Active tiles lie inside the active box, so inside the map.
            return Err(BrickError::Unsupported(format!(
                "tile {bbox:?} lies outside the grid's active box"
            )));
        };
        self.tile_values.push(v);
        let b0 = (IVec3::from_array(bbox.min.to_array()) - self.origin) >> BRICK_LOG2 as i32;
        let b1 = (IVec3::from_array(bbox.max.to_array()) - self.origin) >> BRICK_LOG2 as i32;
        let [_, dy, dz] = self.dims.map(|d| d as usize);
        for x in b0.x..=b1.x {
            for y in b0.y..=b1.y {
                let row = (x as usize * dy + y as usize) * dz;
                self.map[row + b0.z as usize..=row + b1.z as usize].fill(TILE | t);
            }
        }
        Ok(())
    }

    /// Places leaf `i` (in the order the leaves will be written) at its
    /// brick. A leaf outside the map has no active voxel, so it is all
    /// background and needs no brick.
    pub fn place_leaves(&mut self, origins: impl Iterator<Item = Coord>) {
        for (i, origin) in origins.enumerate() {
            if let Some(at) = self.brick_index(origin) {
                self.map[at] = LEAF | i as u32;
            }
        }
    }

    /// The writer of every leaf's voxels; split it to write in parallel.
    pub fn sink(&mut self) -> LeafWriter<'_> {
        LeafWriter {
            precision: self.precision,
            first: 0,
            atlas: match &mut self.atlas {
                AtlasBuf::F32(v) => AtlasMut::F32(v),
                AtlasBuf::F16(v) => AtlasMut::F16(v),
                AtlasBuf::U8(v) => AtlasMut::U8(v),
            },
            states: &mut self.states,
            ranges: &mut self.ranges,
            stats: &self.stats,
            max_error: 0.0,
            sanitized: 0,
        }
    }

    /// Numbers and compacts the stored bricks, settles the map and builds
    /// the bounds pyramid.
    pub fn finish(self) -> Result<BrickVolume, BrickError> {
        self.finish_timed(&Stages::silent())
    }

    pub(crate) fn finish_timed(mut self, clock: &Stages) -> Result<BrickVolume, BrickError> {
        let n = self.number_stored();
        clock.lap("atlas numbered and compacted");
        let constants = self.settle_map(n)?;
        let total = constants.len();
        let count = self.map.len() as u64;
        let mut info = self.info;
        info.max_error = f32::from_bits(self.stats.max_error_bits.load(Ordering::Relaxed));
        info.sanitized_voxels += self.stats.sanitized.load(Ordering::Relaxed);
        info.bricks_stored = n as u64;
        info.bricks_constant = total as u64;
        info.bricks_empty = count - n as u64 - total as u64;
        drop(self.states);
        drop(self.tile_values);
        let atlas = match self.atlas {
            AtlasBuf::F32(v) => Atlas::F32(v.into()),
            AtlasBuf::F16(v) => Atlas::F16(v.into()),
            AtlasBuf::U8(v) => Atlas::U8(v.into()),
        };
        let ranges: Vec<f32> = self.ranges.into_iter().flatten().collect();
        let mut volume = BrickVolume {
            origin: self.origin,
            dims: self.dims,
            index_to_world: glam::DMat4::IDENTITY,
            map: self.map.into(),
            constants: constants.into(),
            ranges: ranges.into(),
            atlas,
            levels: Vec::new(),
            info,
            finest_partition: Default::default(),
        };
        clock.lap("map settled");
        let level0 = brick_bounds(&volume);
        clock.lap("level-0 bounds");
        volume.levels = build_pyramid(level0);
        clock.lap("bounds pyramid");
        Ok(volume)
    }

    /// Numbers the stored bricks in leaf order and closes the gaps the
    /// constant leaves left in the atlas (and the u8 ranges): each stored
    /// slot moves to its number, never later than where it is. Returns
    /// how many are stored.
    fn number_stored(&mut self) -> usize {
        let mut stored = 0u32;
        for s in self.states.iter_mut() {
            if *s & STORED != 0 {
                *s = STORED | stored;
                stored += 1;
            }
        }
        fn compact<T: Copy>(v: &mut Vec<T>, states: &[u32], per: usize, stored: usize) {
            for (i, &s) in states.iter().enumerate() {
                let r = (s & INDEX) as usize;
                if s & STORED != 0 && r != i {
                    v.copy_within(i * per..(i + 1) * per, r * per);
                }
            }
            v.truncate(stored * per);
            v.shrink_to_fit();
        }
        let n = stored as usize;
        match &mut self.atlas {
            AtlasBuf::F32(v) => compact(v, &self.states, BRICK_VOXELS, n),
            AtlasBuf::F16(v) => compact(v, &self.states, BRICK_VOXELS, n),
            AtlasBuf::U8(v) => compact(v, &self.states, BRICK_VOXELS, n),
        }
        if self.precision == Precision::U8 {
            compact(&mut self.ranges, &self.states, 1, n);
        }
        n
    }

    /// The map's final codes, with the constants numbered in map order
    /// (`n` bricks stored): count per chunk, then fill each chunk's part
    /// of the table, in parallel. Returns the constants' table.
    fn settle_map(&mut self, n: usize) -> Result<Vec<f32>, BrickError> {
        const CHUNK: usize = 1 << 16;
        let (states, tiles) = (&self.states, &self.tile_values);
        let constant_of = |code: u32| -> Option<f32> {
            match code & LEAF {
                TILE => Some(tiles[(code & INDEX) as usize]),
                LEAF => {
                    let s = states[(code & INDEX) as usize];
                    let v = f32::from_bits(s);
                    (s & STORED == 0 && v != 0.0).then_some(v)
                }
                _ => None,
            }
        };
        let counts: Vec<usize> = self
            .map
            .par_chunks(CHUNK)
            .map(|c| {
                c.iter()
                    .filter(|&&code| constant_of(code).is_some())
                    .count()
            })
            .collect();
        let total: usize = counts.iter().sum();
        if n as u64 > MAX_BRICK_INDEX as u64 || total as u64 > MAX_BRICK_INDEX as u64 {
            return Err(BrickError::TooLarge(format!(
                "{n} stored and {total} constant bricks: at most 2^30 of each"
            )));
        }
        let mut constants = vec![0f32; total];
        let mut parts = Vec::with_capacity(counts.len());
        let (mut rest, mut first) = (&mut constants[..], 0u32);
        for &c in &counts {
            let (part, r) = rest.split_at_mut(c);
            rest = r;
            parts.push((part, first));
            first += c as u32;
        }
        self.map
            .par_chunks_mut(CHUNK)
            .zip(parts)
            .for_each(|(codes, (table, first))| {
                let mut k = 0usize;
                for code in codes.iter_mut() {
                    *code = if let Some(v) = constant_of(*code) {
                        table[k] = v;
                        k += 1;
                        BrickRef::Constant(first + k as u32 - 1).encode()
                    } else if *code & LEAF == LEAF {
                        let s = states[(*code & INDEX) as usize];
                        if s & STORED != 0 {
                            BrickRef::Stored(s & INDEX).encode()
                        } else {
                            BrickRef::Empty.encode()
                        }
                    } else {
                        BrickRef::Empty.encode()
                    };
                }
            });
        Ok(constants)
    }
}

/// Writes leaves into their atlas slots: all of them, or (after
/// [`LeafSink::split_front`]) a run of consecutive ones.
pub(crate) struct LeafWriter<'a> {
    precision: Precision,
    /// Index of the first leaf this part holds.
    first: usize,
    atlas: AtlasMut<'a>,
    states: &'a mut [u32],
    ranges: &'a mut [[f32; 2]],
    stats: &'a LeafStats,
    max_error: f32,
    sanitized: u64,
}

impl LeafSink<f32> for LeafWriter<'_> {
    type Error = BrickError;

    fn split_front(&mut self, n: usize) -> Self {
        let states = std::mem::take(&mut self.states);
        let (states, rest) = states.split_at_mut(n);
        self.states = rest;
        let ranges = std::mem::take(&mut self.ranges);
        let (ranges, rest) = ranges.split_at_mut(if ranges.is_empty() { 0 } else { n });
        self.ranges = rest;
        let first = self.first;
        self.first += n;
        LeafWriter {
            precision: self.precision,
            first,
            atlas: self.atlas.split_front(n * BRICK_VOXELS),
            states,
            ranges,
            stats: self.stats,
            max_error: 0.0,
            sanitized: 0,
        }
    }

    /// Sanitises (inactive voxels are 0; NaN, infinite and negative values
    /// become 0 and are counted) and quantises one leaf into its slot.
    fn leaf(
        &mut self,
        index: usize,
        mask: &BitMask<8>,
        values: &[f32; 512],
    ) -> Result<(), BrickError> {
        let k = index - self.first;
        let mut v = [0f32; BRICK_VOXELS];
        // Branch-free over all 512, 64 (one x-slice) at a time.
        let mut bad = 0u32;
        for (&bits, (out, src)) in mask
            .words()
            .iter()
            .zip(v.chunks_exact_mut(64).zip(values.chunks_exact(64)))
        {
            for (b, (o, &x)) in out.iter_mut().zip(src).enumerate() {
                let on = (bits >> b) & 1 != 0;
                let good = x.is_finite() & (x >= 0.0);
                *o = if on & good { x + 0.0 } else { 0.0 }; // -0 as +0
                bad += (on & !good) as u32;
            }
        }
        self.sanitized += bad as u64;
        let (lo, hi) = min_max(&v);
        if lo == hi {
            self.states[k] = lo.to_bits();
            return Ok(());
        }
        self.states[k] = STORED;
        let slot = k * BRICK_VOXELS..(k + 1) * BRICK_VOXELS;
        let mut err = 0f32;
        match &mut self.atlas {
            AtlasMut::F32(a) => a[slot].copy_from_slice(&v),
            AtlasMut::F16(a) => {
                use half::slice::{HalfBitsSliceExt, HalfFloatSliceExt};
                if hi > half::f16::MAX.to_f32() {
                    return Err(BrickError::F16Overflow(hi));
                }
                // Whole-slice conversions use the CPU's F16C instructions;
                // rounding is the same as one value at a time.
                let dst = &mut a[slot];
                dst.reinterpret_cast_mut::<half::f16>()
                    .convert_from_f32_slice(&v);
                let mut back = [0f32; BRICK_VOXELS];
                dst.reinterpret_cast::<half::f16>()
                    .convert_to_f32_slice(&mut back);
                for (b, x) in back.iter_mut().zip(&v) {
                    *b = (*b - x).abs();
                }
                err = min_max(&back).1;
            }
            AtlasMut::U8(a) => {
                // voldata's scheme: 255 steps between the brick's min and max;
                // the error is at most half a step, (hi - lo) / 510.
                let step = (hi - lo) / 255.0;
                self.ranges[k] = [lo, step];
                for (d, &x) in a[slot].iter_mut().zip(&v) {
                    let q = ((x - lo) / step).round().clamp(0.0, 255.0);
                    err = err.max((lo + q * step - x).abs());
                    *d = q as u8;
                }
            }
        }
        self.max_error = self.max_error.max(err);
        Ok(())
    }

    fn finish(self) {
        // Errors are never negative, so their bits order as the values do.
        self.stats
            .max_error_bits
            .fetch_max(self.max_error.to_bits(), Ordering::Relaxed);
        self.stats
            .sanitized
            .fetch_add(self.sanitized, Ordering::Relaxed);
    }
}

/// (min, max) of 512 values that hold no NaN, in eight independent lanes
/// (a single running min would wait on itself every step).
#[inline]
fn min_max(v: &[f32; BRICK_VOXELS]) -> (f32, f32) {
    let (mut lo, mut hi) = ([f32::INFINITY; 8], [f32::NEG_INFINITY; 8]);
    for c in v.chunks_exact(8) {
        for i in 0..8 {
            lo[i] = if c[i] < lo[i] { c[i] } else { lo[i] };
            hi[i] = if c[i] > hi[i] { c[i] } else { hi[i] };
        }
    }
    lo.iter()
        .zip(&hi)
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), (&l, &h)| {
            (a.min(l), b.max(h))
        })
}

/// Feeds `count` leaves through `sink` in parallel runs of `run`, leaf `i`
/// coming from `leaf(i)`.
pub(crate) fn write_leaves<'a, F>(
    mut sink: LeafWriter<'_>,
    count: usize,
    leaf: F,
) -> Result<(), BrickError>
where
    F: Fn(usize) -> (&'a BitMask<8>, &'a [f32; 512]) + Sync,
{
    const RUN: usize = 256;
    let mut parts = Vec::with_capacity(count.div_ceil(RUN));
    let mut start = 0;
    while start < count {
        let n = RUN.min(count - start);
        parts.push((start, n, sink.split_front(n)));
        start += n;
    }
    parts.into_par_iter().try_for_each(|(start, n, mut part)| {
        for i in start..start + n {
            let (mask, values) = leaf(i);
            part.leaf(i, mask, values)?;
        }
        part.finish();
        Ok(())
    })
}
