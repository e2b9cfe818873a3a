//! Typed metadata: the key/value pairs a file or a grid carries.

/// One metadata value. Types the reader does not know are kept by name.
#[derive(Clone, Debug, PartialEq)]
pub enum MetaValue {
    String(String),
    Bool(bool),
    Int32(i32),
    Int64(i64),
    Float(f32),
    Double(f64),
    Vec3i([i32; 3]),
    Vec3s([f32; 3]),
    Vec3d([f64; 3]),
    /// A type this reader does not decode, with its byte length.
    Other {
        type_name: String,
        len: usize,
    },
}

/// Metadata entries in file order.
pub type MetaMap = Vec<(String, MetaValue)>;

/// Looks up a key in a metadata list.
pub fn meta_get<'a>(meta: &'a MetaMap, key: &str) -> Option<&'a MetaValue> {
    meta.iter().find(|(k, _)| k == key).map(|(_, v)| v)
}

impl MetaValue {
    /// Decodes a value of OpenVDB type `type_name` from its bytes; a byte
    /// count that does not match the type keeps it as [`MetaValue::Other`].
    pub fn decode(type_name: &str, b: &[u8]) -> MetaValue {
        let f32_at = |i: usize| f32::from_le_bytes(b[i..i + 4].try_into().unwrap());
        let i32_at = |i: usize| i32::from_le_bytes(b[i..i + 4].try_into().unwrap());
        let f64_at = |i: usize| f64::from_le_bytes(b[i..i + 8].try_into().unwrap());
        match (type_name, b.len()) {
            ("string", _) => MetaValue::String(String::from_utf8_lossy(b).into_owned()),
            ("bool", 1) => MetaValue::Bool(b[0] != 0),
            ("int32", 4) => MetaValue::Int32(i32_at(0)),
            ("int64", 8) => MetaValue::Int64(i64::from_le_bytes(b.try_into().unwrap())),
            ("float", 4) => MetaValue::Float(f32_at(0)),
            ("double", 8) => MetaValue::Double(f64_at(0)),
            ("vec3i", 12) => MetaValue::Vec3i([i32_at(0), i32_at(4), i32_at(8)]),
            ("vec3s", 12) => MetaValue::Vec3s([f32_at(0), f32_at(4), f32_at(8)]),
            ("vec3d", 24) => MetaValue::Vec3d([f64_at(0), f64_at(8), f64_at(16)]),
            _ => MetaValue::Other {
                type_name: type_name.to_string(),
                len: b.len(),
            },
        }
    }

    /// Whether [`MetaValue::decode`] reads values of this type (others
    /// are kept as [`MetaValue::Other`], whatever their bytes).
    pub fn decodes(type_name: &str) -> bool {
        matches!(
            type_name,
            "string"
                | "bool"
                | "int32"
                | "int64"
                | "float"
                | "double"
                | "vec3i"
                | "vec3s"
                | "vec3d"
        )
    }

    pub fn as_str(&self) -> Option<&str> {
        match self {
            MetaValue::String(s) => Some(s),
            _ => None,
        }
    }
}
