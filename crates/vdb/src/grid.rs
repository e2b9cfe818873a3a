//! A loaded grid: its tree of one value type, transform, class and metadata.

use crate::metadata::MetaMap;
use crate::tree::{TileCounts, ValueRange};
use crate::{CoordBBox, Transform, Tree, ValueType};

/// OpenVDB's grid class (the `class` metadata).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridClass {
    Unknown,
    LevelSet,
    FogVolume,
    Staggered,
}

impl GridClass {
    pub fn name(self) -> &'static str {
        match self {
            GridClass::Unknown => "unknown",
            GridClass::LevelSet => "level set",
            GridClass::FogVolume => "fog volume",
            GridClass::Staggered => "staggered",
        }
    }
    pub fn from_name(s: &str) -> GridClass {
        match s {
            "level set" => GridClass::LevelSet,
            "fog volume" => GridClass::FogVolume,
            "staggered" => GridClass::Staggered,
            _ => GridClass::Unknown,
        }
    }
}

/// A grid's tree, by value type.
#[derive(Clone, Debug)]
pub enum GridTree {
    Float(Tree<f32>),
    Double(Tree<f64>),
    Int32(Tree<i32>),
    Int64(Tree<i64>),
    Bool(Tree<bool>),
    /// Topology only: values are true exactly where active.
    Mask(Tree<bool>),
    Vec3f(Tree<[f32; 3]>),
    Vec3d(Tree<[f64; 3]>),
}

/// Runs `$body` with `$t` bound to the tree, whatever its value type.
macro_rules! with_tree {
    ($tree:expr, $t:ident => $body:expr) => {
        match $tree {
            GridTree::Float($t) => $body,
            GridTree::Double($t) => $body,
            GridTree::Int32($t) => $body,
            GridTree::Int64($t) => $body,
            GridTree::Bool($t) | GridTree::Mask($t) => $body,
            GridTree::Vec3f($t) => $body,
            GridTree::Vec3d($t) => $body,
        }
    };
}

impl GridTree {
    pub fn value_type(&self) -> ValueType {
        match self {
            GridTree::Float(_) => ValueType::Float,
            GridTree::Double(_) => ValueType::Double,
            GridTree::Int32(_) => ValueType::Int32,
            GridTree::Int64(_) => ValueType::Int64,
            GridTree::Bool(_) => ValueType::Bool,
            GridTree::Mask(_) => ValueType::Mask,
            GridTree::Vec3f(_) => ValueType::Vec3f,
            GridTree::Vec3d(_) => ValueType::Vec3d,
        }
    }
    pub fn active_voxel_count(&self) -> u64 {
        with_tree!(self, t => t.active_voxel_count())
    }
    pub fn leaf_count(&self) -> usize {
        with_tree!(self, t => t.leaf_count())
    }
    pub fn active_tile_counts(&self) -> TileCounts {
        with_tree!(self, t => t.active_tile_counts())
    }
    pub fn active_bbox(&self) -> Option<CoordBBox> {
        with_tree!(self, t => t.active_bbox())
    }
    pub fn value_range(&self) -> Option<ValueRange> {
        with_tree!(self, t => t.value_range())
    }
    pub fn memory_bytes(&self) -> usize {
        with_tree!(self, t => t.memory_bytes())
    }
    /// The value at `c` as up to three f64 components, and whether it is active.
    pub fn probe_components(&self, c: crate::Coord) -> ([f64; 3], usize, bool) {
        use crate::Value;
        with_tree!(self, t => {
            let (v, active, _) = t.probe(c);
            let (comp, n) = v.components();
            (comp, n, active)
        })
    }
    /// The background as up to three f64 components.
    pub fn background_components(&self) -> ([f64; 3], usize) {
        use crate::Value;
        with_tree!(self, t => t.background().components())
    }
}

/// One grid read from a file.
#[derive(Clone, Debug)]
pub struct Grid {
    /// The grid's name (for duplicates, without OpenVDB's `\x1e<n>` suffix).
    pub name: String,
    pub class: GridClass,
    pub transform: Transform,
    pub metadata: MetaMap,
    pub tree: GridTree,
    /// Stored as 16-bit floats (widened to f32 on load); NanoVDB quantised
    /// grids (Fp16 and friends) say so here too.
    pub half_float: bool,
}

impl Grid {
    /// The float tree of a scalar grid, if it is one.
    pub fn float_tree(&self) -> Option<&Tree<f32>> {
        match &self.tree {
            GridTree::Float(t) => Some(t),
            _ => None,
        }
    }
}

/// What is known of a grid from the file's index, before its data is read.
#[derive(Clone, Debug, PartialEq)]
pub struct GridInfo {
    /// The grid's name; several grids may share it.
    pub name: String,
    /// The name as stored, unique within the file (`density\x1e1` for the
    /// second grid named `density` in an OpenVDB file).
    pub unique_name: String,
    /// The file's type name for the grid (OpenVDB `Tree_float_5_4_3`, NanoVDB `Float`).
    pub type_name: String,
    /// The value type, when the reader supports the grid's type.
    pub value_type: Option<ValueType>,
    pub half_float: bool,
    /// Bytes of the file the grid's data occupies.
    pub byte_len: u64,
}
