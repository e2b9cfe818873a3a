//! OpenVDB's value streams: `readData` chunks and `readCompressedValues`
//! node buffers (io/Compression.h), with every length checked.

use super::blosc;
use crate::bytes::ByteCursor;
use crate::error::{corrupt, KindResult};
use crate::mask::BitMask;
use crate::Value;

pub const COMPRESS_ZIP: u32 = 0x1;
pub const COMPRESS_ACTIVE_MASK: u32 = 0x2;
pub const COMPRESS_BLOSC: u32 = 0x4;

/// The per-node byte that says how inactive values were stored
/// (io/Compression.h, `readCompressedValues`). All seven are listed; mode 1
/// needs no branch of its own (its inactive value, -background, is the
/// default for every mode but 0).
#[allow(dead_code)]
mod mode {
    pub const NO_MASK_OR_INACTIVE_VALS: u8 = 0;
    pub const NO_MASK_AND_MINUS_BG: u8 = 1;
    pub const NO_MASK_AND_ONE_INACTIVE_VAL: u8 = 2;
    pub const MASK_AND_NO_INACTIVE_VALS: u8 = 3;
    pub const MASK_AND_ONE_INACTIVE_VAL: u8 = 4;
    pub const MASK_AND_TWO_INACTIVE_VALS: u8 = 5;
    pub const NO_MASK_AND_ALL_VALS: u8 = 6;
}

/// What every value stream of one grid shares.
#[derive(Clone, Copy)]
pub struct StreamContext<V> {
    pub compression: u32,
    pub background: V,
    pub half: bool,
}

/// Reads one `readData` chunk of `nbytes` uncompressed bytes into `out`
/// (cleared first), or skips it when `out` is `None`.
pub fn read_data(
    cur: &mut ByteCursor,
    compression: u32,
    nbytes: usize,
    out: Option<&mut Vec<u8>>,
) -> KindResult<()> {
    if compression & (COMPRESS_BLOSC | COMPRESS_ZIP) == 0 {
        let raw = cur.take(nbytes, "uncompressed values")?;
        if let Some(out) = out {
            out.clear();
            out.extend_from_slice(raw);
        }
        return Ok(());
    }
    // A chunk: i64 size, negative (or zero) for bytes stored uncompressed.
    let size = cur.i64("compressed chunk size")?;
    if size <= 0 {
        let n = size.unsigned_abs();
        if n != nbytes as u64 {
            return Err(corrupt(format!(
                "uncompressed chunk of {n} bytes where {nbytes} were expected"
            )));
        }
        let raw = cur.take(nbytes, "uncompressed chunk")?;
        if let Some(out) = out {
            out.clear();
            out.extend_from_slice(raw);
        }
        return Ok(());
    }
    // Neither zlib nor blosc (which stores a chunk it cannot shrink) grows
    // data by more than a few bytes, so a larger size is corrupt: refused
    // before anything is read or allocated for it.
    let limit = nbytes as u64 + nbytes as u64 / 8 + 1024;
    if size as u64 > limit {
        return Err(corrupt(format!(
            "compressed chunk of {size} bytes for {nbytes} bytes of values"
        )));
    }
    let src = cur.take(size as usize, "compressed chunk")?;
    let Some(out) = out else { return Ok(()) };
    out.clear();
    out.resize(nbytes, 0);
    if compression & COMPRESS_BLOSC != 0 {
        blosc::decompress(src, out)
    } else {
        inflate(src, out)
    }
}

fn inflate(src: &[u8], out: &mut [u8]) -> KindResult<()> {
    use std::io::Read;
    let mut d = flate2::read::ZlibDecoder::new(src);
    let mut n = 0;
    while n < out.len() {
        match d.read(&mut out[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) => return Err(corrupt(format!("zip chunk: {e}"))),
        }
    }
    if n != out.len() {
        return Err(corrupt(format!(
            "zip chunk decoded to {n} bytes, expected {}",
            out.len()
        )));
    }
    Ok(())
}

/// What precedes a node's values: the mode byte, the inactive values it
/// implies (read or from the background) and the selection mask between
/// them where it has one.
struct NodeMode<V, const W: usize> {
    meta: u8,
    inactive: [V; 2],
    selection: Option<BitMask<W>>,
}

impl<V: Value, const W: usize> NodeMode<V, W> {
    fn read(cur: &mut ByteCursor, bg: V) -> KindResult<Self> {
        let meta = cur.u8("node value mode")?;
        if meta > mode::NO_MASK_AND_ALL_VALS {
            return Err(corrupt(format!(
                "node value mode {meta} is not one of the 7 OpenVDB writes"
            )));
        }
        let mut inactive0 = if meta == mode::NO_MASK_OR_INACTIVE_VALS {
            bg
        } else {
            bg.negate()
        };
        let mut inactive1 = bg;
        if matches!(
            meta,
            mode::NO_MASK_AND_ONE_INACTIVE_VAL
                | mode::MASK_AND_ONE_INACTIVE_VAL
                | mode::MASK_AND_TWO_INACTIVE_VALS
        ) {
            inactive0 = V::from_le(cur.take(V::SIZE, "inactive value")?);
            if meta == mode::MASK_AND_TWO_INACTIVE_VALS {
                inactive1 = V::from_le(cur.take(V::SIZE, "inactive value")?);
            }
        }
        let selection = if matches!(
            meta,
            mode::MASK_AND_NO_INACTIVE_VALS
                | mode::MASK_AND_ONE_INACTIVE_VAL
                | mode::MASK_AND_TWO_INACTIVE_VALS
        ) {
            Some(BitMask::<W>::from_le_bytes(
                cur.take(BitMask::<W>::BYTES, "selection mask")?,
            ))
        } else {
            None
        };
        Ok(Self {
            meta,
            inactive: [inactive0, inactive1],
            selection,
        })
    }
}

/// Reads a node's values as `readCompressedValues` stores them: the mode
/// byte, inactive values, the selection mask, then the values themselves —
/// all of them, or with active-mask compression only the active ones, the
/// inactive restored from the background (or `-background`, or the stored
/// inactive values) as the mode says.
///
/// `dest` has one slot per node value; `None` skips the record.
/// `scratch` is reused between calls to avoid an allocation per node.
pub fn read_compressed_values<V: Value, const W: usize>(
    cur: &mut ByteCursor,
    ctx: &StreamContext<V>,
    value_mask: &BitMask<W>,
    dest: Option<&mut [V]>,
    scratch: &mut Vec<u8>,
) -> KindResult<()> {
    let mask_compressed = ctx.compression & COMPRESS_ACTIVE_MASK != 0;
    let NodeMode {
        meta,
        inactive: [inactive0, inactive1],
        selection,
    } = NodeMode::<V, W>::read(cur, ctx.background)?;
    let total = BitMask::<W>::BITS;
    let stored = if mask_compressed && meta != mode::NO_MASK_AND_ALL_VALS {
        value_mask.count_on() as usize
    } else {
        total
    };
    let elem = if ctx.half {
        V::HALF_SIZE.unwrap_or(V::SIZE)
    } else {
        V::SIZE
    };
    let half = ctx.half && V::HALF_SIZE.is_some();
    // OpenVDB's HalfReader writes and reads nothing at all for zero values.
    if half && stored == 0 {
        if let Some(dest) = dest {
            fill_inactive(
                dest,
                value_mask,
                selection.as_ref(),
                inactive0,
                inactive1,
                &[],
                0,
                false,
            );
        }
        return Ok(());
    }
    let Some(dest) = dest else {
        return read_data(cur, ctx.compression, stored * elem, None);
    };
    read_data(cur, ctx.compression, stored * elem, Some(scratch))?;
    if stored == total {
        for (d, b) in dest.iter_mut().zip(scratch.chunks_exact(elem)) {
            *d = decode(b, half);
        }
    } else {
        fill_inactive(
            dest,
            value_mask,
            selection.as_ref(),
            inactive0,
            inactive1,
            scratch,
            elem,
            half,
        );
    }
    Ok(())
}

#[inline]
fn decode<V: Value>(b: &[u8], half: bool) -> V {
    if half {
        V::from_half_le(b)
    } else {
        V::from_le(b)
    }
}

/// Spreads the stored active values over `dest` and fills the inactive
/// slots: `inactive1` where the selection mask is on, else `inactive0`.
#[allow(clippy::too_many_arguments)]
fn fill_inactive<V: Value, const W: usize>(
    dest: &mut [V],
    value_mask: &BitMask<W>,
    selection: Option<&BitMask<W>>,
    inactive0: V,
    inactive1: V,
    active: &[u8],
    elem: usize,
    half: bool,
) {
    let mut next = active.chunks_exact(elem.max(1));
    for (i, d) in dest.iter_mut().enumerate() {
        *d = if value_mask.is_on(i) {
            // The count of stored values equals the mask's count, checked by read_data's length.
            next.next().map_or(inactive0, |b| decode(b, half))
        } else if selection.is_some_and(|s| s.is_on(i)) {
            inactive1
        } else {
            inactive0
        };
    }
}
