//! Sizes and bit fields of the brick layout.
//!
//! - A brick is 8^3 voxels, aligned with OpenVDB leaves, so a leaf converts
//!   to a brick by a copy and a leaf-level tile to a constant brick.
//! - The brick map holds one `u32` [`BrickRef`] per brick of a dense grid
//!   over the volume's bounds: 4 bytes per 512 voxels (under 0.01 byte per
//!   voxel), one load to find any voxel. Its top two bits say what the brick
//!   is; the low 30 bits index the constant table or the voxel atlas, so up to
//!   2^30 of each.
//! - Stored bricks hold 512 voxels at one [`Precision`]: f32 (2 KiB), f16
//!   (1 KiB) or u8 normalised to the brick's own [lo, hi] (512 B + 8 B range),
//!   as nihofm/voldata quantises.
//! - Bounds: per brick and per coarser level, an f32 (min, max) pair — see
//!   `bounds.rs`.

/// log2 of a brick's side in voxels.
pub const BRICK_LOG2: u32 = 3;
/// A brick's side in voxels.
pub const BRICK: i32 = 1 << BRICK_LOG2;
/// Voxels in a brick.
pub const BRICK_VOXELS: usize = 512;

/// What one brick of the map is, in 32 bits: `tag:2 | index:30`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BrickRef {
    /// All zero: no storage at all.
    Empty,
    /// One value everywhere: index into the constant table.
    Constant(u32),
    /// Voxels in the atlas: brick index in the atlas.
    Stored(u32),
}

const TAG_SHIFT: u32 = 30;
const INDEX_MASK: u32 = (1 << TAG_SHIFT) - 1;
/// Most bricks of one kind a volume can hold.
pub const MAX_BRICK_INDEX: u32 = INDEX_MASK;

impl BrickRef {
    #[inline]
    pub fn encode(self) -> u32 {
        match self {
            BrickRef::Empty => 0,
            BrickRef::Constant(i) => (1 << TAG_SHIFT) | (i & INDEX_MASK),
            BrickRef::Stored(i) => (2 << TAG_SHIFT) | (i & INDEX_MASK),
        }
    }

    /// Decodes a map entry; tag 3 (never written) reads as empty.
    #[inline]
    pub fn decode(bits: u32) -> BrickRef {
        match bits >> TAG_SHIFT {
            1 => BrickRef::Constant(bits & INDEX_MASK),
            2 => BrickRef::Stored(bits & INDEX_MASK),
            _ => BrickRef::Empty,
        }
    }
}

/// How stored bricks keep their voxels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    F32,
    F16,
    /// 8 bits a voxel between the brick's own min and max.
    U8,
}

impl Precision {
    pub fn bytes_per_voxel(self) -> usize {
        match self {
            Precision::F32 => 4,
            Precision::F16 => 2,
            Precision::U8 => 1,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F16 => "f16",
            Precision::U8 => "u8",
        }
    }
    pub fn from_name(s: &str) -> Option<Precision> {
        match s {
            "f32" => Some(Precision::F32),
            "f16" => Some(Precision::F16),
            "u8" => Some(Precision::U8),
            _ => None,
        }
    }
    pub(crate) fn code(self) -> u32 {
        match self {
            Precision::F32 => 0,
            Precision::F16 => 1,
            Precision::U8 => 2,
        }
    }
    pub(crate) fn from_code(c: u32) -> Option<Precision> {
        [Precision::F32, Precision::F16, Precision::U8]
            .get(c as usize)
            .copied()
    }
}

/// Offset of a voxel inside its brick: x-major, as in an OpenVDB leaf.
#[inline]
pub fn voxel_offset(x: i32, y: i32, z: i32) -> usize {
    (((x & 7) as usize) << 6) | (((y & 7) as usize) << 3) | ((z & 7) as usize)
}

/// Largest brick map a conversion builds: 2^27 bricks (512 MiB of map,
/// 64 Gi voxels of bounds), far past production clouds.
pub const MAX_MAP_BRICKS: u64 = 1 << 27;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brick_refs_round_trip_through_their_bits() {
        for r in [
            BrickRef::Empty,
            BrickRef::Constant(0),
            BrickRef::Constant(MAX_BRICK_INDEX),
            BrickRef::Stored(7),
        ] {
            assert_eq!(BrickRef::decode(r.encode()), r);
        }
        assert_eq!(BrickRef::decode(3 << 30), BrickRef::Empty);
    }
}
