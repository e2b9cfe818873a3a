//! Fixed-size bit masks: a node's value mask and child mask.
//!
//! Bit `n` is bit `n % 64` of word `n / 64`, the layout OpenVDB writes
//! (`NodeMask::save`) and NanoVDB keeps in memory, so masks load as raw words.

/// A mask of `64 * W` bits. Leaves use `W = 8` (512 bits), lower internal
/// nodes `W = 64` (4096), upper internal nodes `W = 512` (32768).
/// Stored inline: a mask lives inside its node, and nodes live in arenas.
#[derive(Clone, PartialEq, Eq)]
pub struct BitMask<const W: usize> {
    words: [u64; W],
}

impl<const W: usize> Default for BitMask<W> {
    fn default() -> Self {
        BitMask { words: [0u64; W] }
    }
}

impl<const W: usize> std::fmt::Debug for BitMask<W> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "BitMask<{}>({} on)", W * 64, self.count_on())
    }
}

impl<const W: usize> BitMask<W> {
    pub const BITS: usize = W * 64;
    pub const BYTES: usize = W * 8;

    /// Builds a mask from its little-endian on-disk words.
    pub fn from_le_bytes(bytes: &[u8]) -> Self {
        debug_assert_eq!(bytes.len(), Self::BYTES);
        let mut m = Self::default();
        for (w, chunk) in m.words.iter_mut().zip(bytes.chunks_exact(8)) {
            *w = u64::from_le_bytes(chunk.try_into().unwrap());
        }
        m
    }

    #[inline]
    pub fn is_on(&self, n: usize) -> bool {
        (self.words[n >> 6] >> (n & 63)) & 1 != 0
    }

    #[inline]
    pub fn set(&mut self, n: usize, on: bool) {
        let bit = 1u64 << (n & 63);
        if on {
            self.words[n >> 6] |= bit;
        } else {
            self.words[n >> 6] &= !bit;
        }
    }

    pub fn count_on(&self) -> u32 {
        self.words.iter().map(|w| w.count_ones()).sum()
    }

    pub fn is_off(&self) -> bool {
        self.words.iter().all(|&w| w == 0)
    }

    pub fn words(&self) -> &[u64; W] {
        &self.words
    }

    /// Indices of the set bits, in increasing order.
    pub fn iter_on(&self) -> impl Iterator<Item = usize> + '_ {
        self.words.iter().enumerate().flat_map(|(wi, &w)| {
            let mut w = w;
            std::iter::from_fn(move || {
                if w == 0 {
                    return None;
                }
                let b = w.trailing_zeros() as usize;
                w &= w - 1;
                Some(wi * 64 + b)
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iter_on_visits_exactly_the_set_bits() {
        let mut m = BitMask::<8>::default();
        for n in [0, 1, 63, 64, 200, 511] {
            m.set(n, true);
        }
        assert_eq!(
            m.iter_on().collect::<Vec<_>>(),
            vec![0, 1, 63, 64, 200, 511]
        );
        assert_eq!(m.count_on(), 6);
        m.set(64, false);
        assert!(!m.is_on(64));
        assert_eq!(m.count_on(), 5);
    }

    #[test]
    fn loads_little_endian_words() {
        let mut bytes = vec![0u8; 64];
        bytes[0] = 0b101;
        bytes[9] = 0x80; // bit 15 of word 1 = bit 79
        let m = BitMask::<8>::from_le_bytes(&bytes);
        assert_eq!(m.iter_on().collect::<Vec<_>>(), vec![0, 2, 79]);
    }
}
