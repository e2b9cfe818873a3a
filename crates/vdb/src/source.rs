//! Positioned reads from a file, counted, and checked against its length.
//!
//! The readers never map or slurp a whole file: they read the header, the
//! grid descriptors and then only the byte range of the grid asked for. The
//! counter makes that provable (`bytes_read`).

use crate::error::{ErrorKind, KindResult};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

pub struct FileSource {
    path: PathBuf,
    file: Mutex<File>,
    len: u64,
    bytes_read: AtomicU64,
}

impl FileSource {
    pub fn open(path: &Path) -> std::io::Result<FileSource> {
        let file = File::open(path)?;
        let meta = file.metadata()?;
        if meta.is_dir() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "is a directory",
            ));
        }
        Ok(FileSource {
            path: path.to_path_buf(),
            file: Mutex::new(file),
            len: meta.len(),
            bytes_read: AtomicU64::new(0),
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn len(&self) -> u64 {
        self.len
    }

    /// Total bytes read from the file so far.
    pub fn bytes_read(&self) -> u64 {
        self.bytes_read.load(Ordering::Relaxed)
    }

    /// Reads `len` bytes at `offset`; the range must lie inside the file, so
    /// a size taken from the file can never allocate more than the file holds.
    pub fn read_at(&self, offset: u64, len: u64, what: &'static str) -> KindResult<Vec<u8>> {
        let end = offset.checked_add(len);
        if end.is_none_or(|e| e > self.len) {
            return Err(ErrorKind::Truncated {
                what,
                offset,
                needed: len,
                available: self.len.saturating_sub(offset),
            });
        }
        let mut buf = vec![0u8; len as usize];
        let mut f = self.file.lock().unwrap_or_else(|e| e.into_inner());
        f.seek(SeekFrom::Start(offset))?;
        f.read_exact(&mut buf)?;
        self.bytes_read.fetch_add(len, Ordering::Relaxed);
        Ok(buf)
    }

    /// Reads up to `len` bytes at `offset`, fewer at the end of the file.
    pub fn read_window(&self, offset: u64, len: u64, what: &'static str) -> KindResult<Vec<u8>> {
        let len = len.min(self.len.saturating_sub(offset));
        self.read_at(offset, len, what)
    }

    /// Runs a parser over a window of the file starting at `offset`, growing
    /// the window while the parser runs out of bytes and the file has more.
    /// Returns the parser's result and how many bytes it consumed.
    pub fn parse_at<T>(
        &self,
        offset: u64,
        what: &'static str,
        mut parse: impl FnMut(&mut crate::bytes::ByteCursor) -> KindResult<T>,
    ) -> KindResult<(T, u64)> {
        let mut window = 256u64;
        loop {
            let buf = self.read_window(offset, window, what)?;
            let mut cur = crate::bytes::ByteCursor::new(&buf, offset);
            match parse(&mut cur) {
                Err(ErrorKind::Truncated { .. }) if offset + (buf.len() as u64) < self.len => {
                    window *= 4
                }
                Err(e) => return Err(e),
                Ok(v) => return Ok((v, cur.position() as u64)),
            }
        }
    }
}
