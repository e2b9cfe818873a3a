//! Decoding f16 voxels in the lookup's inner loop.
//!
//! `half`'s scalar `to_f32` picks its F16C instruction at run time and so
//! is an out-of-line call per voxel (8 per trilinear lookup); the portable
//! build (x86-64-v2) has no F16C to inline. [`f16_bits_to_f32`] is the
//! exact conversion in a few integer and float operations that inline and
//! vectorise over a lookup's eight corners.

/// 2^112: the ratio between f16 and f32 exponent biases (127 - 15 = 112).
const REBIAS: f32 = f32::from_bits((127 + 112) << 23);

/// The f32 of the f16 with bits `h`, exactly.
///
/// The f16's exponent and mantissa, shifted into an f32's places, read as
/// an f32 whose value is the f16's times 2^-112, for normal and subnormal
/// f16s alike (an f16 subnormal lands on an f32 subnormal with the same
/// mantissa); multiplying by 2^112 is exact, since the product is a normal
/// f32. Infinities and NaNs (exponent all ones) take the f32's all-ones
/// exponent, NaNs their mantissa with the quiet bit set.
#[inline(always)]
pub(crate) fn f16_bits_to_f32(h: u16) -> f32 {
    let sign = u32::from(h & 0x8000) << 16;
    let magnitude = u32::from(h & 0x7fff);
    let shifted = magnitude << 13;
    let bits = if magnitude > 0x7c00 {
        // NaN, made quiet as `half` and the F16C instruction make it.
        shifted | 0x7fc0_0000
    } else if magnitude == 0x7c00 {
        0x7f80_0000
    } else {
        (f32::from_bits(shifted) * REBIAS).to_bits()
    };
    f32::from_bits(bits | sign)
}

/// Whether this CPU decodes f16 in hardware (F16C: x86-64 since 2012;
/// not in the x86-64-v2 baseline the crate is built for).
#[inline]
pub(crate) fn has_f16c() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("f16c")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Eight f16s decoded by two F16C `vcvtph2ps`: the same f32s, bit for
/// bit, as [`f16_bits_to_f32`] gives one by one (the test compares them),
/// for a lookup's eight corners at once.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "f16c")]
#[inline]
pub(crate) fn f16x8_to_f32_f16c(h: [u16; 8]) -> [f32; 8] {
    use std::arch::x86_64::_mm_set_epi16;
    decode8(_mm_set_epi16(
        h[7] as i16,
        h[6] as i16,
        h[5] as i16,
        h[4] as i16,
        h[3] as i16,
        h[2] as i16,
        h[1] as i16,
        h[0] as i16,
    ))
}

/// [`f16x8_to_f32_f16c`] of four pairs of adjacent f16s, each pair one
/// `u32` (its first f16 in the low half): a stencil's corners come in
/// pairs along z, and four 32-bit reads go into a register at once where
/// eight 16-bit inserts went one after another, on the lookup's critical
/// path.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "f16c")]
#[inline]
pub(crate) fn f16_pairs_to_f32_f16c(pairs: [u32; 4]) -> [f32; 8] {
    use std::arch::x86_64::{_mm_cvtsi32_si128, _mm_unpacklo_epi32, _mm_unpacklo_epi64};
    let lane = |p: u32| _mm_cvtsi32_si128(p as i32);
    decode8(_mm_unpacklo_epi64(
        _mm_unpacklo_epi32(lane(pairs[0]), lane(pairs[1])),
        _mm_unpacklo_epi32(lane(pairs[2]), lane(pairs[3])),
    ))
}

/// The eight f16 lanes of `v` as f32s, by two `vcvtph2ps`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "f16c")]
#[inline]
fn decode8(v: std::arch::x86_64::__m128i) -> [f32; 8] {
    use std::arch::x86_64::{__m128, _mm_cvtph_ps, _mm_srli_si128};
    let lo = _mm_cvtph_ps(v);
    let hi = _mm_cvtph_ps(_mm_srli_si128::<8>(v));
    // SAFETY: `__m128` is 16 bytes of four f32 lanes, as `[f32; 4]` is,
    // and every bit pattern is a valid f32.
    let (lo, hi): ([f32; 4], [f32; 4]) = unsafe {
        (
            std::mem::transmute::<__m128, [f32; 4]>(lo),
            std::mem::transmute::<__m128, [f32; 4]>(hi),
        )
    };
    [lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// F16C agrees with the portable decode on all 65,536 patterns, in
    /// every lane (where the CPU has it).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn f16c_decodes_as_the_portable_decode() {
        if !has_f16c() {
            return;
        }
        for base in (0..=u16::MAX).step_by(8) {
            let h: [u16; 8] = std::array::from_fn(|i| base + i as u16);
            let pairs: [u32; 4] =
                std::array::from_fn(|k| u32::from(h[2 * k]) | u32::from(h[2 * k + 1]) << 16);
            // SAFETY: the CPU has F16C (checked above).
            let (ours, paired) = unsafe { (f16x8_to_f32_f16c(h), f16_pairs_to_f32_f16c(pairs)) };
            for (lane, (&bits, v)) in h.iter().zip(ours).enumerate() {
                let expected = f16_bits_to_f32(bits).to_bits();
                assert_eq!(v.to_bits(), expected, "{bits:#06x} lane {lane}");
                assert_eq!(
                    paired[lane].to_bits(),
                    expected,
                    "{bits:#06x} lane {lane}, paired"
                );
            }
        }
    }

    /// Every one of the 65,536 bit patterns against `half`: the same f32,
    /// bit for bit (NaNs compared as NaN with the same payload).
    #[test]
    fn every_f16_decodes_as_half_does() {
        for h in 0..=u16::MAX {
            let ours = f16_bits_to_f32(h);
            let theirs = half::f16::from_bits(h).to_f32();
            if theirs.is_nan() {
                assert!(ours.is_nan(), "{h:#06x}");
                assert_eq!(ours.to_bits() & 0x807f_ffff, theirs.to_bits() & 0x807f_ffff);
            } else {
                assert_eq!(
                    ours.to_bits(),
                    theirs.to_bits(),
                    "{h:#06x}: {ours} vs {theirs}"
                );
            }
        }
    }
}
