//! A bounds-checked view of a NanoVDB buffer: every read names what it
//! reads, and one past the end is a corrupt-file error, never a panic.

use crate::error::{corrupt, KindResult};

/// A bounds-checked view of a grid buffer.
#[derive(Clone, Copy)]
pub struct Buf<'a>(pub &'a [u8]);

impl<'a> Buf<'a> {
    pub fn bytes(&self, off: usize, len: usize, what: &str) -> KindResult<&'a [u8]> {
        off.checked_add(len)
            .and_then(|end| self.0.get(off..end))
            .ok_or_else(|| {
                corrupt(format!(
                    "{what} (bytes {off}..+{len}) lies outside the {}-byte grid buffer",
                    self.0.len()
                ))
            })
    }
    fn array<const N: usize>(&self, off: usize, what: &str) -> KindResult<[u8; N]> {
        Ok(self.bytes(off, N, what)?.try_into().unwrap())
    }
    pub fn u32(&self, off: usize, what: &str) -> KindResult<u32> {
        Ok(u32::from_le_bytes(self.array(off, what)?))
    }
    pub fn u64(&self, off: usize, what: &str) -> KindResult<u64> {
        Ok(u64::from_le_bytes(self.array(off, what)?))
    }
    pub fn i64(&self, off: usize, what: &str) -> KindResult<i64> {
        Ok(i64::from_le_bytes(self.array(off, what)?))
    }
    pub fn f64(&self, off: usize, what: &str) -> KindResult<f64> {
        Ok(f64::from_le_bytes(self.array(off, what)?))
    }
}
