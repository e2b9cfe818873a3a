// Transmittance of shadow rays, by the estimator the settings name
// (crates/kernel/src/tracking/mod.rs, `transmittance`):
//
// - ratio tracking (Novak, Selle, Jarosz 2014): the product of null
//   fractions 1 - sigma_t / majorant over the tentative collisions
//   (tracking/ratio.rs);
// - residual ratio tracking (ibid., section 5) with each segment's
//   minorant as the control: exp(-minorant x length) on entering a
//   segment, collisions at the residual rate majorant - minorant, each
//   weighing 1 - (sigma_t - minorant) / rate (tracking/residual.rs);
// - track-length: 1 if a delta-tracked flight escapes, else 0
//   (tracking/track_length.rs);
//
// the ratio ones with pbrt-v4's Russian roulette below 0.05 (q = 0.75:
// tracking/roulette.rs, `f32`'s `roulette` in crates/kernel/src/spectrum.rs).

const TR_ROULETTE_THRESHOLD: f32 = 0.05;
const TR_ROULETTE_Q: f32 = 0.75;

const TRANSMITTANCE_RATIO: u32 = 0u;
const TRANSMITTANCE_RESIDUAL: u32 = 1u;
const TRANSMITTANCE_TRACK_LENGTH: u32 = 2u;

// Roulette of a transmittance estimate `tr` (0: killed).
fn tr_roulette(tr: f32, rng: ptr<function, u32>) -> f32 {
    if tr <= 0.0 {
        return 0.0;
    }
    if tr < TR_ROULETTE_THRESHOLD {
        if random(rng) < TR_ROULETTE_Q {
            return 0.0;
        }
        return tr / (1.0 - TR_ROULETTE_Q);
    }
    return tr;
}

// Transmittance per channel along render-space ray (origin, dir) up to
// `t_max` (FAR: to infinity): a chromatic medium's by ratio tracking per
// channel, or a track-length flight's spectral weights (spectral.wgsl,
// track_length.rs); a grey one's the same in every channel. A grey
// track-length flight whose collision lies past `t_max` reached it (delta
// tracking is memoryless: the same odds as a flight stopped there); a
// chromatic one's weights are not memoryless, and its lights are all at
// infinity (`support.rs` refuses local lights in chromatic media).
fn transmittance(origin: vec3<f32>, dir: vec3<f32>, t_max: f32, rng: ptr<function, u32>) -> vec3<f32> {
    let estimator = params.walk_mode.y;
    if estimator == TRANSMITTANCE_TRACK_LENGTH {
        var weight = vec3<f32>(1.0);
        let f = free_flight(origin, dir, &weight, rng);
        let through = f.kind == FLIGHT_ESCAPED
            || (!chromatic() && f.kind == FLIGHT_COLLISION && f.t >= t_max);
        return select(vec3<f32>(0.0), weight, through);
    }
    if chromatic() {
        return ratio_tracking_rgb(origin, dir, t_max, rng);
    }
    return vec3<f32>(grey_transmittance(origin, dir, t_max, estimator == TRANSMITTANCE_RESIDUAL, rng));
}

// A grey medium's transmittance up to `t_max` by (residual, where `residual`) ratio
// tracking.
fn grey_transmittance(origin: vec3<f32>, dir: vec3<f32>, t_max: f32, residual: bool, rng: ptr<function, u32>) -> f32 {
    var w = walk_start(origin, dir, residual, rng);
    w.t_end = min(w.t_end, t_max);
    var tr = 1.0;
    loop {
        iterations += 1u;
        let e = walk_next(&w, rng);
        if e.kind == EVENT_END {
            return tr;
        }
        if e.kind == EVENT_CAPPED {
            return 0.0;
        }
        if e.kind == EVENT_ENTER {
            if residual && w.seg_lo > 0.0 {
                tr *= exp(-w.seg_lo * (w.seg_t1 - w.seg_t0));
                tr = tr_roulette(tr, rng);
            }
        } else {
            shadow_collisions += 1u;
            let sigma = walk_sigma(&w, e.t);
            tr *= max(1.0 - (sigma - select(0.0, w.seg_lo, residual)) / w.rate, 0.0);
            tr = tr_roulette(tr, rng);
        }
        if tr <= 0.0 {
            return 0.0;
        }
    }
    cut_short = true;
    return 0.0;
}
