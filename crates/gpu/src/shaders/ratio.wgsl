// Ratio tracking (Novak, Selle, Jarosz 2014) for shadow rays: the product
// of null fractions 1 - sigma_t / majorant over the tentative collisions,
// with pbrt-v4's Russian roulette below 0.05 (q = 0.75). Mirrors
// crates/kernel/src/tracking/ratio.rs and tracking/roulette.rs (`f32`'s
// `null_fraction` and `roulette` in crates/kernel/src/spectrum.rs).

const TR_ROULETTE_THRESHOLD: f32 = 0.05;
const TR_ROULETTE_Q: f32 = 0.75;

// Transmittance along render-space ray (origin, dir) to infinity.
fn transmittance(origin: vec3<f32>, dir: vec3<f32>, rng: ptr<function, u32>) -> f32 {
    var w = walk_start(origin, dir, rng);
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
        shadow_collisions += 1u;
        tr *= max(1.0 - walk_sigma(&w, e.t) / e.majorant, 0.0);
        if tr <= 0.0 {
            return 0.0;
        }
        if tr < TR_ROULETTE_THRESHOLD {
            if random(rng) < TR_ROULETTE_Q {
                return 0.0;
            }
            tr /= 1.0 - TR_ROULETTE_Q;
        }
    }
    cut_short = true;
    return 0.0;
}
