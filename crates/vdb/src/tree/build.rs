//! Building a tree: the readers push nodes top-down, tests and tools set voxels.

use super::*;
use crate::error::{corrupt, KindResult};

impl<V: Value, const LOG2: u32, const W: usize> InternalNode<V, LOG2, W> {
    /// A node whose every slot is a tile of `fill`, active or not.
    pub fn new_filled(origin: Coord, fill: V, active: bool) -> Self {
        let mut node = Self::new(origin, fill);
        if active {
            for n in 0..Self::SLOTS {
                node.value_mask.set(n, true);
            }
        }
        node
    }
}

impl<V: Value> Tree<V> {
    /// Adds a root entry. Its origin must be 4096-aligned and new.
    pub(crate) fn insert_root(&mut self, origin: Coord, slot: RootSlot<V>) -> KindResult<()> {
        if origin.node_origin(UPPER_TOTAL) != origin {
            return Err(corrupt(format!(
                "root entry origin {origin:?} is not a multiple of 4096"
            )));
        }
        if let RootSlot::Child(i) = slot {
            if i as usize >= self.upper.len() {
                return Err(corrupt("root child index out of range"));
            }
        }
        if self
            .root_index
            .insert(origin, self.root.len() as u32)
            .is_some()
        {
            return Err(corrupt(format!("two root entries at {origin:?}")));
        }
        self.root.push(RootEntry { origin, slot });
        Ok(())
    }

    pub(crate) fn push_upper(&mut self, node: UpperNode<V>) -> u32 {
        self.upper.push(node);
        (self.upper.len() - 1) as u32
    }
    pub(crate) fn push_lower(&mut self, node: LowerNode<V>) -> u32 {
        self.lower.push(node);
        (self.lower.len() - 1) as u32
    }
    pub(crate) fn push_leaf(&mut self, node: LeafNode<V>) -> u32 {
        self.leaves.push(node);
        (self.leaves.len() - 1) as u32
    }
    pub(crate) fn leaves_mut(&mut self) -> &mut [LeafNode<V>] {
        &mut self.leaves
    }

    /// Sets the voxel at `c` to an active `value`, creating nodes as needed.
    pub fn set_value_on(&mut self, c: Coord, value: V) {
        self.set(c, value, true);
    }

    /// Sets the voxel at `c` to `value` with the given active state. A tile
    /// on the way down is split into a child filled with the tile's value.
    pub fn set(&mut self, c: Coord, value: V, active: bool) {
        let key = c.node_origin(UPPER_TOTAL);
        let ui = match self
            .root_index
            .get(&key)
            .map(|&i| self.root[i as usize].slot)
        {
            Some(RootSlot::Child(i)) => i,
            found => {
                let (fill, on) = match found {
                    Some(RootSlot::Tile { value, active }) => (value, active),
                    _ => (self.background, false),
                };
                let i = self.push_upper(UpperNode::new_filled(key, fill, on));
                match self.root_index.get(&key) {
                    Some(&r) => self.root[r as usize].slot = RootSlot::Child(i),
                    None => {
                        self.root_index.insert(key, self.root.len() as u32);
                        self.root.push(RootEntry {
                            origin: key,
                            slot: RootSlot::Child(i),
                        });
                    }
                }
                i
            }
        };
        let n = UpperNode::<V>::slot(c, LOWER_TOTAL);
        let li = if self.upper[ui as usize].child_mask.is_on(n) {
            self.upper[ui as usize].children[n]
        } else {
            let up = &self.upper[ui as usize];
            let node = LowerNode::new_filled(
                up.slot_origin(n, LOWER_TOTAL),
                up.tiles[n],
                up.value_mask.is_on(n),
            );
            let li = self.push_lower(node);
            let up = &mut self.upper[ui as usize];
            up.child_mask.set(n, true);
            up.value_mask.set(n, false);
            up.children[n] = li;
            li
        };
        let n = LowerNode::<V>::slot(c, LEAF_TOTAL);
        let fi = if self.lower[li as usize].child_mask.is_on(n) {
            self.lower[li as usize].children[n]
        } else {
            let lo = &self.lower[li as usize];
            let node = LeafNode::new(
                lo.slot_origin(n, LEAF_TOTAL),
                lo.tiles[n],
                lo.value_mask.is_on(n),
            );
            let fi = self.push_leaf(node);
            let lo = &mut self.lower[li as usize];
            lo.child_mask.set(n, true);
            lo.value_mask.set(n, false);
            lo.children[n] = fi;
            fi
        };
        let leaf = &mut self.leaves[fi as usize];
        let n = LeafNode::<V>::offset(c);
        leaf.values[n] = value;
        leaf.value_mask.set(n, active);
    }
}
