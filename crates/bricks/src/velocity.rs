//! A vec3 velocity grid in sparse 8^3 bricks, for motion blur.
//!
//! Velocity is signed, so it cannot go through the density builder (which
//! stores negative values as 0); it gets this small store of its own:
//! a dense map of 8^3 bricks over the grid's leaves and active tiles
//! (background, one constant vector, or 512 stored vectors) at f32.
//!
//! Memory: 12 bytes a voxel of every leaf, 4 bytes a brick of the map;
//! no error beyond the file's own values (a vec3d grid is rounded to f32
//! once). f16 storage would halve the atlas for 2^-12 relative error, but
//! measured 10-20 % slower renders on the corpus cloud with a synthetic
//! wind (the half decode of 24 components a lookup), so velocity stays
//! f32: it is usually coarser and sparser than the density. The
//! displacement bound that majorants are dilated by
//! ([`VelocityGrid::max_abs`]) is taken over the stored values, so it
//! holds exactly for every lookup.
//!
//! Lookups are trilinear in the grid's index space (voxel centres at
//! integers, as [`BrickVolume::trilinear`](crate::BrickVolume::trilinear)),
//! the background outside the map.

use cirrus_vdb::{Coord, Tree, Value};
use glam::{DMat4, IVec3, Vec3};

use crate::layout::MAX_MAP_BRICKS;
use crate::layout::{voxel_offset, BRICK, BRICK_LOG2};
use crate::BrickError;

/// Map code: the brick holds the background.
const BACKGROUND: u32 = 0;
/// Map code flag: a constant brick (low bits: index into `constants`);
/// without it a non-zero code is stored brick `code - 1`.
const CONSTANT: u32 = 1 << 31;

/// A velocity grid ready for lookups; see the module doc.
#[derive(Clone, Debug)]
pub struct VelocityGrid {
    pub name: String,
    /// Index coordinate of the first voxel of brick (0, 0, 0).
    pub origin: IVec3,
    /// Bricks per axis.
    pub dims: [u32; 3],
    /// The grid's index-to-world matrix.
    pub index_to_world: DMat4,
    map: Vec<u32>,
    constants: Vec<Vec3>,
    /// 512 voxels x 3 components per stored brick, x-major voxels.
    atlas: Vec<[f32; 3]>,
    background: Vec3,
    /// Largest |component| over every stored value, constant and the
    /// background, per component.
    max_abs: Vec3,
    /// Components that were NaN or infinite, stored as 0.
    pub sanitized: u64,
}

/// A component as stored: non-finite values become 0 (and are counted).
fn store(v: f32, sanitized: &mut u64) -> f32 {
    if v.is_finite() {
        v
    } else {
        *sanitized += 1;
        0.0
    }
}

#[inline(always)]
fn load(h: [f32; 3]) -> Vec3 {
    Vec3::from_array(h)
}

/// A vector as stored, for constants and the background.
fn stored_vec(v: [f32; 3], sanitized: &mut u64) -> Vec3 {
    load(v.map(|c| store(c, sanitized)))
}

impl VelocityGrid {
    /// Builds the store from a vec3 tree; `to_vec` widens or narrows its
    /// values to f32 components (`[f32; 3]` or `[f64; 3]` grids).
    pub fn from_tree<V: Value>(
        name: &str,
        tree: &Tree<V>,
        index_to_world: DMat4,
        to_vec: impl Fn(V) -> [f32; 3],
    ) -> Result<VelocityGrid, BrickError> {
        let mut sanitized = 0u64;
        let background = stored_vec(to_vec(tree.background()), &mut sanitized);
        let mut tiles = Vec::new();
        tree.for_each_active_tile(|b, v, _| tiles.push((b, to_vec(v))));
        let (lo, hi) = extent(tree, &tiles);
        let mut grid = VelocityGrid {
            name: name.to_string(),
            origin: IVec3::ZERO,
            dims: [0; 3],
            index_to_world,
            map: Vec::new(),
            constants: Vec::new(),
            atlas: Vec::new(),
            background,
            max_abs: background.abs(),
            sanitized: 0,
        };
        let Some((lo, hi)) = lo.zip(hi) else {
            grid.sanitized = sanitized;
            return Ok(grid);
        };
        grid.origin = lo.div_euclid(IVec3::splat(BRICK)) * BRICK;
        let end = hi.div_euclid(IVec3::splat(BRICK)) + 1;
        let d = end - grid.origin / BRICK;
        grid.dims = [d.x as u32, d.y as u32, d.z as u32];
        let count: u64 = grid.dims.iter().map(|&d| u64::from(d)).product();
        if count > MAX_MAP_BRICKS {
            return Err(BrickError::TooLarge(format!(
                "velocity grid {name}: {:?} bricks exceed the limit",
                grid.dims
            )));
        }
        grid.map = vec![BACKGROUND; count as usize];
        for (b, v) in tiles {
            grid.tile(b.min, b.max, stored_vec(v, &mut sanitized));
        }
        for leaf in tree.leaves() {
            let mut voxels = vec![[0f32; 3]; 512];
            for (n, v) in leaf.values.iter().enumerate() {
                let c = to_vec(*v);
                for k in 0..3 {
                    voxels[n][k] = store(c[k], &mut sanitized);
                }
            }
            grid.leaf(leaf.origin, voxels);
        }
        grid.sanitized = sanitized;
        Ok(grid)
    }

    fn brick_index(&self, b: IVec3) -> Option<usize> {
        let [dx, dy, dz] = self.dims;
        let inside = b.cmpge(IVec3::ZERO).all()
            && (b.x as u32) < dx
            && (b.y as u32) < dy
            && (b.z as u32) < dz;
        inside.then(|| (b.x as usize * dy as usize + b.y as usize) * dz as usize + b.z as usize)
    }

    /// An active tile's bricks become one constant.
    fn tile(&mut self, min: Coord, max: Coord, v: Vec3) {
        let k = self.constants.len() as u32;
        self.constants.push(v);
        self.max_abs = self.max_abs.max(v.abs());
        let b0 = (IVec3::from_array(min.to_array()) - self.origin) >> BRICK_LOG2 as i32;
        let b1 = (IVec3::from_array(max.to_array()) - self.origin) >> BRICK_LOG2 as i32;
        for x in b0.x..=b1.x {
            for y in b0.y..=b1.y {
                for z in b0.z..=b1.z {
                    if let Some(i) = self.brick_index(IVec3::new(x, y, z)) {
                        self.map[i] = CONSTANT | k;
                    }
                }
            }
        }
    }

    /// A leaf's 512 voxels (leaf order is x-major, as the atlas).
    fn leaf(&mut self, origin: Coord, voxels: Vec<[f32; 3]>) {
        let b = (IVec3::from_array(origin.to_array()) - self.origin) >> BRICK_LOG2 as i32;
        let Some(i) = self.brick_index(b) else {
            return;
        };
        for v in &voxels {
            self.max_abs = self.max_abs.max(load(*v).abs());
        }
        self.map[i] = 1 + (self.atlas.len() / 512) as u32;
        self.atlas.extend_from_slice(&voxels);
    }

    /// The stored velocity of voxel `c` (index space).
    #[inline]
    pub fn voxel(&self, c: IVec3) -> Vec3 {
        let Some(i) = self.brick_index((c - self.origin) >> BRICK_LOG2 as i32) else {
            return self.background;
        };
        match self.map[i] {
            BACKGROUND => self.background,
            code if code & CONSTANT != 0 => self.constants[(code & !CONSTANT) as usize],
            code => {
                let l = c - self.origin;
                load(self.atlas[(code as usize - 1) * 512 + voxel_offset(l.x, l.y, l.z)])
            }
        }
    }

    /// Trilinear velocity at index-space point `p` (the background where
    /// `p` is not finite).
    #[inline]
    pub fn trilinear(&self, p: Vec3) -> Vec3 {
        if !p.is_finite() {
            return self.background;
        }
        let f0 = p.floor();
        let c = f0.as_ivec3();
        let f = p - f0;
        let v = self.corners(c);
        // Corners ordered x-major: v[4x + 2y + z].
        let lerp = |a: Vec3, b: Vec3, t: f32| a + (b - a) * t;
        let x0 = lerp(lerp(v[0], v[1], f.z), lerp(v[2], v[3], f.z), f.y);
        let x1 = lerp(lerp(v[4], v[5], f.z), lerp(v[6], v[7], f.z), f.y);
        lerp(x0, x1, f.x)
    }

    /// The eight voxels `c + {0, 1}^3`, x-major. When they share one brick
    /// (7/8 of positions per axis) its map entry is read once.
    #[inline]
    fn corners(&self, c: IVec3) -> [Vec3; 8] {
        let l = c - self.origin;
        let one_brick = (l & (BRICK - 1)).cmplt(IVec3::splat(BRICK - 1)).all();
        let code = match self.brick_index(l >> BRICK_LOG2 as i32) {
            Some(i) if one_brick => self.map[i],
            _ => {
                let at = |k: i32| self.voxel(c + IVec3::new(k >> 2, (k >> 1) & 1, k & 1));
                return [0, 1, 2, 3, 4, 5, 6, 7].map(at);
            }
        };
        match code {
            BACKGROUND => [self.background; 8],
            code if code & CONSTANT != 0 => [self.constants[(code & !CONSTANT) as usize]; 8],
            code => {
                let base = (code as usize - 1) * 512 + voxel_offset(l.x, l.y, l.z);
                let s = &self.atlas[base..base + 74];
                [0, 1, 8, 9, 64, 65, 72, 73].map(|k| load(s[k]))
            }
        }
    }

    /// Per component, the largest |value| any lookup can return: trilinear
    /// interpolation is a convex combination of stored values, so it never
    /// exceeds their largest magnitude.
    pub fn max_abs(&self) -> Vec3 {
        self.max_abs
    }

    /// Maps world coordinates to this grid's index coordinates.
    pub fn index_from_world(&self) -> DMat4 {
        self.index_to_world.inverse()
    }

    /// Bytes of the map, constants and atlas.
    pub fn bytes(&self) -> usize {
        self.map.len() * 4 + self.constants.len() * 12 + self.atlas.len() * 12
    }
}

/// The index box of the tree's leaves and active tiles, if any.
fn extent<V: Value>(
    tree: &Tree<V>,
    tiles: &[(cirrus_vdb::CoordBBox, [f32; 3])],
) -> (Option<IVec3>, Option<IVec3>) {
    let mut lo: Option<IVec3> = None;
    let mut hi: Option<IVec3> = None;
    let mut add = |a: IVec3, b: IVec3| {
        lo = Some(lo.map_or(a, |l| l.min(a)));
        hi = Some(hi.map_or(b, |h| h.max(b)));
    };
    for leaf in tree.leaves() {
        let o = IVec3::from_array(leaf.origin.to_array());
        add(o, o + (BRICK - 1));
    }
    for (b, _) in tiles {
        add(
            IVec3::from_array(b.min.to_array()),
            IVec3::from_array(b.max.to_array()),
        );
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookups_interpolate_leaves_and_tiles_and_fall_back_to_the_background() {
        let mut tree = Tree::new([0.5f32, 0.0, 0.0]);
        // A linear field over two leaves: trilinear reproduces it exactly.
        for x in 0..16 {
            for y in 0..8 {
                for z in 0..8 {
                    let v = [x as f32, -2.0 * y as f32, 0.25 * z as f32];
                    tree.set_value_on(Coord::new(x, y, z), v);
                }
            }
        }
        tree.set_value_on(Coord::new(20, 0, 0), [f32::NAN, 1.0, 1.0]);
        let g = VelocityGrid::from_tree("vel", &tree, DMat4::IDENTITY, |v| v).unwrap();
        let p = Vec3::new(7.25, 3.5, 2.75); // straddles the two leaves in x
        assert_eq!(g.trilinear(p), Vec3::new(7.25, -7.0, 0.6875));
        assert_eq!(
            g.trilinear(Vec3::new(1.5, 1.5, 1.5)),
            Vec3::new(1.5, -3.0, 0.375)
        );
        assert_eq!(g.voxel(IVec3::new(20, 0, 0)), Vec3::new(0.0, 1.0, 1.0));
        assert_eq!(g.sanitized, 1);
        assert_eq!(g.voxel(IVec3::new(-100, 0, 0)), Vec3::new(0.5, 0.0, 0.0));
        assert_eq!(g.max_abs(), Vec3::new(15.0, 14.0, 1.75));
    }
}
