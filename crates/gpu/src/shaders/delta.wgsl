// Delta (Woodcock) tracking: the distance to the first real collision,
// with density sigma_t exp(-integral of sigma_t). Mirrors
// crates/kernel/src/tracking/delta.rs: for a grey medium `f32`'s
// `Spectrum::collide` (real when xi * majorant < sigma_t), for a
// chromatic one spectral tracking (spectral.wgsl).

const FLIGHT_COLLISION: u32 = 0u;
const FLIGHT_ESCAPED: u32 = 1u;
const FLIGHT_CAPPED: u32 = 2u;

struct Flight {
    kind: u32,
    t: f32,
}

// `beta`: the path's throughput, which a chromatic medium's spectral
// tracking weighs (spectral.wgsl, `collide_rgb`; delta.rs's
// `sample_free_flight`); a grey medium leaves it alone.
fn free_flight(origin: vec3<f32>, dir: vec3<f32>, beta: ptr<function, vec3<f32>>, rng: ptr<function, u32>) -> Flight {
    var w = walk_start(origin, dir, false, rng);
    let rgb = chromatic();
    loop {
        iterations += 1u;
        let e = walk_next(&w, rng);
        if e.kind == EVENT_END {
            return Flight(FLIGHT_ESCAPED, 0.0);
        }
        if e.kind == EVENT_CAPPED {
            return Flight(FLIGHT_CAPPED, 0.0);
        }
        if e.kind == EVENT_COLLISION {
            var c = COLLISION_NULL;
            if rgb {
                c = collide_rgb(walk_sigma_rgb(&w, e.t), w.seg_hi, beta, rng);
            } else if random(rng) * w.seg_hi < walk_sigma(&w, e.t) {
                c = COLLISION_REAL;
            }
            if c == COLLISION_REAL {
                real_collisions += 1u;
                return Flight(FLIGHT_COLLISION, e.t);
            }
            if c == COLLISION_DEAD {
                return Flight(FLIGHT_CAPPED, 0.0);
            }
            null_collisions += 1u;
        }
    }
    cut_short = true;
    return Flight(FLIGHT_CAPPED, 0.0);
}
