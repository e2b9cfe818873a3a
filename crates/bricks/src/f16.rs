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

#[cfg(test)]
mod tests {
    use super::*;

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
