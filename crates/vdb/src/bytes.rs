//! A bounds-checked little-endian cursor over a byte slice.
//!
//! Every read checks the remaining length first, so a truncated or corrupt
//! file becomes an [`ErrorKind::Truncated`] instead of a panic, and every
//! count read from a file can be checked against the bytes that remain
//! before anything is allocated for it.

use crate::error::{ErrorKind, KindResult};

#[derive(Clone)]
pub struct ByteCursor<'a> {
    data: &'a [u8],
    pos: usize,
    /// Offset of `data[0]` in the file, for error messages.
    base: u64,
}

impl<'a> ByteCursor<'a> {
    pub fn new(data: &'a [u8], base: u64) -> Self {
        ByteCursor { data, pos: 0, base }
    }

    pub fn position(&self) -> usize {
        self.pos
    }

    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    pub fn file_offset(&self) -> u64 {
        self.base + self.pos as u64
    }

    fn truncated(&self, what: &'static str, needed: u64) -> ErrorKind {
        ErrorKind::Truncated {
            what,
            offset: self.file_offset(),
            needed,
            available: self.remaining() as u64,
        }
    }

    /// Takes the next `n` bytes.
    pub fn take(&mut self, n: usize, what: &'static str) -> KindResult<&'a [u8]> {
        if n > self.remaining() {
            return Err(self.truncated(what, n as u64));
        }
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    /// Checks that `count` items of `item_size` bytes can still be read, so a
    /// count from the file may be trusted for an allocation.
    pub fn ensure(&self, count: u64, item_size: u64, what: &'static str) -> KindResult<()> {
        let needed = count.saturating_mul(item_size);
        if needed > self.remaining() as u64 {
            return Err(self.truncated(what, needed));
        }
        Ok(())
    }

    pub fn skip(&mut self, n: usize, what: &'static str) -> KindResult<()> {
        self.take(n, what).map(|_| ())
    }

    pub fn array<const N: usize>(&mut self, what: &'static str) -> KindResult<[u8; N]> {
        let s = self.take(N, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    pub fn u8(&mut self, what: &'static str) -> KindResult<u8> {
        Ok(self.array::<1>(what)?[0])
    }
    pub fn u32(&mut self, what: &'static str) -> KindResult<u32> {
        Ok(u32::from_le_bytes(self.array(what)?))
    }
    pub fn i32(&mut self, what: &'static str) -> KindResult<i32> {
        Ok(i32::from_le_bytes(self.array(what)?))
    }
    pub fn i64(&mut self, what: &'static str) -> KindResult<i64> {
        Ok(i64::from_le_bytes(self.array(what)?))
    }
    pub fn f64(&mut self, what: &'static str) -> KindResult<f64> {
        Ok(f64::from_le_bytes(self.array(what)?))
    }
    pub fn vec3d(&mut self, what: &'static str) -> KindResult<[f64; 3]> {
        Ok([self.f64(what)?, self.f64(what)?, self.f64(what)?])
    }
    pub fn coord(&mut self, what: &'static str) -> KindResult<crate::Coord> {
        Ok(crate::Coord::new(
            self.i32(what)?,
            self.i32(what)?,
            self.i32(what)?,
        ))
    }

    /// An OpenVDB string: a u32 length, then that many bytes (no terminator).
    pub fn string(&mut self, what: &'static str) -> KindResult<String> {
        let len = self.u32(what)? as usize;
        let bytes = self.take(len, what)?;
        Ok(String::from_utf8_lossy(bytes).into_owned())
    }
}
