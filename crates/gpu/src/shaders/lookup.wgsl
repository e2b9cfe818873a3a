// Density lookups in the volume's local index space: the brick map, the
// atlas and the trilinear filter, as crates/bricks/src/volume.rs
// (`voxel`, `trilinear`) reads them.

// The f32 of IEEE half bits `h`, subnormals included, decoded with integer
// operations (as crates/bricks/src/f16.rs, f16_bits_to_f32; WGSL's
// unpack2x16float needs a capability not every adapter has).
fn f16_to_f32(h: u32) -> f32 {
    let sign = (h & 0x8000u) << 16u;
    let e = (h >> 10u) & 0x1fu;
    let m = h & 0x3ffu;
    if e == 0u {
        let v = f32(m) * 5.9604645e-8;
        return select(v, -v, sign != 0u);
    }
    if e == 31u {
        return bitcast<f32>(sign | 0x7f800000u | (m << 13u));
    }
    return bitcast<f32>(sign | ((e + 112u) << 23u) | (m << 13u));
}

// Voxel `n` of stored brick `brick`: an f32 word, or one half of a word
// holding two f16 (the lower half the even voxel), in the atlas chunk
// holding the brick (whole bricks a chunk, so a pair never straddles two).
fn stored_voxel(brick: u32, n: u32) -> f32 {
    let per_chunk = params.counts.y;
    let chunk = brick / per_chunk;
    let i = (brick - chunk * per_chunk) * 512u + n;
    if params.map_dims.w == 1u {
        return f16_to_f32((atlas_word(chunk, i >> 1u) >> ((i & 1u) * 16u)) & 0xffffu);
    }
    return bitcast<f32>(atlas_word(chunk, i));
}

// The voxel at local index `c` (0 outside the volume).
fn voxel(c: vec3<i32>) -> f32 {
    let b = c >> vec3<u32>(3u);
    let dims = vec3<i32>(params.map_dims.xyz);
    if any(b < vec3<i32>(0)) || any(b >= dims) {
        return 0.0;
    }
    let r = brick_map[u32(b.x) * u32(dims.y * dims.z) + u32(b.y * dims.z + b.z)];
    let index = r & 0x3fffffffu;
    switch r >> 30u {
        case 1u: {
            return constants[index];
        }
        case 2u: {
            let o = c & vec3<i32>(7);
            return stored_voxel(index, u32((o.x << 6u) | (o.y << 3u) | o.z));
        }
        default: {
            return 0.0;
        }
    }
}

// Trilinear density at local point `p` (voxel centres at integers): the
// eight corners' values by their weights, one corner a turn of a loop the
// compiler cannot unroll (common.wgsl, `corners`).
fn density(p: vec3<f32>) -> f32 {
    // Far outside (or not a number): nothing, as the CPU's lookup.
    if !(all(abs(p) < vec3<f32>(1.0e9))) {
        return 0.0;
    }
    let fl = floor(p);
    let c = vec3<i32>(fl);
    let f = p - fl;
    var sum = 0.0;
    for (var k = 0; k < corners(); k++) {
        iterations += 1u;
        let o = vec3<i32>((k >> 2u) & 1, (k >> 1u) & 1, k & 1);
        let weight = select(vec3<f32>(1.0) - f, f, o == vec3<i32>(1));
        sum += weight.x * weight.y * weight.z * voxel(c + o);
    }
    return sum;
}

// Extinction at local point `p`.
fn sigma_t(p: vec3<f32>) -> f32 {
    return params.albedo.w * density(p);
}
