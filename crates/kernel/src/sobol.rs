//! Owen-scrambled, shuffled Sobol points (Burley 2020, "Practical
//! Hash-based Owen Scrambling", JCGT 9(4)).
//!
//! Only a two-dimensional Sobol sequence is built: dimension 0 is the van
//! der Corput sequence and dimension 1 comes from Joe and Kuo's direction
//! numbers (2008, `new-joe-kuo-6.21201`, its first row). Together they form
//! a (0, 2)-sequence: every aligned block of `2^m` consecutive points has
//! exactly one point in each elementary interval of area `2^-m`.
//!
//! Higher dimensions are made the way Burley pads them: every 1D or 2D
//! draw gets its own point set, whose *index* is shuffled by a nested
//! uniform scramble and whose *values* are Owen-scrambled, each with a seed
//! hashed from the draw's identity. Independent shuffles decorrelate the
//! draws from one another; the scramble keeps each draw's stratification
//! (Owen 1995) and randomises it, so estimates stay unbiased.
//!
//! Why a shuffled index keeps the nets: the scramble of the index flips
//! bit `i` depending only on bits `i` and above, so indices `0..2^m` (whose
//! bits from `m` up are 0) map onto one aligned block of `2^m` indices,
//! its low `m` bits permuted. Every aligned block of a Sobol sequence is a
//! net, so the first `2^m` samples of a pixel are one. And since the flips
//! of the low bits depend on the high ones, two draws' shuffles pair their
//! points differently: their first digits are not locked together, which
//! they would be if each draw only scrambled the same unshuffled points.

/// Joe and Kuo's primitive-polynomial rows: `(degree s, coefficients a,
/// initial m_1..m_s)`. Dimension `d + 1` of the sequence uses row `d`;
/// extending this table is all it takes to add dimensions.
const JOE_KUO: [(u32, u32, [u32; 1]); 1] = [(1, 0, [1])];

/// Dimensions generated: van der Corput plus one per Joe-Kuo row.
pub const DIMENSIONS: usize = 1 + JOE_KUO.len();

/// Generator matrix columns: `MATRICES[d][k]` is the 32-bit column that
/// index bit `k` XORs into dimension `d` (bit 31 is the first binary digit).
const MATRICES: [[u32; 32]; DIMENSIONS] = matrices();

/// The matrices applied a byte of the index at a time, in the bit-reversed
/// domain the scrambles work in: entry `[d][b][v]` is the bit-reversed XOR
/// of the columns that byte `b` of the *bit-reversed* index selects by the
/// bits of `v`. Four lookups per value instead of a loop over 32 index
/// bits (shuffled indices have random high bits), and no bit reversal
/// between the index shuffle, the matrix and the value scramble; 8 KiB,
/// built at compile time.
static REVERSED_TABLES: [[[u32; 256]; 4]; DIMENSIONS] = reversed_tables();

const fn matrices() -> [[u32; 32]; DIMENSIONS] {
    let mut out = [[0u32; 32]; DIMENSIONS];
    // Dimension 0: van der Corput, the bit-reversal of the index.
    let mut k = 0;
    while k < 32 {
        out[0][k] = 1 << (31 - k);
        k += 1;
    }
    let mut d = 0;
    while d < JOE_KUO.len() {
        let (s, a, m_init) = JOE_KUO[d];
        let s = s as usize;
        // Direction integers m_k (Bratley and Fox 1988; Joe and Kuo 2008,
        // eq. 2): m_k = 2 a_1 m_{k-1} ^ 4 a_2 m_{k-2} ^ ... ^ 2^s m_{k-s} ^ m_{k-s}.
        let mut m = [0u32; 32];
        let mut k = 0;
        while k < 32 {
            m[k] = if k < s {
                m_init[k]
            } else {
                let mut v = m[k - s] ^ (m[k - s] << s);
                let mut j = 1;
                while j < s {
                    if (a >> (s - 1 - j)) & 1 == 1 {
                        v ^= m[k - j] << j;
                    }
                    j += 1;
                }
                v
            };
            // v_k = m_k / 2^(k+1) as a 32-bit binary fraction.
            out[d + 1][k] = m[k] << (31 - k);
            k += 1;
        }
        d += 1;
    }
    out
}

const fn reversed_tables() -> [[[u32; 256]; 4]; DIMENSIONS] {
    let mut t = [[[0u32; 256]; 4]; DIMENSIONS];
    let mut d = 0;
    while d < DIMENSIONS {
        let mut b = 0;
        while b < 4 {
            let mut v = 0;
            while v < 256 {
                let mut x = 0u32;
                let mut bit = 0;
                while bit < 8 {
                    // Bit `8b + bit` of the reversed index is index bit
                    // `31 - 8b - bit`.
                    if (v >> bit) & 1 == 1 {
                        x ^= MATRICES[d][31 - 8 * b - bit].reverse_bits();
                    }
                    bit += 1;
                }
                t[d][b][v] = x;
                v += 1;
            }
            b += 1;
        }
        d += 1;
    }
    t
}

/// Dimension `dim` of the unscrambled Sobol point `index`, as a 32-bit
/// binary fraction.
#[inline]
pub fn sobol(dim: usize, index: u32) -> u32 {
    sobol_reversed(dim, index.reverse_bits()).reverse_bits()
}

/// [`sobol`] in the bit-reversed domain: the reversed value of the point
/// whose index, reversed, is `reversed_index`.
#[inline]
fn sobol_reversed(dim: usize, reversed_index: u32) -> u32 {
    let t = &REVERSED_TABLES[dim];
    let b = reversed_index.to_le_bytes();
    t[0][b[0] as usize] ^ t[1][b[1] as usize] ^ t[2][b[2] as usize] ^ t[3][b[3] as usize]
}

/// Burley 2020, listing 2: Laine and Karras's hash-based permutation, in
/// which bit `i` of the result depends only on bits `0..=i` of `x` (adding
/// and multiplying by even constants carry upward only).
#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Burley 2020, listing 3: a nested uniform (Owen) scramble of a binary
/// fraction: each digit is flipped depending on the digits before it.
#[inline]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// A 32-bit binary fraction as an f32 in `[0, 1)`: the top 24 bits, so
/// the value is exact and never rounds up to 1.
#[inline]
pub fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// A sample index, kept bit-reversed: the form the shuffle takes it in,
/// reversed once per sample instead of once per draw.
#[derive(Clone, Copy, Debug)]
pub struct SobolIndex(u32);

impl SobolIndex {
    #[inline]
    pub fn new(index: u32) -> Self {
        Self(index.reverse_bits())
    }
}

/// One shuffled, Owen-scrambled Sobol point set (Burley 2020, listing 4,
/// cut to the two dimensions used): the seeds of the index shuffle and of
/// each dimension's scramble.
///
/// Computed in the bit-reversed domain: with `R` the bit reversal and
/// `LK` the permutation, the shuffled index is `R(LK(R(i)))`, its point
/// `R(T(LK(R(i))))` for the reversed table `T`, and the scrambled value
/// `R(LK(R(value)))`; the reversals between the steps cancel, leaving one
/// per index and one per value, the same bits as the literal listing.
#[derive(Clone, Copy, Debug)]
pub struct OwenSobol {
    pub shuffle: u32,
    pub scramble: [u32; 2],
}

impl OwenSobol {
    /// The reversed shuffled index of sample `index`.
    #[inline]
    fn shuffled(&self, index: SobolIndex) -> u32 {
        laine_karras(index.0, self.shuffle)
    }

    /// Dimension `d` of the point at reversed shuffled index `r`.
    #[inline]
    fn coordinate(&self, d: usize, r: u32) -> u32 {
        laine_karras(sobol_reversed(d, r), self.scramble[d]).reverse_bits()
    }

    /// Point `index` of the set, as 32-bit fractions.
    #[inline]
    pub fn point_bits(&self, index: u32) -> [u32; 2] {
        let r = self.shuffled(SobolIndex::new(index));
        [self.coordinate(0, r), self.coordinate(1, r)]
    }

    /// The first coordinate of point `index`, in `[0, 1)`.
    #[inline]
    pub fn get_1d(&self, index: SobolIndex) -> f32 {
        to_unit(self.coordinate(0, self.shuffled(index)))
    }

    /// Point `index`, in `[0, 1)^2`.
    #[inline]
    pub fn get_2d(&self, index: SobolIndex) -> (f32, f32) {
        let r = self.shuffled(index);
        (
            to_unit(self.coordinate(0, r)),
            to_unit(self.coordinate(1, r)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_points_are_the_textbook_sobol_points() {
        // The first eight points in index order (tables list them in the
        // Gray-code order of Antonov and Saleev, which permutes pairs).
        let want = [
            (0.0, 0.0),
            (0.5, 0.5),
            (0.25, 0.75),
            (0.75, 0.25),
            (0.125, 0.625),
            (0.625, 0.125),
            (0.375, 0.375),
            (0.875, 0.875),
        ];
        for (i, w) in want.iter().enumerate() {
            let got = (to_unit(sobol(0, i as u32)), to_unit(sobol(1, i as u32)));
            assert_eq!(got, *w, "point {i}");
        }
    }

    #[test]
    fn the_reversed_domain_gives_the_literal_listing() {
        let set = OwenSobol {
            shuffle: 0x1234_5678,
            scramble: [0x9abc_def0, 0x0fed_cba9],
        };
        for index in [0u32, 1, 2, 3, 100, 65_537, u32::MAX] {
            let i = owen_scramble(index, set.shuffle);
            let literal = [0, 1].map(|d| owen_scramble(sobol(d, i), set.scramble[d]));
            assert_eq!(set.point_bits(index), literal, "index {index}");
        }
    }

    #[test]
    fn byte_tables_match_the_matrix_product() {
        for (d, matrix) in MATRICES.iter().enumerate() {
            for index in [0u32, 1, 7, 255, 256, 0x1234_5678, u32::MAX] {
                let mut x = 0;
                for (k, col) in matrix.iter().enumerate() {
                    if (index >> k) & 1 == 1 {
                        x ^= col;
                    }
                }
                assert_eq!(sobol(d, index), x, "dim {d} index {index:#x}");
            }
        }
    }

    #[test]
    fn the_index_shuffle_is_a_permutation_of_every_aligned_block() {
        for seed in [0u32, 1, 0xdead_beef] {
            let mut low = vec![false; 256];
            for i in 0..256u32 {
                low[(owen_scramble(i, seed) & 255) as usize] = true;
            }
            assert!(low.iter().all(|&b| b), "seed {seed}");
        }
    }
}
