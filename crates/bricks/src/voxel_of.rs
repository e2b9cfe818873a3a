//! The voxel holding a point: `floor(p)` per axis, as integers.
//!
//! Every cell walk and lookup starts here, once per step or lattice point.
//! `p.floor().as_ivec3()` converts each axis with Rust's saturating cast,
//! which compiles to a compare and two branches per axis (NaN to 0, out of
//! range to the nearest bound); with SSE4.1 (the build's x86-64-v2
//! baseline) one `roundps` and one `cvttps2dq` do all three axes, and any
//! axis out of `i32`'s range (or NaN) comes out as `i32::MIN`. Callers only
//! ever pass points within a volume's box give or take a nudge, where both
//! agree; beyond it either answer is a cell outside the volume, which every
//! caller bounds-checks.

use glam::{IVec3, Vec3A};

/// `floor(p)` per axis (see the module doc for out-of-range axes).
#[inline(always)]
pub(crate) fn voxel_of(p: Vec3A) -> IVec3 {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse4.1"))]
    {
        use std::arch::x86_64::{_mm_cvttps_epi32, _mm_floor_ps, _mm_storeu_si128};
        let mut out = [0i32; 4];
        // SAFETY: the intrinsics need SSE4.1, which this code is compiled
        // with (the cfg above), so every CPU that runs it has it; `out` is
        // 16 writable bytes and `storeu` needs no alignment. The fourth
        // lane, whatever it holds, is converted and dropped.
        unsafe {
            let v = _mm_cvttps_epi32(_mm_floor_ps(p.into()));
            _mm_storeu_si128(out.as_mut_ptr().cast(), v);
        }
        IVec3::new(out[0], out[1], out[2])
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse4.1")))]
    {
        p.floor().as_ivec3()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Agrees with `floor` then the saturating cast wherever a point is in
    /// range: integers, halves, values just below integers, negatives.
    #[test]
    fn voxel_of_is_floor_in_range() {
        let values = [
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            0.999_999_9,
            -0.000_001,
            7.0,
            7.999_999,
            8.0,
            -8.000_001,
            1e6 + 0.5,
            -1e6 - 0.5,
            16_777_215.0,
            -16_777_215.0,
            2.0e9,
            -2.0e9,
        ];
        for &x in &values {
            for &y in &values {
                for &z in &[values[3], values[9], values[14]] {
                    let p = Vec3::new(x, y, z);
                    assert_eq!(voxel_of(p.into()), p.floor().as_ivec3(), "{p}");
                }
            }
        }
    }

    /// With SSE4.1, out of range and NaN come out as `i32::MIN`: far
    /// outside every volume.
    #[cfg(all(target_arch = "x86_64", target_feature = "sse4.1"))]
    #[test]
    fn voxel_of_out_of_range_is_far_outside() {
        for x in [f32::NAN, 3.0e9, -3.0e9, f32::INFINITY, f32::NEG_INFINITY] {
            let v = voxel_of(Vec3A::new(x, 1.5, -2.5));
            assert_eq!(v, IVec3::new(i32::MIN, 1, -3), "{x}");
        }
    }
}
