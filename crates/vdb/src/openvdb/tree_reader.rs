//! Reads a grid's tree: topology (root, internal nodes, leaf masks) and then
//! the leaf buffers, as `Tree::readTopology` and `Tree::readBuffers` write them.
//!
//! Leaf buffers follow in the same depth-first order as the topology, and
//! each is a self-contained record, so a first pass finds where each starts
//! (cheap: it only reads sizes) and a second decodes them in parallel.

use super::compression::{read_compressed_values, StreamContext};
use crate::bytes::ByteCursor;
use crate::error::{corrupt, unsupported, KindResult};
use crate::mask::BitMask;
use crate::tree::{LeafNode, LowerNode, RootSlot, UpperNode, LEAF_TOTAL, LOWER_TOTAL};
use crate::{Coord, Tree, Value};
use rayon::prelude::*;

/// How a tree's leaves store their values.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum LeafKind {
    /// A value buffer per leaf (`LeafNode<T>`).
    Values,
    /// `LeafNode<bool>`: value mask, origin, then a bit mask of values.
    Bool,
    /// `LeafNode<ValueMask>`: value mask and origin; values equal the mask.
    Mask,
}

/// Reads the topology starting at `cur`, then the leaf buffers that follow it.
pub fn read_tree<V: Value>(
    cur: &mut ByteCursor,
    compression: u32,
    half: bool,
    kind: LeafKind,
) -> KindResult<Tree<V>> {
    let buffer_count = cur.i32("tree buffer count")?;
    if buffer_count != 1 {
        return Err(unsupported(format!("tree with {buffer_count} buffers")));
    }
    let background = V::from_le(cur.take(V::SIZE, "background value")?);
    let ctx = StreamContext {
        compression,
        background,
        half,
    };
    let mut tree = Tree::new(background);
    let num_tiles = cur.u32("root tile count")?;
    let num_children = cur.u32("root child count")?;
    cur.ensure(num_tiles as u64, 12 + V::SIZE as u64 + 1, "root tiles")?;
    for _ in 0..num_tiles {
        let origin = cur.coord("root tile origin")?;
        let value = V::from_le(cur.take(V::SIZE, "root tile value")?);
        let active = cur.u8("root tile state")? != 0;
        tree.insert_root(origin, RootSlot::Tile { value, active })?;
    }
    // Each child needs at least its origin and two 4 KiB masks.
    cur.ensure(num_children as u64, 12 + 2 * 4096, "root children")?;
    let mut scratch = Vec::new();
    for _ in 0..num_children {
        let origin = cur.coord("root child origin")?;
        if origin.node_origin(crate::tree::UPPER_TOTAL) != origin {
            return Err(corrupt(format!(
                "root child origin {origin:?} is not a multiple of 4096"
            )));
        }
        let index = read_upper(cur, &ctx, &mut tree, origin, kind, &mut scratch)?;
        tree.insert_root(origin, RootSlot::Child(index))?;
    }
    read_leaf_buffers(cur, &ctx, &mut tree, kind)?;
    Ok(tree)
}

/// Reads an internal node's masks and tile values; returns the node and the
/// slots that hold children, in order.
fn read_internal_header<V: Value, const LOG2: u32, const W: usize>(
    cur: &mut ByteCursor,
    ctx: &StreamContext<V>,
    origin: Coord,
    scratch: &mut Vec<u8>,
) -> KindResult<crate::tree::InternalNode<V, LOG2, W>> {
    let mut node = crate::tree::InternalNode::<V, LOG2, W>::new(origin, ctx.background);
    node.child_mask = BitMask::from_le_bytes(cur.take(BitMask::<W>::BYTES, "child mask")?);
    node.value_mask = BitMask::from_le_bytes(cur.take(BitMask::<W>::BYTES, "value mask")?);
    read_compressed_values(cur, ctx, &node.value_mask, Some(&mut node.tiles), scratch)?;
    // A slot is a child or a tile, never both.
    for n in node.child_mask.iter_on().collect::<Vec<_>>() {
        node.value_mask.set(n, false);
    }
    Ok(node)
}

fn read_upper<V: Value>(
    cur: &mut ByteCursor,
    ctx: &StreamContext<V>,
    tree: &mut Tree<V>,
    origin: Coord,
    kind: LeafKind,
    scratch: &mut Vec<u8>,
) -> KindResult<u32> {
    let mut node: UpperNode<V> = read_internal_header(cur, ctx, origin, scratch)?;
    let slots: Vec<usize> = node.child_mask.iter_on().collect();
    cur.ensure(slots.len() as u64, 2 * 512, "lower nodes")?;
    for n in slots {
        let child_origin = node.slot_origin(n, LOWER_TOTAL);
        node.children[n] = read_lower(cur, ctx, tree, child_origin, kind, scratch)?;
    }
    Ok(tree.push_upper(node))
}

fn read_lower<V: Value>(
    cur: &mut ByteCursor,
    ctx: &StreamContext<V>,
    tree: &mut Tree<V>,
    origin: Coord,
    kind: LeafKind,
    scratch: &mut Vec<u8>,
) -> KindResult<u32> {
    let mut node: LowerNode<V> = read_internal_header(cur, ctx, origin, scratch)?;
    let slots: Vec<usize> = node.child_mask.iter_on().collect();
    cur.ensure(slots.len() as u64, 64, "leaf masks")?;
    for n in slots {
        let leaf_origin = node.slot_origin(n, LEAF_TOTAL);
        let mask = BitMask::<8>::from_le_bytes(cur.take(64, "leaf value mask")?);
        let mut leaf = LeafNode::new(leaf_origin, ctx.background, false);
        leaf.value_mask = mask;
        if kind == LeafKind::Mask {
            fill_from_mask(&mut leaf);
        }
        node.children[n] = tree.push_leaf(leaf);
    }
    Ok(tree.push_lower(node))
}

fn fill_from_mask<V: Value>(leaf: &mut LeafNode<V>) {
    // Only bool trees are read as masks; `from_le(&[1])` is `true` for them.
    let on = V::from_le(&[1u8; 32]);
    let off = V::from_le(&[0u8; 32]);
    for i in 0..512 {
        leaf.values[i] = if leaf.value_mask.is_on(i) { on } else { off };
    }
}

fn read_leaf_buffers<V: Value>(
    cur: &mut ByteCursor,
    ctx: &StreamContext<V>,
    tree: &mut Tree<V>,
    kind: LeafKind,
) -> KindResult<()> {
    let leaves = tree.leaves_mut();
    match kind {
        LeafKind::Mask => {
            cur.ensure(leaves.len() as u64, 64 + 12, "mask leaf buffers")?;
            for leaf in leaves.iter_mut() {
                check_leaf_header(cur, leaf)?;
                fill_from_mask(leaf);
            }
        }
        LeafKind::Bool => {
            cur.ensure(leaves.len() as u64, 64 + 12 + 64, "bool leaf buffers")?;
            for leaf in leaves.iter_mut() {
                check_leaf_header(cur, leaf)?;
                let bits = BitMask::<8>::from_le_bytes(cur.take(64, "bool leaf values")?);
                let (on, off) = (V::from_le(&[1u8; 32]), V::from_le(&[0u8; 32]));
                for i in 0..512 {
                    leaf.values[i] = if bits.is_on(i) { on } else { off };
                }
            }
        }
        LeafKind::Values => {
            // Pass 1: where each leaf's record starts.
            cur.ensure(leaves.len() as u64, 64 + 1, "leaf buffers")?;
            let mut starts = Vec::with_capacity(leaves.len());
            let mut scratch = Vec::new();
            for leaf in leaves.iter() {
                starts.push(cur.clone());
                cur.skip(64, "leaf value mask")?;
                read_compressed_values(cur, ctx, &leaf.value_mask, None, &mut scratch)?;
            }
            // Pass 2: decode every record on its own.
            leaves
                .par_iter_mut()
                .zip(starts.into_par_iter())
                .try_for_each_init(Vec::new, |scratch, (leaf, mut c)| {
                    c.skip(64, "leaf value mask")?;
                    let LeafNode {
                        value_mask, values, ..
                    } = leaf;
                    read_compressed_values(&mut c, ctx, value_mask, Some(&mut values[..]), scratch)
                })?;
        }
    }
    Ok(())
}

/// The value mask and origin that start a bool or mask leaf buffer must
/// repeat the topology's.
fn check_leaf_header<V: Value>(cur: &mut ByteCursor, leaf: &mut LeafNode<V>) -> KindResult<()> {
    let mask = BitMask::<8>::from_le_bytes(cur.take(64, "leaf value mask")?);
    let origin = cur.coord("leaf origin")?;
    if origin != leaf.origin {
        return Err(corrupt(format!(
            "leaf buffer for {origin:?} where the topology has {:?}",
            leaf.origin
        )));
    }
    leaf.value_mask = mask;
    Ok(())
}
