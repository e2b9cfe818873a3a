//! A typed slice that is either owned or borrowed from a memory-mapped file.

use std::ops::Deref;
use std::sync::Arc;

/// Plain data the volume is made of: `u32` brick references, `f32` bounds,
/// `u8` voxel bytes. Owned after a conversion, mapped after loading a .cbrk.
#[derive(Clone)]
pub enum Section<T: bytemuck::Pod> {
    Owned(Vec<T>),
    /// `offset` and `len` are in bytes and `T`-aligned within the map
    /// (checked when the section is made, see `format.rs`).
    Mapped {
        map: Arc<memmap2::Mmap>,
        offset: usize,
        len: usize,
    },
}

impl<T: bytemuck::Pod> Deref for Section<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        match self {
            Section::Owned(v) => v,
            Section::Mapped { map, offset, len } => {
                bytemuck::cast_slice(&map[*offset..*offset + *len])
            }
        }
    }
}

impl<T: bytemuck::Pod> From<Vec<T>> for Section<T> {
    fn from(v: Vec<T>) -> Self {
        Section::Owned(v)
    }
}

impl<T: bytemuck::Pod + std::fmt::Debug> std::fmt::Debug for Section<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Section[{}; {}]", std::any::type_name::<T>(), self.len())
    }
}
