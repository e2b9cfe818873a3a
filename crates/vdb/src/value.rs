//! The value types a grid can hold and how each is decoded from bytes.

use half::f16;

/// The value type of a grid, named as OpenVDB names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ValueType {
    Float,
    Double,
    Int32,
    Int64,
    Bool,
    /// A topology-only grid (OpenVDB `MaskGrid`, NanoVDB `Mask`): bool values,
    /// true exactly where active.
    Mask,
    Vec3f,
    Vec3d,
}

impl ValueType {
    /// OpenVDB's name: the one `vdb_print` and the grid's `value_type` metadata use.
    pub fn name(self) -> &'static str {
        match self {
            ValueType::Float => "float",
            ValueType::Double => "double",
            ValueType::Int32 => "int32",
            ValueType::Int64 => "int64",
            ValueType::Bool => "bool",
            ValueType::Mask => "mask",
            ValueType::Vec3f => "vec3s",
            ValueType::Vec3d => "vec3d",
        }
    }
}

/// A value that a [`Tree`](crate::Tree) can store. Implemented for `f32`,
/// `f64`, `i32`, `i64`, `bool` and `[f32; 3]`, `[f64; 3]`.
pub trait Value: Copy + Default + PartialEq + Send + Sync + std::fmt::Debug + 'static {
    /// The grid value type that holds this Rust type (`bool`: [`ValueType::Bool`]).
    const VALUE_TYPE: ValueType;
    /// Bytes per value on disk at full precision.
    const SIZE: usize;
    /// Bytes per value when saved as half float, for real-valued types.
    const HALF_SIZE: Option<usize>;
    /// Decodes one value from `SIZE` little-endian bytes.
    fn from_le(b: &[u8]) -> Self;
    /// Decodes one value from `HALF_SIZE` bytes of IEEE half floats.
    #[inline]
    fn from_half_le(b: &[u8]) -> Self {
        Self::from_le(b)
    }
    /// `-v`: OpenVDB's `math::negative`, used for the "minus background"
    /// inactive-value modes of level sets.
    fn negate(self) -> Self;
    /// Components as f64, for statistics and printing.
    fn components(self) -> ([f64; 3], usize);
}

#[inline]
fn half(b: &[u8]) -> f32 {
    f16::from_le_bytes([b[0], b[1]]).to_f32()
}

impl Value for f32 {
    const VALUE_TYPE: ValueType = ValueType::Float;
    const SIZE: usize = 4;
    const HALF_SIZE: Option<usize> = Some(2);
    #[inline]
    fn from_le(b: &[u8]) -> Self {
        f32::from_le_bytes(b[..4].try_into().unwrap())
    }
    #[inline]
    fn from_half_le(b: &[u8]) -> Self {
        half(b)
    }
    #[inline]
    fn negate(self) -> Self {
        -self
    }
    #[inline]
    fn components(self) -> ([f64; 3], usize) {
        ([self as f64, 0.0, 0.0], 1)
    }
}

impl Value for f64 {
    const VALUE_TYPE: ValueType = ValueType::Double;
    const SIZE: usize = 8;
    const HALF_SIZE: Option<usize> = Some(2);
    #[inline]
    fn from_le(b: &[u8]) -> Self {
        f64::from_le_bytes(b[..8].try_into().unwrap())
    }
    #[inline]
    fn from_half_le(b: &[u8]) -> Self {
        half(b) as f64
    }
    #[inline]
    fn negate(self) -> Self {
        -self
    }
    #[inline]
    fn components(self) -> ([f64; 3], usize) {
        ([self, 0.0, 0.0], 1)
    }
}

impl Value for i32 {
    const VALUE_TYPE: ValueType = ValueType::Int32;
    const SIZE: usize = 4;
    const HALF_SIZE: Option<usize> = None;
    #[inline]
    fn from_le(b: &[u8]) -> Self {
        i32::from_le_bytes(b[..4].try_into().unwrap())
    }
    #[inline]
    fn negate(self) -> Self {
        self.wrapping_neg()
    }
    #[inline]
    fn components(self) -> ([f64; 3], usize) {
        ([self as f64, 0.0, 0.0], 1)
    }
}

impl Value for i64 {
    const VALUE_TYPE: ValueType = ValueType::Int64;
    const SIZE: usize = 8;
    const HALF_SIZE: Option<usize> = None;
    #[inline]
    fn from_le(b: &[u8]) -> Self {
        i64::from_le_bytes(b[..8].try_into().unwrap())
    }
    #[inline]
    fn negate(self) -> Self {
        self.wrapping_neg()
    }
    #[inline]
    fn components(self) -> ([f64; 3], usize) {
        ([self as f64, 0.0, 0.0], 1)
    }
}

impl Value for bool {
    const VALUE_TYPE: ValueType = ValueType::Bool;
    const SIZE: usize = 1;
    const HALF_SIZE: Option<usize> = None;
    #[inline]
    fn from_le(b: &[u8]) -> Self {
        b[0] != 0
    }
    #[inline]
    fn negate(self) -> Self {
        // OpenVDB's math::negative of a bool is the bool itself.
        self
    }
    #[inline]
    fn components(self) -> ([f64; 3], usize) {
        ([self as u8 as f64, 0.0, 0.0], 1)
    }
}

impl Value for [f32; 3] {
    const VALUE_TYPE: ValueType = ValueType::Vec3f;
    const SIZE: usize = 12;
    const HALF_SIZE: Option<usize> = Some(6);
    #[inline]
    fn from_le(b: &[u8]) -> Self {
        [
            f32::from_le(&b[0..4]),
            f32::from_le(&b[4..8]),
            f32::from_le(&b[8..12]),
        ]
    }
    #[inline]
    fn from_half_le(b: &[u8]) -> Self {
        [half(&b[0..2]), half(&b[2..4]), half(&b[4..6])]
    }
    #[inline]
    fn negate(self) -> Self {
        [-self[0], -self[1], -self[2]]
    }
    #[inline]
    fn components(self) -> ([f64; 3], usize) {
        ([self[0] as f64, self[1] as f64, self[2] as f64], 3)
    }
}

impl Value for [f64; 3] {
    const VALUE_TYPE: ValueType = ValueType::Vec3d;
    const SIZE: usize = 24;
    const HALF_SIZE: Option<usize> = Some(6);
    #[inline]
    fn from_le(b: &[u8]) -> Self {
        [
            f64::from_le(&b[0..8]),
            f64::from_le(&b[8..16]),
            f64::from_le(&b[16..24]),
        ]
    }
    #[inline]
    fn from_half_le(b: &[u8]) -> Self {
        [
            half(&b[0..2]) as f64,
            half(&b[2..4]) as f64,
            half(&b[4..6]) as f64,
        ]
    }
    #[inline]
    fn negate(self) -> Self {
        [-self[0], -self[1], -self[2]]
    }
    #[inline]
    fn components(self) -> ([f64; 3], usize) {
        (self, 3)
    }
}
