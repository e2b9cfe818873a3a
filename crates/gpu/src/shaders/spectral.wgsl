// A chromatic medium's extinction per RGB channel, `tint x sigma_t` (the
// walk's majorants bound the largest channel, whose tint is 1), and how
// its trackers weigh each channel. Mirrors crates/kernel/src/spectrum.rs,
// `impl Spectrum for Vec3` (`clamp_to_majorant`, `null_fraction`,
// `roulette`, `collide`, `escaped_alpha`); a grey medium takes the scalar
// code of delta.wgsl and ratio.wgsl unchanged.

const COLLISION_REAL: u32 = 0u;
const COLLISION_NULL: u32 = 1u;
// The path's throughput is zero or not a number: nothing left to weigh.
const COLLISION_DEAD: u32 = 2u;

fn chromatic() -> bool {
    return params.tint.w > 0.0;
}

// Each channel's extinction at the walk's `t`, clamped to [0, majorant]
// (tracking/lookup.rs with `Vec3::clamp_to_majorant`).
fn walk_sigma_rgb(w: ptr<function, Walk>, t: f32) -> vec3<f32> {
    let sigma = params.tint.xyz * sigma_t((*w).o + (*w).d * t);
    return clamp(sigma, vec3<f32>(0.0), vec3<f32>((*w).seg_hi));
}

// Spectral tracking's decision at a tentative collision of majorant
// `maj` (Kutz et al. 2017, eq. 16): real with probability
// `sum(beta sigma) / (maj sum(beta))`, `beta` weighed by each channel's
// real or null coefficient over that probability (`collide`).
fn collide_rgb(sigma: vec3<f32>, maj: f32, beta: ptr<function, vec3<f32>>, rng: ptr<function, u32>) -> u32 {
    let sum_beta = (*beta).x + (*beta).y + (*beta).z;
    if !(sum_beta > 0.0) {
        *beta = vec3<f32>(0.0);
        return COLLISION_DEAD;
    }
    let weighted = *beta * sigma;
    let p_real = clamp((weighted.x + weighted.y + weighted.z) / (maj * sum_beta), 0.0, 1.0);
    if random(rng) < p_real {
        *beta *= sigma / (maj * p_real);
        return COLLISION_REAL;
    }
    *beta *= (vec3<f32>(maj) - sigma) / (maj * (1.0 - p_real));
    return COLLISION_NULL;
}

// Roulette of a per-channel transmittance on its largest channel: the
// estimate lives or dies whole (`roulette`).
fn tr_roulette_rgb(tr: vec3<f32>, rng: ptr<function, u32>) -> vec3<f32> {
    let m = max(tr.x, max(tr.y, tr.z));
    if !(m > 0.0) {
        return vec3<f32>(0.0);
    }
    if m < TR_ROULETTE_THRESHOLD {
        if random(rng) < TR_ROULETTE_Q {
            return vec3<f32>(0.0);
        }
        return tr / (1.0 - TR_ROULETTE_Q);
    }
    return tr;
}

// Per-channel ratio tracking along render-space ray (origin, dir) to
// infinity (tracking/ratio.rs over `Vec3`; residual tracking takes this
// too for a chromatic medium, as tracking/mod.rs's `transmittance` does).
fn ratio_tracking_rgb(origin: vec3<f32>, dir: vec3<f32>, t_max: f32, rng: ptr<function, u32>) -> vec3<f32> {
    var w = walk_start(origin, dir, false, rng);
    w.t_end = min(w.t_end, t_max);
    var tr = vec3<f32>(1.0);
    loop {
        iterations += 1u;
        let e = walk_next(&w, rng);
        if e.kind == EVENT_END {
            return tr;
        }
        if e.kind == EVENT_CAPPED {
            return vec3<f32>(0.0);
        }
        if e.kind == EVENT_COLLISION {
            shadow_collisions += 1u;
            tr *= vec3<f32>(1.0) - walk_sigma_rgb(&w, e.t) / w.seg_hi;
            tr = tr_roulette_rgb(tr, rng);
            if !(max(tr.x, max(tr.y, tr.z)) > 0.0) {
                return vec3<f32>(0.0);
            }
        }
    }
    cut_short = true;
    return vec3<f32>(0.0);
}
