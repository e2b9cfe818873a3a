//! A converted volume: the brick map, voxel atlas, bounds pyramid and the
//! transform, with the density lookups the renderer calls.

use crate::bounds::BoundsLevel;
use crate::f16::f16_bits_to_f32;
#[cfg(target_arch = "x86_64")]
use crate::f16::{f16_pairs_to_f32_f16c, f16x8_to_f32_f16c, has_f16c};
use crate::layout::{voxel_offset, BrickRef, Precision, BRICK_LOG2};
use crate::partition::CellPartition;
use crate::section::Section;
use crate::voxel_of::voxel_of;
use glam::{DMat4, IVec3, Vec3};
use std::sync::OnceLock;

/// Voxel storage of the stored bricks, at their precision.
#[derive(Clone, Debug)]
pub enum Atlas {
    F32(Section<f32>),
    F16(Section<u16>),
    /// With a (lo, step) pair per brick in `BrickVolume::ranges`.
    U8(Section<u8>),
}

impl Atlas {
    pub fn precision(&self) -> Precision {
        match self {
            Atlas::F32(_) => Precision::F32,
            Atlas::F16(_) => Precision::F16,
            Atlas::U8(_) => Precision::U8,
        }
    }
    pub fn bytes(&self) -> usize {
        match self {
            Atlas::F32(s) => s.len() * 4,
            Atlas::F16(s) => s.len() * 2,
            Atlas::U8(s) => s.len(),
        }
    }
}

/// Where the volume came from and what converting it did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SourceInfo {
    pub grid_name: String,
    /// Active voxels of the source grid, tiles included.
    pub active_voxels: u64,
    pub bricks_stored: u64,
    pub bricks_constant: u64,
    /// Bricks of the map that hold nothing.
    pub bricks_empty: u64,
    /// Largest |stored - source| over all voxels.
    pub max_error: f32,
    /// Voxels whose value was NaN, infinite or negative, stored as 0.
    pub sanitized_voxels: u64,
}

/// A density volume in 8^3 bricks with its bounds hierarchy.
#[derive(Clone, Debug)]
pub struct BrickVolume {
    /// Index coordinate of the first voxel of brick (0, 0, 0).
    pub origin: IVec3,
    /// Bricks per axis.
    pub dims: [u32; 3],
    /// Source grid's index-to-world matrix.
    pub index_to_world: DMat4,
    pub(crate) map: Section<u32>,
    pub(crate) constants: Section<f32>,
    /// Per stored brick (lo, step) for u8 bricks; empty otherwise.
    pub(crate) ranges: Section<f32>,
    pub(crate) atlas: Atlas,
    /// Level 0 = 4^3 cells, level 1 = bricks; each next level halves the resolution.
    pub levels: Vec<BoundsLevel>,
    pub info: SourceInfo,
    /// The partition of [`BrickVolume::segments`] (every cell refined), made
    /// on first use.
    pub(crate) finest_partition: OnceLock<CellPartition>,
}

impl BrickVolume {
    /// The partition the walk uses when it refines cells whose slack
    /// exceeds `split` density x voxels, and walks level-0 cells whose
    /// slack exceeds `voxel_split` voxel by voxel
    /// ([`CellPartition::refined`]).
    pub fn partition(&self, split: f32, voxel_split: f32) -> CellPartition {
        CellPartition::refined(&self.levels, split, voxel_split)
    }

    /// The partition a ray march uses ([`CellPartition::occupancy`]).
    pub fn occupancy_partition(&self, level: usize) -> CellPartition {
        CellPartition::occupancy(&self.levels, level)
    }

    /// A volume with no bricks (an empty grid) of `active_voxels` active
    /// voxels (all zero: tiles of density 0).
    pub(crate) fn empty(precision: Precision, active_voxels: u64) -> BrickVolume {
        let atlas = match precision {
            Precision::F32 => Atlas::F32(Vec::new().into()),
            Precision::F16 => Atlas::F16(Vec::new().into()),
            Precision::U8 => Atlas::U8(Vec::new().into()),
        };
        BrickVolume {
            origin: IVec3::ZERO,
            dims: [0; 3],
            index_to_world: glam::DMat4::IDENTITY,
            map: Vec::new().into(),
            constants: Vec::new().into(),
            ranges: Vec::new().into(),
            atlas,
            levels: Vec::new(),
            info: SourceInfo {
                active_voxels,
                ..Default::default()
            },
            finest_partition: Default::default(),
        }
    }

    pub fn precision(&self) -> Precision {
        self.atlas.precision()
    }

    /// The brick map: one [`BrickRef`] word per brick, x-major (what a
    /// device copy of the volume uploads).
    pub fn map_words(&self) -> &[u32] {
        &self.map
    }

    /// The values of constant bricks, indexed by [`BrickRef::Constant`].
    pub fn constants(&self) -> &[f32] {
        &self.constants
    }

    /// The stored bricks' voxels, 512 a brick, indexed by
    /// [`BrickRef::Stored`], x-major within a brick (`x << 6 | y << 3 | z`).
    pub fn atlas(&self) -> &Atlas {
        &self.atlas
    }

    /// Bytes of each part: (map, constants + ranges, atlas, bounds per level).
    pub fn memory_bytes(&self) -> (usize, usize, usize, Vec<usize>) {
        (
            self.map.len() * 4,
            (self.constants.len() + self.ranges.len()) * 4,
            self.atlas.bytes(),
            self.levels.iter().map(|l| l.bytes()).collect(),
        )
    }

    pub fn total_bytes(&self) -> usize {
        let (a, b, c, d) = self.memory_bytes();
        a + b + c + d.iter().sum::<usize>()
    }

    /// Extent of the brick grid in local index coordinates: [0, dims * 8).
    pub fn local_extent(&self) -> Vec3 {
        Vec3::new(
            self.dims[0] as f32,
            self.dims[1] as f32,
            self.dims[2] as f32,
        ) * (1 << BRICK_LOG2) as f32
    }

    /// Maps world coordinates to local index coordinates (index minus `origin`).
    pub fn local_from_world(&self) -> DMat4 {
        DMat4::from_translation(-self.origin.as_dvec3()) * self.index_to_world.inverse()
    }

    /// How brick `b` is stored (empty outside the map).
    #[inline(always)]
    pub fn brick_ref(&self, b: IVec3) -> BrickRef {
        if b.x < 0
            || b.y < 0
            || b.z < 0
            || b.x as u32 >= self.dims[0]
            || b.y as u32 >= self.dims[1]
            || b.z as u32 >= self.dims[2]
        {
            return BrickRef::Empty;
        }
        // Two independent products (see `BoundsLevel::index`).
        let [_, dy, dz] = self.dims.map(|d| d as usize);
        let i = b.x as usize * (dy * dz) + (b.y as usize * dz + b.z as usize);
        BrickRef::decode(self.map[i])
    }

    /// Value of voxel `n` of stored brick `b`.
    #[inline(always)]
    fn stored(&self, b: u32, n: usize) -> f32 {
        let i = b as usize * 512 + n;
        match &self.atlas {
            Atlas::F32(a) => a[i],
            Atlas::F16(a) => f16_bits_to_f32(a[i]),
            Atlas::U8(a) => {
                let (lo, step) = (self.ranges[2 * b as usize], self.ranges[2 * b as usize + 1]);
                lo + a[i] as f32 * step
            }
        }
    }

    /// The eight voxels `n + {0, 1, 8, 9, 64, 65, 72, 73}` of stored brick
    /// `b` (a trilinear stencil inside one brick), decoding the atlas once.
    #[inline(always)]
    fn stored_corners(&self, b: u32, n: usize) -> [f32; 8] {
        // One slice per stencil: a single bounds check covers all eight reads.
        macro_rules! gather {
            ($s:expr, $f:expr) => {{
                let s = $s;
                let f = $f;
                [
                    f(s[0]),
                    f(s[1]),
                    f(s[8]),
                    f(s[9]),
                    f(s[64]),
                    f(s[65]),
                    f(s[72]),
                    f(s[73]),
                ]
            }};
        }
        let base = b as usize * 512 + n;
        match &self.atlas {
            Atlas::F32(a) => gather!(&a[base..base + 74], |v: f32| v),
            Atlas::F16(a) => gather!(&a[base..base + 74], f16_bits_to_f32),
            Atlas::U8(a) => {
                let (lo, step) = (self.ranges[2 * b as usize], self.ranges[2 * b as usize + 1]);
                gather!(&a[base..base + 74], |v: u8| lo + v as f32 * step)
            }
        }
    }

    /// Decodes `out.len()` voxels of stored brick `b` from voxel `first`
    /// on, `stride` apart.
    fn stored_run(&self, b: u32, first: usize, stride: usize, out: &mut [f32]) {
        let base = b as usize * 512 + first;
        let at = |i: usize| base + i * stride;
        match &self.atlas {
            Atlas::F32(a) => out.iter_mut().enumerate().for_each(|(i, o)| *o = a[at(i)]),
            Atlas::F16(a) if stride == 1 => {
                use half::slice::{HalfBitsSliceExt, HalfFloatSliceExt};
                a[base..base + out.len()]
                    .reinterpret_cast::<half::f16>()
                    .convert_to_f32_slice(out);
            }
            Atlas::F16(a) => out
                .iter_mut()
                .enumerate()
                .for_each(|(i, o)| *o = half::f16::from_bits(a[at(i)]).to_f32()),
            Atlas::U8(a) => {
                let (lo, step) = (self.ranges[2 * b as usize], self.ranges[2 * b as usize + 1]);
                out.iter_mut()
                    .enumerate()
                    .for_each(|(i, o)| *o = lo + a[at(i)] as f32 * step);
            }
        }
    }

    /// The 9^3 voxels from the first of brick `b` (the brick and the first
    /// layer of its +x, +y, +z neighbours), x-major: what the bounds of its
    /// cells read. Each neighbour's kind is looked up once and its voxels
    /// decoded as runs.
    pub(crate) fn gather_block(&self, b: IVec3, out: &mut [f32; 729]) {
        const N: usize = 9;
        let mut buf = [0f32; 512];
        for k in 0..8usize {
            let d = [k >> 2, (k >> 1) & 1, k & 1];
            let r = d.map(|on| if on == 0 { 0..8usize } else { 8..9usize });
            let n = r.iter().map(|r| r.len()).product::<usize>();
            // The voxels this neighbour gives, in x-major order of its part.
            let vals = &mut buf[..n];
            match self.brick_ref(b + IVec3::new(d[0] as i32, d[1] as i32, d[2] as i32)) {
                BrickRef::Empty => vals.fill(0.0),
                BrickRef::Constant(c) => vals.fill(self.constants[c as usize]),
                BrickRef::Stored(s) => match d {
                    // The brick itself, a face, an edge or the corner of a neighbour:
                    // (first voxel, stride) per run of the last varying axis.
                    [0, 0, 0] => self.stored_run(s, 0, 1, vals),
                    [1, 0, 0] => self.stored_run(s, 0, 1, vals), // x = 0: y, z
                    [0, 1, 0] => {
                        for x in 0..8 {
                            self.stored_run(s, x << 6, 1, &mut vals[x * 8..x * 8 + 8]);
                        }
                    }
                    [0, 0, 1] => self.stored_run(s, 0, 8, vals), // z = 0: x, y
                    [1, 1, 0] => self.stored_run(s, 0, 1, vals), // x = y = 0: z
                    [1, 0, 1] => self.stored_run(s, 0, 8, vals), // x = z = 0: y
                    [0, 1, 1] => self.stored_run(s, 0, 64, vals), // y = z = 0: x
                    _ => self.stored_run(s, 0, 1, vals),
                },
            }
            let mut i = 0;
            for x in r[0].clone() {
                for y in r[1].clone() {
                    let row = (x * N + y) * N;
                    let len = r[2].len();
                    out[row + r[2].start..row + r[2].end].copy_from_slice(&vals[i..i + len]);
                    i += len;
                }
            }
        }
    }

    /// The voxel at local index `c` (0 outside the volume).
    #[inline]
    pub fn voxel(&self, c: IVec3) -> f32 {
        match self.brick_ref(c >> BRICK_LOG2 as i32) {
            BrickRef::Empty => 0.0,
            BrickRef::Constant(k) => self.constants[k as usize],
            BrickRef::Stored(b) => self.stored(b, voxel_offset(c.x, c.y, c.z)),
        }
    }

    /// (min, max) of the trilinear density over the voxel cell `[c, c + 1)`:
    /// the range of its eight corner voxels.
    pub fn voxel_cell_range(&self, c: IVec3) -> (f32, f32) {
        let v = if (c & 7).cmplt(IVec3::splat(7)).all() {
            match self.brick_ref(c >> BRICK_LOG2 as i32) {
                BrickRef::Empty => return (0.0, 0.0),
                BrickRef::Constant(k) => {
                    let v = self.constants[k as usize];
                    return (v, v);
                }
                BrickRef::Stored(b) => self.stored_corners(b, voxel_offset(c.x, c.y, c.z)),
            }
        } else {
            self.straddling_corners(c)
        };
        v.iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &x| {
                (lo.min(x), hi.max(x))
            })
    }

    /// The bricks a stencil at voxel `c` touches: `cross`, the corner index
    /// bits (x 4, y 2, z 1) along which it crosses a brick face, and the
    /// brick of each corner `k` at slot `k & cross` (the other slots empty).
    #[inline(always)]
    fn straddled_bricks(&self, c: IVec3) -> (usize, [BrickRef; 8]) {
        let b0 = c >> BRICK_LOG2 as i32;
        let b1 = (c + 1) >> BRICK_LOG2 as i32;
        let cross = (usize::from(b1.x != b0.x) << 2)
            | (usize::from(b1.y != b0.y) << 1)
            | usize::from(b1.z != b0.z);
        let mut bricks = [BrickRef::Empty; 8];
        for (k, b) in bricks.iter_mut().enumerate() {
            if k & !cross == 0 {
                *b = self.brick_ref(b0 + corner_offset(k));
            }
        }
        (cross, bricks)
    }

    /// The eight voxels `c + {0, 1}^3` (ordered `v[4x + 2y + z]`) of a
    /// stencil that crosses a brick face: each distinct brick it touches is
    /// looked up once, two across a face, four at an edge, eight only at a
    /// corner, where reading the corners one voxel at a time would look a
    /// brick up eight times.
    #[inline]
    fn straddling_corners(&self, c: IVec3) -> [f32; 8] {
        let (cross, bricks) = self.straddled_bricks(c);
        let mut v = [0.0; 8];
        for (k, out) in v.iter_mut().enumerate() {
            let q = c + corner_offset(k);
            *out = match bricks[k & cross] {
                BrickRef::Empty => 0.0,
                BrickRef::Constant(i) => self.constants[i as usize],
                BrickRef::Stored(b) => self.stored(b, voxel_offset(q.x, q.y, q.z)),
            };
        }
        v
    }

    /// Nearest-voxel density at a local index point.
    #[inline]
    pub fn nearest(&self, p: Vec3) -> f32 {
        self.voxel((p + 0.5).floor().as_ivec3())
    }

    /// Trilinear density at a local index point (voxel centres at integer
    /// coordinates, as OpenVDB's `BoxSampler`). Reads one brick when all
    /// eight corners share it (7/8 of positions per axis), else each corner.
    #[inline]
    pub fn trilinear(&self, p: Vec3) -> f32 {
        #[cfg(target_arch = "x86_64")]
        if let Some(a) = self.f16c_atlas() {
            // SAFETY: `f16c_atlas` is `Some` only where the CPU has F16C.
            return unsafe { self.trilinear_f16c(a, p) };
        }
        self.trilinear_with(
            p,
            |b, n| self.stored_corners(b, n),
            |c| self.straddling_corners(c),
        )
    }

    /// [`trilinear`](Self::trilinear) over an f16 atlas, each stencil
    /// inside a brick decoded by F16C at once: the same value, bit for
    /// bit. Measured on the corpus cloud's ray march (f16 atlas): the
    /// portable decode of the eight corners made a lookup about 10%
    /// slower than one over an f32 atlas.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "f16c")]
    fn trilinear_f16c(&self, atlas: &[u16], p: Vec3) -> f32 {
        self.trilinear_f16c_inlined(atlas, p)
    }

    /// [`Self::trilinear_f16c`] for callers compiled with F16C themselves
    /// (the ray march), into which it inlines. The path tracer's lookups
    /// call the other, out of line: inlined into every caller, its
    /// straddling stencils went out of line instead, 1-2% slower there.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "f16c")]
    #[inline]
    pub(crate) fn trilinear_f16c_inlined(&self, atlas: &[u16], p: Vec3) -> f32 {
        self.trilinear_with(
            p,
            |b, n| {
                let base = b as usize * 512 + n;
                let s = &atlas[base..base + 74];
                let pair = |i: usize| u32::from(s[i]) | u32::from(s[i + 1]) << 16;
                f16_pairs_to_f32_f16c([pair(0), pair(8), pair(64), pair(72)])
            },
            |c| match self.straddling_f16_bits(atlas, c) {
                Some(raw) => f16x8_to_f32_f16c(raw),
                None => self.straddling_corners(c),
            },
        )
    }

    /// The f16 atlas, where the CPU has F16C to decode it with.
    #[cfg(target_arch = "x86_64")]
    #[inline]
    pub(crate) fn f16c_atlas(&self) -> Option<&[u16]> {
        match &self.atlas {
            Atlas::F16(a) if has_f16c() => Some(a),
            _ => None,
        }
    }

    /// The raw f16 corners of a stencil across brick faces (0 for empty
    /// bricks, as f16 0 is 0.0), each brick looked up once; `None` when a
    /// constant brick is among them (its value is an f32).
    #[inline(always)]
    fn straddling_f16_bits(&self, atlas: &[u16], c: IVec3) -> Option<[u16; 8]> {
        const EMPTY: usize = usize::MAX;
        let (cross, bricks) = self.straddled_bricks(c);
        let mut base = [EMPTY; 8];
        for (b, r) in base.iter_mut().zip(bricks) {
            match r {
                BrickRef::Empty => {}
                BrickRef::Constant(_) => return None,
                BrickRef::Stored(i) => *b = i as usize * 512,
            }
        }
        let mut raw = [0u16; 8];
        for (k, r) in raw.iter_mut().enumerate() {
            let b = base[k & cross];
            if b != EMPTY {
                let q = c + corner_offset(k);
                *r = atlas[b + voxel_offset(q.x, q.y, q.z)];
            }
        }
        Some(raw)
    }

    /// The trilinear lookup, with `stored(b, n)` the eight corners of a
    /// stencil at voxel `n` inside stored brick `b`, and `straddling(c)`
    /// those of a stencil at voxel `c` across brick faces.
    #[inline(always)]
    fn trilinear_with(
        &self,
        p: Vec3,
        stored: impl Fn(u32, usize) -> [f32; 8],
        straddling: impl Fn(IVec3) -> [f32; 8],
    ) -> f32 {
        if !p.is_finite() {
            return 0.0;
        }
        let c = voxel_of(p.into());
        let f = p - c.as_vec3();
        let v = if (c & 7).cmplt(IVec3::splat(7)).all() {
            match self.brick_ref(c >> BRICK_LOG2 as i32) {
                BrickRef::Empty => return 0.0,
                BrickRef::Constant(k) => return self.constants[k as usize],
                BrickRef::Stored(b) => stored(b, voxel_offset(c.x, c.y, c.z)),
            }
        } else {
            straddling(c)
        };
        lerp_corners(v, f)
    }

    /// Largest value of the volume (the global majorant).
    pub fn max_density(&self) -> f32 {
        self.levels.last().map_or(0.0, |l| {
            l.cells.chunks_exact(2).fold(0.0, |m, c| m.max(c[1]))
        })
    }
}

/// The offset of a stencil's corner `k` (`k = 4x + 2y + z`).
#[inline(always)]
fn corner_offset(k: usize) -> IVec3 {
    IVec3::new((k >> 2) as i32, ((k >> 1) & 1) as i32, (k & 1) as i32)
}

/// Trilinear interpolation of a stencil's corners, ordered x-major
/// (`v[4x + 2y + z]`), at fractional position `f`.
#[inline(always)]
fn lerp_corners(v: [f32; 8], f: Vec3) -> f32 {
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x0 = lerp(lerp(v[0], v[1], f.z), lerp(v[2], v[3], f.z), f.y);
    let x1 = lerp(lerp(v[4], v[5], f.z), lerp(v[6], v[7], f.z), f.y);
    lerp(x0, x1, f.x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convert::convert_tree;
    use cirrus_testkit::SplitMix64;
    use cirrus_vdb::{Coord, Tree};

    /// Over an f16 atlas the lookup (through F16C where the CPU has it)
    /// gives exactly the portable lookup's value, inside bricks and across
    /// their faces, next to empty and constant bricks: 200,000 points over
    /// a volume of random voxels, a hole and a constant 8^3 block.
    #[test]
    fn f16_lookups_equal_the_portable_decode_bit_for_bit() {
        let mut rng = SplitMix64(7);
        let mut tree = Tree::new(0.0f32);
        for x in 0..24 {
            for y in 0..24 {
                for z in 0..24 {
                    let hole = (8..16).contains(&x) && (8..16).contains(&y) && z < 8;
                    let block = x >= 16 && y >= 16 && z >= 16;
                    let value = if block { 0.75 } else { 3.0 * rng.unit() };
                    if !hole && (block || rng.below(3) > 0) {
                        tree.set_value_on(Coord::new(x, y, z), value);
                    }
                }
            }
        }
        let volume = convert_tree(&tree, Precision::F16).unwrap();
        assert_eq!(volume.precision(), Precision::F16);
        assert!(
            !volume.constants.is_empty(),
            "the block is a constant brick"
        );
        let (mut positive, mut straddling) = (0, 0);
        for _ in 0..200_000 {
            // Index space [-1, 25)^3, in the volume's local coordinates.
            let p = Vec3::new(rng.unit(), rng.unit(), rng.unit()) * 26.0
                - 1.0
                - volume.origin.as_vec3();
            let fast = volume.trilinear(p);
            let portable = volume.trilinear_with(
                p,
                |b, n| volume.stored_corners(b, n),
                |c| volume.straddling_corners(c),
            );
            assert_eq!(fast.to_bits(), portable.to_bits(), "at {p}");
            positive += usize::from(fast > 0.0);
            straddling += usize::from((p.floor().as_ivec3() & 7).cmpeq(IVec3::splat(7)).any());
        }
        assert!(
            positive > 100_000 && straddling > 50_000,
            "{positive} {straddling}"
        );
    }
}
