//! The in-memory sparse tree both file formats load into.
//!
//! The shape is OpenVDB's standard `5-4-3` tree, which NanoVDB shares:
//!
//! | level | node            | children per node | spans (voxels) |
//! |-------|-----------------|-------------------|----------------|
//! | 3     | root (hash map) | unbounded         | everything     |
//! | 2     | [`UpperNode`]   | 32^3              | 4096^3         |
//! | 1     | [`LowerNode`]   | 16^3              | 128^3          |
//! | 0     | [`LeafNode`]    | 8^3 voxels        | 8^3            |
//!
//! Every internal slot holds either a child or a tile: one value (active or
//! not) that stands for the whole child-sized box. Nodes of one level live in
//! one arena (`Vec`) and parents refer to children by `u32` index, so a tree
//! is four flat allocations plus the root table and needs no pointers.
//!
//! Slot and voxel offsets are x-major, as in both file formats:
//! `n = (x << 2*LOG2) | (y << LOG2) | z` over the local (child-unit) coordinates.

mod accessor;
mod build;
mod stats;

pub use accessor::Accessor;
pub use stats::{TileCounts, ValueRange};

use crate::mask::BitMask;
use crate::{Coord, CoordBBox, Value};
use std::collections::HashMap;

/// log2 of a leaf's side in voxels.
pub const LEAF_LOG2: u32 = 3;
/// log2 of a lower internal node's side in leaves.
pub const LOWER_LOG2: u32 = 4;
/// log2 of an upper internal node's side in lower nodes.
pub const UPPER_LOG2: u32 = 5;
/// log2 of the voxel span of a leaf, a lower node and an upper node.
pub const LEAF_TOTAL: u32 = LEAF_LOG2;
pub const LOWER_TOTAL: u32 = LEAF_TOTAL + LOWER_LOG2;
pub const UPPER_TOTAL: u32 = LOWER_TOTAL + UPPER_LOG2;

/// Marks a slot without a child in [`InternalNode::children`].
pub const NO_CHILD: u32 = u32::MAX;

/// An 8^3 block of voxels with its active mask.
#[derive(Clone, Debug)]
pub struct LeafNode<V> {
    pub origin: Coord,
    pub value_mask: BitMask<8>,
    pub values: Box<[V; 512]>,
}

impl<V: Value> LeafNode<V> {
    pub fn new(origin: Coord, fill: V, active: bool) -> Self {
        let mut value_mask = BitMask::default();
        if active {
            for n in 0..512 {
                value_mask.set(n, true);
            }
        }
        LeafNode {
            origin,
            value_mask,
            values: Box::new([fill; 512]),
        }
    }

    /// Offset of a voxel inside its leaf.
    #[inline]
    pub fn offset(c: Coord) -> usize {
        (((c.x & 7) as usize) << 6) | (((c.y & 7) as usize) << 3) | ((c.z & 7) as usize)
    }

    /// The voxel at a leaf offset.
    #[inline]
    pub fn coord_of(&self, n: usize) -> Coord {
        self.origin + Coord::new((n >> 6) as i32, ((n >> 3) & 7) as i32, (n & 7) as i32)
    }
}

/// An internal node of `2^LOG2` children a side, `64 * W` slots in all.
#[derive(Clone, Debug)]
pub struct InternalNode<V, const LOG2: u32, const W: usize> {
    pub origin: Coord,
    pub child_mask: BitMask<W>,
    /// Active tiles (never set where a child is).
    pub value_mask: BitMask<W>,
    /// Arena index of the child per slot, [`NO_CHILD`] where there is none.
    pub children: Box<[u32]>,
    /// Tile value per slot, meaningful where there is no child.
    pub tiles: Box<[V]>,
}

/// A 16^3 node over leaves: 128^3 voxels.
pub type LowerNode<V> = InternalNode<V, LOWER_LOG2, 64>;
/// A 32^3 node over lower nodes: 4096^3 voxels.
pub type UpperNode<V> = InternalNode<V, UPPER_LOG2, 512>;

impl<V: Value, const LOG2: u32, const W: usize> InternalNode<V, LOG2, W> {
    pub const SLOTS: usize = 64 * W;

    pub fn new(origin: Coord, fill: V) -> Self {
        InternalNode {
            origin,
            child_mask: BitMask::default(),
            value_mask: BitMask::default(),
            children: vec![NO_CHILD; Self::SLOTS].into_boxed_slice(),
            tiles: vec![fill; Self::SLOTS].into_boxed_slice(),
        }
    }

    /// Slot of the child containing `c`, where `child_total` is log2 of the
    /// child's voxel span.
    #[inline]
    pub fn slot(c: Coord, child_total: u32) -> usize {
        let mask = (1i32 << (LOG2 + child_total)) - 1;
        let x = ((c.x & mask) >> child_total) as usize;
        let y = ((c.y & mask) >> child_total) as usize;
        let z = ((c.z & mask) >> child_total) as usize;
        (x << (2 * LOG2)) | (y << LOG2) | z
    }

    /// Origin of the child box at slot `n`.
    #[inline]
    pub fn slot_origin(&self, n: usize, child_total: u32) -> Coord {
        let m = (1usize << LOG2) - 1;
        let x = (n >> (2 * LOG2)) as i32;
        let y = ((n >> LOG2) & m) as i32;
        let z = (n & m) as i32;
        self.origin + Coord::new(x << child_total, y << child_total, z << child_total)
    }
}

/// What the root table holds at one 4096^3 key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RootSlot<V> {
    /// Index into [`Tree::upper_nodes`].
    Child(u32),
    Tile {
        value: V,
        active: bool,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootEntry<V> {
    pub origin: Coord,
    pub slot: RootSlot<V>,
}

/// A sparse voxel tree with a background value.
#[derive(Clone, Debug)]
pub struct Tree<V> {
    background: V,
    /// Root entries in file order (OpenVDB: sorted by origin).
    root: Vec<RootEntry<V>>,
    root_index: HashMap<Coord, u32>,
    upper: Vec<UpperNode<V>>,
    lower: Vec<LowerNode<V>>,
    leaves: Vec<LeafNode<V>>,
}

/// Where a coordinate's value is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    Leaf,
    Lower,
    Upper,
    Root,
    /// Not covered by any node: the background.
    Background,
}

impl<V: Value> Tree<V> {
    pub fn new(background: V) -> Self {
        Tree {
            background,
            root: Vec::new(),
            root_index: HashMap::new(),
            upper: Vec::new(),
            lower: Vec::new(),
            leaves: Vec::new(),
        }
    }

    pub fn background(&self) -> V {
        self.background
    }
    pub fn root_entries(&self) -> &[RootEntry<V>] {
        &self.root
    }
    pub fn upper_nodes(&self) -> &[UpperNode<V>] {
        &self.upper
    }
    pub fn lower_nodes(&self) -> &[LowerNode<V>] {
        &self.lower
    }
    pub fn leaves(&self) -> &[LeafNode<V>] {
        &self.leaves
    }
    pub fn leaf_count(&self) -> usize {
        self.leaves.len()
    }

    pub(crate) fn root_lookup(&self, c: Coord) -> Option<&RootEntry<V>> {
        self.root_index
            .get(&c.node_origin(UPPER_TOTAL))
            .map(|&i| &self.root[i as usize])
    }

    /// The value at `c`, whether it is active, and the level that stores it.
    pub fn probe(&self, c: Coord) -> (V, bool, Level) {
        let Some(entry) = self.root_lookup(c) else {
            return (self.background, false, Level::Background);
        };
        let upper = match entry.slot {
            RootSlot::Tile { value, active } => return (value, active, Level::Root),
            RootSlot::Child(i) => &self.upper[i as usize],
        };
        let n = UpperNode::<V>::slot(c, LOWER_TOTAL);
        if !upper.child_mask.is_on(n) {
            return (upper.tiles[n], upper.value_mask.is_on(n), Level::Upper);
        }
        let lower = &self.lower[upper.children[n] as usize];
        let n = LowerNode::<V>::slot(c, LEAF_TOTAL);
        if !lower.child_mask.is_on(n) {
            return (lower.tiles[n], lower.value_mask.is_on(n), Level::Lower);
        }
        let leaf = &self.leaves[lower.children[n] as usize];
        let n = LeafNode::<V>::offset(c);
        (leaf.values[n], leaf.value_mask.is_on(n), Level::Leaf)
    }

    pub fn get(&self, c: Coord) -> V {
        self.probe(c).0
    }

    pub fn is_active(&self, c: Coord) -> bool {
        self.probe(c).1
    }

    /// A random-access reader that remembers the last leaf it visited.
    pub fn accessor(&self) -> Accessor<'_, V> {
        Accessor::new(self)
    }

    /// Calls `f(coord, value)` for every active voxel stored in a leaf.
    pub fn for_each_active_voxel(&self, mut f: impl FnMut(Coord, V)) {
        for leaf in &self.leaves {
            for n in leaf.value_mask.iter_on() {
                f(leaf.coord_of(n), leaf.values[n]);
            }
        }
    }

    /// Calls `f(box, value, level)` for every active tile at any level.
    pub fn for_each_active_tile(&self, mut f: impl FnMut(CoordBBox, V, Level)) {
        for e in &self.root {
            if let RootSlot::Tile {
                value,
                active: true,
            } = e.slot
            {
                f(
                    CoordBBox::from_origin(e.origin, 1 << UPPER_TOTAL),
                    value,
                    Level::Root,
                );
            }
        }
        for node in &self.upper {
            for n in node.value_mask.iter_on() {
                let o = node.slot_origin(n, LOWER_TOTAL);
                f(
                    CoordBBox::from_origin(o, 1 << LOWER_TOTAL),
                    node.tiles[n],
                    Level::Upper,
                );
            }
        }
        for node in &self.lower {
            for n in node.value_mask.iter_on() {
                let o = node.slot_origin(n, LEAF_TOTAL);
                f(
                    CoordBBox::from_origin(o, 1 << LEAF_TOTAL),
                    node.tiles[n],
                    Level::Lower,
                );
            }
        }
    }

    /// Bytes this tree occupies in memory (nodes, tables and the root map).
    pub fn memory_bytes(&self) -> usize {
        memory_bytes::<V>(NodeCounts {
            root_entries: self.root.len() as u64,
            upper: self.upper.len() as u64,
            lower: self.lower.len() as u64,
            leaves: self.leaves.len() as u64,
        })
    }
}

/// How many nodes of each level a tree has (root entries: tiles and children).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NodeCounts {
    pub root_entries: u64,
    pub upper: u64,
    pub lower: u64,
    pub leaves: u64,
}

/// Bytes a [`Tree`] of value `V` with these node counts occupies in memory,
/// without building it: what [`Tree::memory_bytes`] reports.
pub fn memory_bytes<V: Value>(n: NodeCounts) -> usize {
    use std::mem::size_of;
    let internal = |slots: usize, w: usize| 2 * 8 * w + slots * (4 + size_of::<V>()) + 12;
    n.leaves as usize * (size_of::<LeafNode<V>>() + 512 * size_of::<V>())
        + n.lower as usize * internal(4096, 64)
        + n.upper as usize * internal(32768, 512)
        + n.root_entries as usize * (size_of::<RootEntry<V>>() + 16)
}
