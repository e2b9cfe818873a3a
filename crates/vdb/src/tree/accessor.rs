//! Random access with a cache of the last leaf, for coherent lookups.

use super::*;

/// Reads values from a [`Tree`], remembering the last leaf it found so that
/// neighbouring lookups (a trilinear stencil, a ray step) skip the descent.
pub struct Accessor<'a, V> {
    tree: &'a Tree<V>,
    /// Origin of the cached leaf; `None` until a leaf was found.
    leaf_origin: Option<Coord>,
    leaf: u32,
}

impl<'a, V: Value> Accessor<'a, V> {
    pub fn new(tree: &'a Tree<V>) -> Self {
        Accessor {
            tree,
            leaf_origin: None,
            leaf: 0,
        }
    }

    /// The value at `c` and whether it is active.
    #[inline]
    pub fn probe(&mut self, c: Coord) -> (V, bool) {
        let origin = c.node_origin(LEAF_TOTAL);
        if self.leaf_origin == Some(origin) {
            let leaf = &self.tree.leaves[self.leaf as usize];
            let n = LeafNode::<V>::offset(c);
            return (leaf.values[n], leaf.value_mask.is_on(n));
        }
        self.descend(c)
    }

    #[inline]
    pub fn get(&mut self, c: Coord) -> V {
        self.probe(c).0
    }

    #[inline]
    pub fn is_active(&mut self, c: Coord) -> bool {
        self.probe(c).1
    }

    fn descend(&mut self, c: Coord) -> (V, bool) {
        let tree = self.tree;
        let Some(entry) = tree.root_lookup(c) else {
            return (tree.background, false);
        };
        let upper = match entry.slot {
            RootSlot::Tile { value, active } => return (value, active),
            RootSlot::Child(i) => &tree.upper[i as usize],
        };
        let n = UpperNode::<V>::slot(c, LOWER_TOTAL);
        if !upper.child_mask.is_on(n) {
            return (upper.tiles[n], upper.value_mask.is_on(n));
        }
        let lower = &tree.lower[upper.children[n] as usize];
        let n = LowerNode::<V>::slot(c, LEAF_TOTAL);
        if !lower.child_mask.is_on(n) {
            return (lower.tiles[n], lower.value_mask.is_on(n));
        }
        let li = lower.children[n];
        self.leaf = li;
        self.leaf_origin = Some(c.node_origin(LEAF_TOTAL));
        let leaf = &tree.leaves[li as usize];
        let n = LeafNode::<V>::offset(c);
        (leaf.values[n], leaf.value_mask.is_on(n))
    }
}
