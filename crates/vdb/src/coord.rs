//! Integer voxel coordinates and inclusive index-space boxes.

use std::ops::{Add, Sub};

/// A voxel coordinate in a grid's index space.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Coord {
    pub x: i32,
    pub y: i32,
    pub z: i32,
}

impl Coord {
    pub const fn new(x: i32, y: i32, z: i32) -> Self {
        Coord { x, y, z }
    }
    pub const fn splat(v: i32) -> Self {
        Coord { x: v, y: v, z: v }
    }
    pub fn to_array(self) -> [i32; 3] {
        [self.x, self.y, self.z]
    }
    /// The coordinate with its low `log2` bits cleared: the origin of the
    /// node of side `1 << log2` that contains it.
    pub fn node_origin(self, log2: u32) -> Self {
        let m = !((1i32 << log2) - 1);
        Coord::new(self.x & m, self.y & m, self.z & m)
    }
    pub fn min(self, o: Self) -> Self {
        Coord::new(self.x.min(o.x), self.y.min(o.y), self.z.min(o.z))
    }
    pub fn max(self, o: Self) -> Self {
        Coord::new(self.x.max(o.x), self.y.max(o.y), self.z.max(o.z))
    }
    pub fn as_dvec3(self) -> glam::DVec3 {
        glam::DVec3::new(self.x as f64, self.y as f64, self.z as f64)
    }
}

impl Add for Coord {
    type Output = Coord;
    fn add(self, o: Coord) -> Coord {
        Coord::new(
            self.x.wrapping_add(o.x),
            self.y.wrapping_add(o.y),
            self.z.wrapping_add(o.z),
        )
    }
}

impl Sub for Coord {
    type Output = Coord;
    fn sub(self, o: Coord) -> Coord {
        Coord::new(
            self.x.wrapping_sub(o.x),
            self.y.wrapping_sub(o.y),
            self.z.wrapping_sub(o.z),
        )
    }
}

/// An inclusive box of voxel coordinates, as OpenVDB's `CoordBBox`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoordBBox {
    pub min: Coord,
    pub max: Coord,
}

impl CoordBBox {
    pub fn new(min: Coord, max: Coord) -> Self {
        CoordBBox { min, max }
    }
    /// The box of side `dim` starting at `origin`.
    pub fn from_origin(origin: Coord, dim: i32) -> Self {
        CoordBBox {
            min: origin,
            max: origin + Coord::splat(dim - 1),
        }
    }
    pub fn union(self, o: Self) -> Self {
        CoordBBox {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    pub fn contains(&self, c: Coord) -> bool {
        c.x >= self.min.x
            && c.y >= self.min.y
            && c.z >= self.min.z
            && c.x <= self.max.x
            && c.y <= self.max.y
            && c.z <= self.max.z
    }
    /// Number of voxels in the box.
    pub fn volume(&self) -> u64 {
        let d = |a: i32, b: i32| (b as i64 - a as i64 + 1).max(0) as u64;
        d(self.min.x, self.max.x) * d(self.min.y, self.max.y) * d(self.min.z, self.max.z)
    }
}
