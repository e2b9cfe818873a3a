//! The sliding window the streaming reader parses the topology through:
//! a few KiB at first, doubling up to [`WINDOW`], re-read from a record's
//! start when a record needs more than the window holds, so a header is
//! read alone and a topology in one sequential pass of bounded memory.

use crate::bytes::ByteCursor;
use crate::error::{ErrorKind, KindResult};
use crate::source::FileSource;

/// Bytes of the file read at a time, for the topology and per leaf chunk.
pub(super) const WINDOW: u64 = 4 << 20;

/// A sliding window over `[start, end)` of the file that parses one record
/// at a time and grows only when a record needs more than it holds.
pub(super) struct Window<'s> {
    src: &'s FileSource,
    end: u64,
    buf: Vec<u8>,
    start: u64,
    at: usize,
    /// Bytes the next read asks at least: 4 KiB, doubling to [`WINDOW`],
    /// so reading a header alone stays small.
    step: u64,
}

impl<'s> Window<'s> {
    pub(super) fn new(src: &'s FileSource, pos: u64, end: u64) -> Self {
        Window {
            src,
            end,
            buf: Vec::new(),
            start: pos,
            at: 0,
            step: 4096,
        }
    }

    pub(super) fn position(&self) -> u64 {
        self.start + self.at as u64
    }

    /// Checks that `count` items of at least `size` bytes can lie in what is left.
    pub(super) fn ensure(&self, count: u64, size: u64, what: &'static str) -> KindResult<()> {
        let needed = count.saturating_mul(size);
        let available = self.end.saturating_sub(self.position());
        if needed > available {
            return Err(ErrorKind::Truncated {
                what,
                offset: self.position(),
                needed,
                available,
            });
        }
        Ok(())
    }

    /// Parses one record. On running out of window, re-reads from the
    /// record's start with room for what the failed read asked, unless the
    /// grid ends first (then the error is the answer).
    pub(super) fn record<T>(
        &mut self,
        mut parse: impl FnMut(&mut ByteCursor) -> KindResult<T>,
    ) -> KindResult<T> {
        loop {
            let mut cur = ByteCursor::new(&self.buf[self.at..], self.position());
            match parse(&mut cur) {
                Ok(v) => {
                    self.at += cur.position();
                    return Ok(v);
                }
                Err(ErrorKind::Truncated {
                    what,
                    offset,
                    needed,
                    ..
                }) => {
                    let window_end = self.start + self.buf.len() as u64;
                    let need_end = offset.saturating_add(needed);
                    if window_end >= self.end || need_end > self.end {
                        return Err(ErrorKind::Truncated {
                            what,
                            offset,
                            needed,
                            available: self.end.saturating_sub(offset),
                        });
                    }
                    let from = self.position();
                    let len = (need_end - from).max(self.step).min(self.end - from);
                    self.step = (self.step * 2).min(WINDOW);
                    self.buf = self.src.read_at(from, len, "grid data")?;
                    self.start = from;
                    self.at = 0;
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// Moves past `n` bytes without reading those the window does not hold.
    pub(super) fn skip(&mut self, n: u64, what: &'static str) -> KindResult<()> {
        self.ensure(n, 1, what)?;
        let held = (self.buf.len() - self.at) as u64;
        if n <= held {
            self.at += n as usize;
        } else {
            self.start = self.position() + n;
            self.buf.clear();
            self.at = 0;
            self.step = 4096;
        }
        Ok(())
    }

    /// The bytes read but not parsed, and the file offset of the first.
    pub(super) fn into_rest(mut self) -> (Vec<u8>, u64) {
        let pos = self.position();
        self.buf.drain(..self.at);
        (self.buf, pos)
    }
}
