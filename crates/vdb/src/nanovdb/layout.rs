//! Byte layouts of NanoVDB's file records and grid-buffer nodes (major
//! version 32), per grid type.
//!
//! The offsets are those of the C++ structs in `NanoVDB.h` and
//! `util/IO.h` of NanoVDB 32.4.2, checked with `offsetof`/`sizeof` against
//! the installed headers, and equal to the `pnanovdb_grid_type_constants`
//! table of `PNanoVDB.h` in both 32.4.2 and 32.9 (the one exception: the
//! value bits of a `bool` leaf sit at byte 80, right after the value mask,
//! as the C++ struct has them; PNanoVDB's table says 96).

use crate::ValueType;

/// `FileHeader` (IO.h): magic, version, grid count, codec.
pub const FILE_HEADER_SIZE: usize = 16;
/// `FileMetaData` (IO.h 32.4 `MetaData`, NanoVDB.h 32.6+ `FileMetaData`).
pub const FILE_META_SIZE: usize = 176;
/// `GridData`.
pub const GRID_DATA_SIZE: usize = 672;
/// `TreeData<3>`, which always follows `GridData`.
pub const TREE_DATA_SIZE: usize = 64;

pub mod grid {
    pub const MAGIC: usize = 0;
    pub const VERSION: usize = 16;
    pub const GRID_SIZE: usize = 32;
    pub const NAME: usize = 40;
    pub const NAME_SIZE: usize = 256;
    /// `Map::mMatD`: 3x3 doubles, row-major, `world = M * ijk + t`.
    pub const MAT_D: usize = 296 + 88;
    /// `Map::mVecD`: the translation.
    pub const VEC_D: usize = 296 + 232;
    pub const GRID_CLASS: usize = 632;
    pub const GRID_TYPE: usize = 636;
}

pub mod tree {
    /// `mNodeOffset[4]`: byte offsets from the TreeData to the first leaf,
    /// lower, upper and root node.
    pub const NODE_OFFSET: usize = 0;
    /// `mNodeCount[3]`: leaves, lower nodes, upper nodes.
    pub const NODE_COUNT: usize = 32;
    pub const VOXEL_COUNT: usize = 56;
}

/// Root tile fields shared by all grid types (`RootData::Tile`).
pub mod tile {
    pub const KEY: usize = 0;
    pub const CHILD: usize = 8;
    pub const STATE: usize = 16;
}

pub const ROOT_TABLE_SIZE: usize = 24;
/// Internal nodes: 24-byte bbox, u64 flags, then the value mask and the child mask.
pub const INTERNAL_VALUE_MASK: usize = 32;
/// Leaves: 12-byte bbox min, 3 bbox deltas, one flags byte, then the value mask.
pub const LEAF_FLAGS: usize = 15;
pub const LEAF_VALUE_MASK: usize = 16;
/// Quantised leaves (`LeafFnBase`): minimum and quantum, then the codes at 96.
pub const FP_MINIMUM: usize = 80;
pub const FP_QUANTUM: usize = 84;
pub const FP_CODES: usize = 96;
pub const BOOL_VALUES: usize = 80;
/// A leaf of `Mask` type is only its header and value mask.
pub const MASK_LEAF_SIZE: usize = 96;

/// NanoVDB's `GridType` enum, by number.
pub fn grid_type_name(t: u32) -> String {
    const NAMES: [&str; 27] = [
        "Unknown",
        "Float",
        "Double",
        "Int16",
        "Int32",
        "Int64",
        "Vec3f",
        "Vec3d",
        "Mask",
        "Half",
        "UInt32",
        "Boolean",
        "RGBA8",
        "Fp4",
        "Fp8",
        "Fp16",
        "FpN",
        "Vec4f",
        "Vec4d",
        "Index",
        "OnIndex",
        "IndexMask",
        "OnIndexMask",
        "PointIndex",
        "Vec3u8",
        "Vec3u16",
        "UInt8",
    ];
    NAMES
        .get(t as usize)
        .map_or_else(|| format!("GridType({t})"), |s| s.to_string())
}

/// How a grid type's leaves store their values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeafCodec {
    /// 512 plain values starting at this byte offset.
    Plain(usize),
    /// A bit per value after the value mask (`bool`).
    Bits,
    /// No values: a voxel's value is its active state (`ValueMask`).
    Mask,
    /// Fixed-width quantisation: 4, 8 or 16 bits per code.
    Fp(u32),
    /// Variable-width quantisation, the width in the leaf's flags.
    FpN,
}

/// Where a grid type keeps its values in the root, internal nodes and leaves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    pub value_type: ValueType,
    /// Quantised floats (Fp4, Fp8, Fp16, FpN), widened to f32.
    pub quantised: bool,
    /// Bytes of one value in the root and internal nodes.
    pub value_size: usize,
    pub root_background: usize,
    /// Size of `RootData`: the tiles follow it.
    pub root_size: usize,
    pub tile_value: usize,
    pub tile_size: usize,
    /// Byte size of one internal-node table slot (a value or an i64 child offset).
    pub table_stride: usize,
    pub upper_table: usize,
    pub lower_table: usize,
    pub leaf: LeafCodec,
}

impl Layout {
    /// The layout of a NanoVDB grid type, or `None` for types this reader does not decode.
    pub fn of(grid_type: u32) -> Option<Layout> {
        // (value type, size, background, root size, tile value, tile size, stride, upper table, lower table)
        let four = (4, 28, 64, 20, 32, 8, 8256, 1088);
        let eight = (8, 32, 96, 24, 32, 8, 8256, 1088);
        let one = (1, 28, 64, 20, 32, 8, 8256, 1088);
        let (vt, quantised, shape, leaf) = match grid_type {
            1 => (ValueType::Float, false, four, LeafCodec::Plain(96)),
            2 => (ValueType::Double, false, eight, LeafCodec::Plain(128)),
            4 => (ValueType::Int32, false, four, LeafCodec::Plain(96)),
            5 => (ValueType::Int64, false, eight, LeafCodec::Plain(128)),
            6 => (
                ValueType::Vec3f,
                false,
                (12, 28, 96, 20, 32, 16, 8256, 1088),
                LeafCodec::Plain(128),
            ),
            7 => (
                ValueType::Vec3d,
                false,
                (24, 32, 128, 24, 64, 24, 8288, 1120),
                LeafCodec::Plain(160),
            ),
            8 => (ValueType::Mask, false, one, LeafCodec::Mask),
            11 => (ValueType::Bool, false, one, LeafCodec::Bits),
            13 => (ValueType::Float, true, four, LeafCodec::Fp(4)),
            14 => (ValueType::Float, true, four, LeafCodec::Fp(8)),
            15 => (ValueType::Float, true, four, LeafCodec::Fp(16)),
            16 => (ValueType::Float, true, four, LeafCodec::FpN),
            _ => return None,
        };
        let (
            value_size,
            root_background,
            root_size,
            tile_value,
            tile_size,
            table_stride,
            upper_table,
            lower_table,
        ) = shape;
        Some(Layout {
            value_type: vt,
            quantised,
            value_size,
            root_background,
            root_size,
            tile_value,
            tile_size,
            table_stride,
            upper_table,
            lower_table,
            leaf,
        })
    }

    pub fn upper_size(&self) -> usize {
        self.upper_table + 32768 * self.table_stride
    }

    pub fn lower_size(&self) -> usize {
        self.lower_table + 4096 * self.table_stride
    }

    /// The smallest a leaf of this type can be (FpN leaves vary with their bit width).
    pub fn min_leaf_size(&self) -> usize {
        match self.leaf {
            LeafCodec::Plain(at) => (at + 512 * self.value_size).next_multiple_of(32),
            LeafCodec::Bits => BOOL_VALUES + 64 + 16,
            LeafCodec::Mask => MASK_LEAF_SIZE,
            LeafCodec::Fp(bits) => FP_CODES + 64 * bits as usize,
            LeafCodec::FpN => FP_CODES + 64,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_sizes_match_the_cpp_structs() {
        // sizeof(InternalData<..,5>), sizeof(InternalData<..,4>), sizeof(LeafData<..>)
        // printed from NanoVDB 32.4.2's headers.
        let cases = [
            (1, 270400, 33856, 2144),
            (2, 270400, 33856, 4224),
            (4, 270400, 33856, 2144),
            (5, 270400, 33856, 4224),
            (6, 532544, 66624, 6272),
            (7, 794720, 99424, 12448),
            (8, 270400, 33856, 96),
            (11, 270400, 33856, 160),
            (13, 270400, 33856, 352),
            (14, 270400, 33856, 608),
            (15, 270400, 33856, 1120),
            (16, 270400, 33856, 160),
        ];
        for (t, upper, lower, leaf) in cases {
            let l = Layout::of(t).unwrap();
            assert_eq!(
                (l.upper_size(), l.lower_size(), l.min_leaf_size()),
                (upper, lower, leaf),
                "type {t}"
            );
        }
        assert!(Layout::of(9).is_none(), "Half is not decoded");
        assert_eq!(grid_type_name(15), "Fp16");
        assert_eq!(grid_type_name(99), "GridType(99)");
    }
}
