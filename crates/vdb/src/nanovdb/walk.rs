//! The descent from the root of a grid buffer to its leaves, building the tree.
//!
//! Nodes are found only by following child offsets from the root (never by
//! assuming the breadth-first order the writers use). Every offset is checked
//! against the buffer, every node may be reached once, and no level may hold
//! more nodes than `TreeData` declares (which in turn must fit in the buffer),
//! so a corrupt buffer can neither loop nor make the reader allocate more than
//! a small multiple of its own size. Leaves are decoded in parallel at the end.

use super::buf::Buf;
use super::layout::{self, Layout, LeafCodec};
use crate::error::{corrupt, KindResult};
use crate::grid::GridTree;
use crate::mask::BitMask;
use crate::tree::{
    InternalNode, LeafNode, LowerNode, RootSlot, LEAF_TOTAL, LOWER_LOG2, LOWER_TOTAL, UPPER_LOG2,
};
use crate::{Coord, Tree, Value, ValueType};
use rayon::prelude::*;
use std::collections::HashSet;

/// Builds the tree of a grid of layout `lay`, choosing the value type and leaf decoder.
pub fn build_tree(b: Buf, lay: &Layout) -> KindResult<GridTree> {
    use LeafCodec::*;
    Ok(match (lay.value_type, lay.leaf) {
        (ValueType::Float, Plain(at)) => GridTree::Float(Walk::run(b, lay, from_bytes, plain(at))?),
        (ValueType::Float, Fp(bits)) => {
            GridTree::Float(Walk::run(b, lay, from_bytes, move |l, o| fp(l, bits, o))?)
        }
        (ValueType::Float, FpN) => GridTree::Float(Walk::run(b, lay, from_bytes, fpn)?),
        (ValueType::Double, Plain(at)) => {
            GridTree::Double(Walk::run(b, lay, from_bytes, plain(at))?)
        }
        (ValueType::Int32, Plain(at)) => GridTree::Int32(Walk::run(b, lay, from_bytes, plain(at))?),
        (ValueType::Int64, Plain(at)) => GridTree::Int64(Walk::run(b, lay, from_bytes, plain(at))?),
        (ValueType::Vec3f, Plain(at)) => GridTree::Vec3f(Walk::run(b, lay, from_bytes, plain(at))?),
        (ValueType::Vec3d, Plain(at)) => GridTree::Vec3d(Walk::run(b, lay, from_bytes, plain(at))?),
        (ValueType::Bool, Bits) => GridTree::Bool(Walk::run(b, lay, from_bytes, bits)?),
        // A mask grid's value is its active state, at every level.
        (ValueType::Mask, Mask) => GridTree::Mask(Walk::run(b, lay, |_, on| on, mask_values)?),
        (vt, codec) => {
            return Err(corrupt(format!(
                "no decoder for {vt:?} leaves stored as {codec:?}"
            )))
        }
    })
}

fn plain<V: Value>(at: usize) -> impl Fn(&[u8], &mut [V; 512]) + Sync {
    move |leaf, out| plain_values(leaf, at, out)
}

fn from_bytes<V: Value>(bytes: &[u8], _active: bool) -> V {
    V::from_le(bytes)
}

fn plain_values<V: Value>(leaf: &[u8], at: usize, out: &mut [V; 512]) {
    for (v, chunk) in out
        .iter_mut()
        .zip(leaf[at..at + 512 * V::SIZE].chunks_exact(V::SIZE))
    {
        *v = V::from_le(chunk);
    }
}

fn bits(leaf: &[u8], out: &mut [bool; 512]) {
    let m = BitMask::<8>::from_le_bytes(&leaf[layout::BOOL_VALUES..layout::BOOL_VALUES + 64]);
    for (n, v) in out.iter_mut().enumerate() {
        *v = m.is_on(n);
    }
}

fn mask_values(leaf: &[u8], out: &mut [bool; 512]) {
    let m =
        BitMask::<8>::from_le_bytes(&leaf[layout::LEAF_VALUE_MASK..layout::LEAF_VALUE_MASK + 64]);
    for (n, v) in out.iter_mut().enumerate() {
        *v = m.is_on(n);
    }
}

fn f32_at(leaf: &[u8], at: usize) -> f32 {
    f32::from_le_bytes(leaf[at..at + 4].try_into().unwrap())
}

/// Fp4, Fp8, Fp16: `value = code * quantum + minimum`, codes packed low bits first.
fn fp(leaf: &[u8], bits: u32, out: &mut [f32; 512]) {
    let (min, quantum) = (
        f32_at(leaf, layout::FP_MINIMUM),
        f32_at(leaf, layout::FP_QUANTUM),
    );
    let codes = &leaf[layout::FP_CODES..];
    for (i, v) in out.iter_mut().enumerate() {
        let code = match bits {
            4 => ((codes[i >> 1] >> ((i & 1) << 2)) & 15) as u16,
            8 => codes[i] as u16,
            _ => u16::from_le_bytes([codes[2 * i], codes[2 * i + 1]]),
        };
        *v = code as f32 * quantum + min;
    }
}

/// FpN: the bit width is `1 << (flags >> 5)`, codes packed in 32-bit words.
fn fpn(leaf: &[u8], out: &mut [f32; 512]) {
    let (min, quantum) = (
        f32_at(leaf, layout::FP_MINIMUM),
        f32_at(leaf, layout::FP_QUANTUM),
    );
    let b = (leaf[layout::LEAF_FLAGS] >> 5) as usize; // checked <= 4 by the walk
    let codes = &leaf[layout::FP_CODES..];
    let mask = (1u32 << (1u32 << b)) - 1;
    for (i, v) in out.iter_mut().enumerate() {
        let w = (i >> (5 - b)) * 4;
        let word = u32::from_le_bytes(codes[w..w + 4].try_into().unwrap());
        let code = (word >> ((i & ((32 >> b) - 1)) << b)) & mask;
        *v = code as f32 * quantum + min;
    }
}

/// The descent from the root: checks offsets, builds internal nodes, and
/// queues leaves, which are decoded in parallel at the end.
struct Walk<'a, V> {
    b: Buf<'a>,
    lay: &'a Layout,
    tile: fn(&[u8], bool) -> V,
    /// Nodes `TreeData` declares per level (leaf, lower, upper).
    declared: [u64; 3],
    seen: [HashSet<usize>; 3],
    /// Byte offset, size and origin of each leaf, in arena order.
    leaves: Vec<(usize, usize, Coord)>,
}

/// A node's children: slot and byte offset relative to the node.
type ChildOffsets = Vec<(usize, i64)>;

/// Each level's name, singular and plural, for messages.
const LEVEL_NAMES: [(&str, &str); 3] = [
    ("leaf", "leaves"),
    ("lower node", "lower nodes"),
    ("upper node", "upper nodes"),
];

/// The node counts the tree declares per level (leaves, lower, upper),
/// checked to fit in the buffer: this bounds every allocation of the walk.
fn declared_nodes(b: Buf<'_>, lay: &Layout) -> KindResult<[u64; 3]> {
    let tree_at = layout::GRID_DATA_SIZE;
    let mut declared = [0u64; 3];
    for (level, d) in declared.iter_mut().enumerate() {
        *d = b.u32(tree_at + layout::tree::NODE_COUNT + 4 * level, "node count")? as u64;
    }
    let sizes = [lay.min_leaf_size(), lay.lower_size(), lay.upper_size()];
    let needed: u128 = declared
        .iter()
        .zip(sizes)
        .map(|(&n, s)| n as u128 * s as u128)
        .sum();
    if needed > b.0.len() as u128 {
        return Err(corrupt(format!(
            "tree declares {} leaves, {} lower and {} upper nodes: more than its {}-byte buffer holds",
            declared[0],
            declared[1],
            declared[2],
            b.0.len()
        )));
    }
    Ok(declared)
}

impl<'a, V: Value> Walk<'a, V> {
    fn run(
        b: Buf<'a>,
        lay: &'a Layout,
        tile: fn(&[u8], bool) -> V,
        leaf_values: impl Fn(&[u8], &mut [V; 512]) + Sync,
    ) -> KindResult<Tree<V>> {
        let tree_at = layout::GRID_DATA_SIZE;
        let declared = declared_nodes(b, lay)?;
        let root_rel = b.u64(tree_at + layout::tree::NODE_OFFSET + 24, "root offset")?;
        let root = usize::try_from(root_rel)
            .ok()
            .and_then(|r| r.checked_add(tree_at))
            .ok_or_else(|| corrupt("root offset out of range"))?;
        b.bytes(root, lay.root_size, "root node")?;
        let table_size = b.u32(root + layout::ROOT_TABLE_SIZE, "root table size")? as usize;
        b.bytes(
            root + lay.root_size,
            table_size * lay.tile_size,
            "root table",
        )?;
        let background = (tile)(
            b.bytes(root + lay.root_background, lay.value_size, "background")?,
            false,
        );

        let mut walk = Walk {
            b,
            lay,
            tile,
            declared,
            seen: Default::default(),
            leaves: Vec::new(),
        };
        let mut tree = Tree::new(background);
        for t in 0..table_size {
            let at = root + lay.root_size + t * lay.tile_size;
            let origin = key_origin(b.u64(at + layout::tile::KEY, "root key")?)?;
            let child = b.i64(at + layout::tile::CHILD, "root child")?;
            let slot = if child == 0 {
                let active = b.u32(at + layout::tile::STATE, "root tile state")? != 0;
                let value = (tile)(
                    b.bytes(at + lay.tile_value, lay.value_size, "root tile value")?,
                    active,
                );
                RootSlot::Tile { value, active }
            } else {
                let upper = walk.child(root, child, 2, lay.upper_size())?;
                RootSlot::Child(walk.upper(&mut tree, upper, origin)?)
            };
            tree.insert_root(origin, slot)?;
        }
        for leaf in walk.decoded_leaves(leaf_values) {
            tree.push_leaf(leaf);
        }
        Ok(tree)
    }

    /// The leaves the walk found, their values decoded in parallel.
    fn decoded_leaves(
        &self,
        leaf_values: impl Fn(&[u8], &mut [V; 512]) + Sync,
    ) -> Vec<LeafNode<V>> {
        let b = self.b;
        self.leaves
            .par_iter()
            .map(|&(off, size, origin)| {
                let leaf = &b.0[off..off + size];
                let m = layout::LEAF_VALUE_MASK;
                let value_mask = BitMask::from_le_bytes(&leaf[m..m + 64]);
                let mut values = Box::new([V::default(); 512]);
                leaf_values(leaf, &mut values);
                LeafNode {
                    origin,
                    value_mask,
                    values,
                }
            })
            .collect()
    }

    /// Resolves a child offset relative to `base`, checks the node lies in
    /// the buffer, is new, and that its level has room for it.
    fn child(&mut self, base: usize, rel: i64, level: usize, size: usize) -> KindResult<usize> {
        let (what, plural) = LEVEL_NAMES[level];
        let off = (base as i64)
            .checked_add(rel)
            .and_then(|o| usize::try_from(o).ok())
            .ok_or_else(|| {
                corrupt(format!(
                    "{what} offset {rel} from byte {base} points before the buffer"
                ))
            })?;
        self.b.bytes(off, size, what)?;
        if !self.seen[level].insert(off) {
            return Err(corrupt(format!(
                "two parents share the {what} at byte {off}"
            )));
        }
        if self.seen[level].len() as u64 > self.declared[level] {
            return Err(corrupt(format!(
                "more {plural} than the {} the tree declares",
                self.declared[level]
            )));
        }
        Ok(off)
    }

    /// Masks and table of an internal node; returns the node and its child offsets by slot.
    fn internal<const LOG2: u32, const W: usize>(
        &self,
        off: usize,
        origin: Coord,
        table: usize,
    ) -> KindResult<(InternalNode<V, LOG2, W>, ChildOffsets)> {
        let (b, lay) = (self.b, self.lay);
        let mut node = InternalNode::<V, LOG2, W>::new(origin, V::default());
        let vm = off + layout::INTERNAL_VALUE_MASK;
        let bytes = BitMask::<W>::BYTES;
        node.value_mask = BitMask::from_le_bytes(b.bytes(vm, bytes, "value mask")?);
        node.child_mask = BitMask::from_le_bytes(b.bytes(vm + bytes, bytes, "child mask")?);
        let slots = b.bytes(
            off + table,
            InternalNode::<V, LOG2, W>::SLOTS * lay.table_stride,
            "node table",
        )?;
        let mut children = Vec::new();
        for (n, slot) in slots.chunks_exact(lay.table_stride).enumerate() {
            if node.child_mask.is_on(n) {
                // A slot is a child or a tile, never both.
                node.value_mask.set(n, false);
                children.push((n, i64::from_le_bytes(slot[..8].try_into().unwrap())));
            } else {
                node.tiles[n] = (self.tile)(&slot[..lay.value_size], node.value_mask.is_on(n));
            }
        }
        Ok((node, children))
    }

    fn upper(&mut self, tree: &mut Tree<V>, off: usize, origin: Coord) -> KindResult<u32> {
        let (mut node, children) =
            self.internal::<UPPER_LOG2, 512>(off, origin, self.lay.upper_table)?;
        for (n, rel) in children {
            let lower = self.child(off, rel, 1, self.lay.lower_size())?;
            node.children[n] = self.lower(tree, lower, node.slot_origin(n, LOWER_TOTAL))?;
        }
        Ok(tree.push_upper(node))
    }

    fn lower(&mut self, tree: &mut Tree<V>, off: usize, origin: Coord) -> KindResult<u32> {
        let (mut node, children): (LowerNode<V>, _) =
            self.internal::<LOWER_LOG2, 64>(off, origin, self.lay.lower_table)?;
        for (n, rel) in children {
            let size = self.leaf_size(off, rel)?;
            let leaf = self.child(off, rel, 0, size)?;
            node.children[n] = self.leaves.len() as u32;
            self.leaves
                .push((leaf, size, node.slot_origin(n, LEAF_TOTAL)));
        }
        Ok(tree.push_lower(node))
    }

    /// Byte size of the leaf at `rel` from `base`: fixed per type except FpN.
    fn leaf_size(&self, base: usize, rel: i64) -> KindResult<usize> {
        let fixed = self.lay.min_leaf_size();
        if self.lay.leaf != LeafCodec::FpN {
            return Ok(fixed);
        }
        let off = (base as i64)
            .checked_add(rel)
            .and_then(|o| usize::try_from(o).ok())
            .unwrap_or(usize::MAX);
        let flags = self.b.bytes(off, fixed, "leaf")?[layout::LEAF_FLAGS];
        let b = flags >> 5;
        if b > 4 {
            return Err(corrupt(format!(
                "FpN leaf at byte {off} has bit-width code {b}"
            )));
        }
        Ok(layout::FP_CODES + 64 * (1usize << b))
    }
}

/// Decodes a root key: 21 bits per axis, x highest, each the coordinate as an
/// unsigned 32-bit integer shifted right by 12 (so negative coordinates wrap).
pub fn key_origin(key: u64) -> KindResult<Coord> {
    const FIELD: u64 = (1 << 21) - 1;
    let (x, y, z) = ((key >> 42) & FIELD, (key >> 21) & FIELD, key & FIELD);
    // A 32-bit coordinate shifted by 12 leaves 20 bits: the top bit of each field, and bit 63, are unused.
    if key >> 63 != 0 || (x | y | z) >> 20 != 0 {
        return Err(corrupt(format!(
            "root key {key:#018x} is not a coordinate key"
        )));
    }
    let axis = |v: u64| ((v as u32) << 12) as i32;
    Ok(Coord::new(axis(x), axis(y), axis(z)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fpn_decodes_every_bit_width() {
        for b in 0..=4u8 {
            let width = 1usize << b;
            let mut leaf = vec![0u8; layout::FP_CODES + 64 * width];
            leaf[layout::LEAF_FLAGS] = b << 5;
            leaf[layout::FP_MINIMUM..layout::FP_MINIMUM + 4]
                .copy_from_slice(&(-1.0f32).to_le_bytes());
            leaf[layout::FP_QUANTUM..layout::FP_QUANTUM + 4].copy_from_slice(&0.5f32.to_le_bytes());
            let max = (1u32 << width) - 1;
            // code of voxel i is i mod 2^width, packed low bits first
            let mut bitpos = 0;
            for i in 0..512u32 {
                let code = i & max;
                for k in 0..width {
                    if code >> k & 1 != 0 {
                        leaf[layout::FP_CODES + bitpos / 8] |= 1 << (bitpos % 8);
                    }
                    bitpos += 1;
                }
            }
            let mut out = [0f32; 512];
            fpn(&leaf, &mut out);
            for (i, v) in out.iter().enumerate() {
                assert_eq!(
                    *v,
                    (i as u32 & max) as f32 * 0.5 - 1.0,
                    "width {width} voxel {i}"
                );
            }
        }
    }

    fn fog_buffer() -> Vec<u8> {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/fog.nvdb");
        std::fs::read(path).unwrap()[200..].to_vec()
    }

    fn parse(buf: &[u8]) -> KindResult<crate::grid::Grid> {
        super::super::grid::parse_grid(buf, "density".into())
    }

    fn put(buf: &mut [u8], at: usize, bytes: &[u8]) {
        buf[at..at + bytes.len()].copy_from_slice(bytes);
    }

    /// Byte offsets of the first upper and lower node, from `TreeData`.
    fn nodes(buf: &[u8]) -> (usize, usize) {
        let b = Buf(buf);
        let tree = layout::GRID_DATA_SIZE;
        let at = |level: usize| tree + b.u64(tree + 8 * level, "offset").unwrap() as usize;
        (at(2), at(1))
    }

    fn message(r: KindResult<crate::grid::Grid>) -> String {
        match r {
            Err(crate::error::ErrorKind::Corrupt(m)) => m,
            Err(e) => panic!("expected corrupt data, got {e}"),
            Ok(_) => panic!("expected an error"),
        }
    }

    #[test]
    fn shared_children_and_miscounted_nodes_are_refused() {
        let buf = fog_buffer();
        assert_eq!(parse(&buf).unwrap().tree.leaf_count(), 13);
        let (upper, lower) = nodes(&buf);
        let lay = Layout::of(1).unwrap();
        // Upper slot 0 holds the lower node; make slot 1 a second parent of it.
        let child_mask = upper + layout::INTERNAL_VALUE_MASK + 4096;
        assert_eq!(buf[child_mask] & 3, 1);
        let mut shared = buf.clone();
        shared[child_mask] |= 2;
        let rel = (lower as i64 - upper as i64).to_le_bytes();
        put(
            &mut shared,
            upper + lay.upper_table + lay.table_stride,
            &rel,
        );
        assert!(message(parse(&shared)).contains("two parents share the lower node"));
        // A child offset pointing past the buffer, or before it.
        for rel in [1i64 << 40, -(1i64 << 40), buf.len() as i64] {
            let mut far = buf.clone();
            put(&mut far, upper + lay.upper_table, &rel.to_le_bytes());
            assert!(message(parse(&far)).contains("lower node"));
        }
        // Fewer leaves declared than linked, and more than the buffer can hold.
        let count = layout::GRID_DATA_SIZE + layout::tree::NODE_COUNT;
        let mut fewer = buf.clone();
        put(&mut fewer, count, &12u32.to_le_bytes());
        assert!(message(parse(&fewer)).contains("more leaves than the 12"));
        let mut more = buf.clone();
        put(&mut more, count, &u32::MAX.to_le_bytes());
        assert!(message(parse(&more)).contains("more than its"));
        // A root key with bits no coordinate sets.
        let root = layout::GRID_DATA_SIZE
            + Buf(&buf).u64(layout::GRID_DATA_SIZE + 24, "root").unwrap() as usize;
        let mut key = buf.clone();
        key[root + lay.root_size + 7] |= 0x80;
        assert!(message(parse(&key)).contains("root key"));
    }

    /// Random words written over the grid header, tree header, root table,
    /// node masks and child tables: errors or trees, never a panic.
    #[test]
    fn random_mutations_of_the_node_structure_never_panic() {
        let buf = fog_buffer();
        let (upper, lower) = nodes(&buf);
        let lay = Layout::of(1).unwrap();
        let (masks, table) = (layout::INTERNAL_VALUE_MASK, lay.upper_table);
        let regions = [
            (
                0,
                layout::GRID_DATA_SIZE + layout::TREE_DATA_SIZE + lay.root_size + 2 * lay.tile_size,
            ),
            (upper, upper + masks + 64),
            (upper + masks + 4096, upper + masks + 4096 + 64),
            (upper + table, upper + table + 64),
            (lower, lower + masks + 1024),
            (lower + lay.lower_table, lower + lay.lower_size()),
            (lower + lay.lower_size(), buf.len()),
        ];
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let (mut ok, mut err) = (0, 0);
        for _ in 0..1000 {
            let mut b = buf.clone();
            let (lo, hi) = regions[(next() % regions.len() as u64) as usize];
            let at = lo + (next() as usize % (hi - lo - 8));
            let word = match next() % 4 {
                0 => next(),
                1 => u64::MAX,
                2 => next() % 64,
                _ => (next() % 0x10_0000).wrapping_neg(),
            };
            put(&mut b, at, &word.to_le_bytes()[..1 + (next() % 8) as usize]);
            match parse(&b) {
                Ok(_) => ok += 1,
                Err(_) => err += 1,
            }
        }
        assert!(ok > 0 && err > 0, "{ok} parsed, {err} refused");
    }

    #[test]
    fn root_keys_decode_negative_and_positive_origins() {
        let key = |x: i32, y: i32, z: i32| {
            ((x as u32 >> 12) as u64) << 42
                | ((y as u32 >> 12) as u64) << 21
                | (z as u32 >> 12) as u64
        };
        for c in [
            (0, 0, 0),
            (4096, 0, 8192),
            (-4096, 4096, -8192),
            (i32::MIN, i32::MAX & !4095, -4096),
        ] {
            let k = key(c.0, c.1, c.2);
            assert_eq!(key_origin(k).unwrap(), Coord::new(c.0, c.1, c.2));
        }
        assert!(key_origin(1 << 63).is_err());
        assert!(key_origin(1 << 20).is_err());
    }
}
