//! A bounds-checked decoder for Blosc 1 chunks, the frames OpenVDB writes
//! with `COMPRESS_BLOSC`.
//!
//! Chunk layout (all little-endian): a 16-byte header
//! `[version u8, versionlz u8, flags u8, typesize u8, nbytes u32, blocksize u32, cbytes u32]`,
//! then, unless the chunk is stored (flag 0x02), one i32 start offset per
//! block and the blocks. A block is split into `typesize` streams when the
//! split rule below holds, each stream an i32 compressed size and its bytes
//! (a size equal to the stream's length means stored). Byte shuffle
//! (flag 0x01) is undone per block. OpenVDB uses LZ4 (compressor code 1);
//! zlib (code 3) is decoded too; others are refused by name.

use crate::error::{corrupt, unsupported, KindResult};

const HEADER: usize = 16;
const FLAG_SHUFFLE: u8 = 0x01;
const FLAG_MEMCPYED: u8 = 0x02;
const FLAG_BITSHUFFLE: u8 = 0x04;
const FLAG_DONT_SPLIT: u8 = 0x10;
/// Blosc splits blocks into `typesize` streams only for small type sizes and
/// blocks of at least this many elements (blosc.c, `blosc_d`).
const MAX_SPLITS: usize = 16;
const MIN_BUFFERSIZE: usize = 128;

/// Decodes one Blosc chunk into `out`, which must have exactly the chunk's
/// uncompressed size.
pub fn decompress(src: &[u8], out: &mut [u8]) -> KindResult<()> {
    if src.len() < HEADER {
        return Err(corrupt("blosc chunk shorter than its header"));
    }
    let flags = src[2];
    let typesize = (src[3] as usize).max(1);
    let rd = |i: usize| u32::from_le_bytes(src[i..i + 4].try_into().unwrap()) as usize;
    let (nbytes, blocksize, cbytes) = (rd(4), rd(8), rd(12));
    if nbytes != out.len() {
        return Err(corrupt(format!(
            "blosc chunk holds {nbytes} bytes, expected {}",
            out.len()
        )));
    }
    if cbytes > src.len() {
        return Err(corrupt(format!(
            "blosc chunk claims {cbytes} bytes, only {} present",
            src.len()
        )));
    }
    if nbytes == 0 {
        return Ok(());
    }
    if flags & FLAG_MEMCPYED != 0 {
        let data = src
            .get(HEADER..HEADER + nbytes)
            .ok_or_else(|| corrupt("stored blosc chunk is short"))?;
        out.copy_from_slice(data);
        return Ok(());
    }
    if flags & FLAG_BITSHUFFLE != 0 {
        return Err(unsupported("blosc bit-shuffle filter"));
    }
    if blocksize == 0 {
        return Err(corrupt("blosc block size 0"));
    }
    let starts_end = HEADER + 4 * nbytes.div_ceil(blocksize);
    if starts_end > src.len() {
        return Err(corrupt("blosc block table runs past the chunk"));
    }
    let shuffle = flags & FLAG_SHUFFLE != 0 && typesize > 1;
    // Sized by nbytes, which the caller vouches for, never by the file's
    // blocksize alone; kept per thread, as a leaf chunk is decoded per call.
    thread_local! {
        static SCRATCH: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
    }
    let mut scratch = SCRATCH.with(|s| std::mem::take(&mut *s.borrow_mut()));
    if shuffle {
        scratch.resize(blocksize.min(nbytes), 0);
    }
    let result = decode_blocks(
        src,
        out,
        flags,
        typesize,
        nbytes,
        blocksize,
        compressor_of(flags),
        shuffle,
        &mut scratch,
    );
    SCRATCH.with(|s| *s.borrow_mut() = scratch);
    result
}

fn compressor_of(flags: u8) -> u8 {
    (flags >> 5) & 0x7
}

#[allow(clippy::too_many_arguments)]
fn decode_blocks(
    src: &[u8],
    out: &mut [u8],
    flags: u8,
    typesize: usize,
    nbytes: usize,
    blocksize: usize,
    compressor: u8,
    shuffle: bool,
    scratch: &mut [u8],
) -> KindResult<()> {
    let rd = |i: usize| u32::from_le_bytes(src[i..i + 4].try_into().unwrap()) as usize;
    let nblocks = nbytes.div_ceil(blocksize);
    for b in 0..nblocks {
        let start = rd(HEADER + 4 * b);
        let bsize = blocksize.min(nbytes - b * blocksize);
        let leftover = bsize < blocksize;
        let dest = &mut out[b * blocksize..b * blocksize + bsize];
        let target: &mut [u8] = if shuffle { &mut scratch[..bsize] } else { dest };
        let split = flags & FLAG_DONT_SPLIT == 0
            && typesize <= MAX_SPLITS
            && blocksize / typesize >= MIN_BUFFERSIZE
            && !leftover;
        let nsplits = if split { typesize } else { 1 };
        let neblock = bsize / nsplits;
        let mut pos = start;
        for j in 0..nsplits {
            let size_bytes = src
                .get(pos..pos + 4)
                .ok_or_else(|| corrupt("blosc stream header past the chunk"))?;
            let csize = i32::from_le_bytes(size_bytes.try_into().unwrap());
            pos += 4;
            if csize < 0 {
                return Err(corrupt("negative blosc stream size"));
            }
            let csize = csize as usize;
            let stream = src
                .get(pos..pos + csize)
                .ok_or_else(|| corrupt("blosc stream runs past the chunk"))?;
            let dst = &mut target[j * neblock..(j + 1) * neblock];
            if csize == neblock {
                dst.copy_from_slice(stream);
            } else {
                decode_stream(compressor, stream, dst)?;
            }
            pos += csize;
        }
        if shuffle {
            unshuffle(
                typesize,
                &scratch[..bsize],
                &mut out[b * blocksize..b * blocksize + bsize],
            );
        }
    }
    Ok(())
}

fn decode_stream(compressor: u8, src: &[u8], dst: &mut [u8]) -> KindResult<()> {
    let n = match compressor {
        1 => lz4_flex::block::decompress_into(src, dst)
            .map_err(|e| corrupt(format!("blosc lz4 stream: {e}")))?,
        3 => {
            use std::io::Read;
            let mut d = flate2::read::ZlibDecoder::new(src);
            let mut n = 0;
            while n < dst.len() {
                let k = d
                    .read(&mut dst[n..])
                    .map_err(|e| corrupt(format!("blosc zlib stream: {e}")))?;
                if k == 0 {
                    break;
                }
                n += k;
            }
            n
        }
        0 => return Err(unsupported("blosc codec blosclz")),
        2 => return Err(unsupported("blosc codec snappy")),
        4 => return Err(unsupported("blosc codec zstd")),
        c => return Err(corrupt(format!("unknown blosc codec {c}"))),
    };
    if n != dst.len() {
        return Err(corrupt(format!(
            "blosc stream decoded to {n} bytes, expected {}",
            dst.len()
        )));
    }
    Ok(())
}

/// Undoes Blosc's byte shuffle: the input holds byte 0 of every element,
/// then byte 1 of every element, and so on; trailing bytes that do not fill
/// an element are stored as they are.
fn unshuffle(typesize: usize, src: &[u8], dst: &mut [u8]) {
    let n = src.len() / typesize;
    if typesize == 4 {
        // The common case (f32 values): four streams zipped, without the
        // inner loop's index arithmetic.
        let (s0, rest) = src.split_at(n);
        let (s1, rest) = rest.split_at(n);
        let (s2, s3) = rest.split_at(n);
        for (i, d) in dst[..4 * n].chunks_exact_mut(4).enumerate() {
            d.copy_from_slice(&[s0[i], s1[i], s2[i], s3[i]]);
        }
        dst[4 * n..].copy_from_slice(&src[4 * n..]);
        return;
    }
    for i in 0..n {
        for j in 0..typesize {
            dst[i * typesize + j] = src[j * n + i];
        }
    }
    let tail = n * typesize;
    dst[tail..].copy_from_slice(&src[tail..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(flags: u8, typesize: u8, nbytes: u32, blocksize: u32, cbytes: u32) -> Vec<u8> {
        let mut h = vec![2, 1, flags, typesize];
        h.extend(nbytes.to_le_bytes());
        h.extend(blocksize.to_le_bytes());
        h.extend(cbytes.to_le_bytes());
        h
    }

    #[test]
    fn decodes_a_shuffled_lz4_chunk_with_split_streams() {
        // 256 f32 values = 1024 bytes; one block, split into 4 streams of 256.
        let values: Vec<f32> = (0..256).map(|i| i as f32 * 0.5).collect();
        let raw: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut shuffled = vec![0u8; raw.len()];
        for i in 0..256 {
            for j in 0..4 {
                shuffled[j * 256 + i] = raw[i * 4 + j];
            }
        }
        let mut body = Vec::new();
        for j in 0..4 {
            let c = lz4_flex::block::compress(&shuffled[j * 256..(j + 1) * 256]);
            body.extend((c.len() as i32).to_le_bytes());
            body.extend(c);
        }
        let mut chunk = header(FLAG_SHUFFLE | (1 << 5), 4, 1024, 1024, 0);
        chunk.extend(((HEADER + 4) as u32).to_le_bytes());
        chunk.extend(body);
        let n = chunk.len() as u32;
        chunk[12..16].copy_from_slice(&n.to_le_bytes());
        let mut out = vec![0u8; 1024];
        decompress(&chunk, &mut out).unwrap();
        assert_eq!(out, raw);
    }

    #[test]
    fn rejects_lying_lengths() {
        let mut out = vec![0u8; 64];
        // nbytes disagrees with the expected size.
        assert!(decompress(&header(FLAG_MEMCPYED, 4, 32, 32, 48), &mut out).is_err());
        // Stored chunk shorter than it claims.
        assert!(decompress(&header(FLAG_MEMCPYED, 4, 64, 64, 16), &mut out).is_err());
        // A block table pointing past the end.
        let mut c = header(1 << 5, 4, 64, 64, 24);
        c.extend(1000u32.to_le_bytes());
        c.extend([0u8; 4]);
        assert!(decompress(&c, &mut out).is_err());
    }
}
