// Delta (Woodcock) tracking: the distance to the first real collision,
// with density sigma_t exp(-integral of sigma_t). Mirrors
// crates/kernel/src/tracking/delta.rs for a grey medium (`f32`'s
// `Spectrum::collide`: real when xi * majorant < sigma_t).

const FLIGHT_COLLISION: u32 = 0u;
const FLIGHT_ESCAPED: u32 = 1u;
const FLIGHT_CAPPED: u32 = 2u;

struct Flight {
    kind: u32,
    t: f32,
}

fn free_flight(origin: vec3<f32>, dir: vec3<f32>, rng: ptr<function, u32>) -> Flight {
    var w = walk_start(origin, dir, false, rng);
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
            let xi = random(rng) * w.seg_hi;
            if xi < walk_sigma(&w, e.t) {
                real_collisions += 1u;
                return Flight(FLIGHT_COLLISION, e.t);
            }
            null_collisions += 1u;
        }
    }
    cut_short = true;
    return Flight(FLIGHT_CAPPED, 0.0);
}
