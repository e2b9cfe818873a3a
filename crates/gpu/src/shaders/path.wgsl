// The megakernel: one invocation owns one pixel of the window, takes its
// samples in order and adds each to the pixel's running moments (so no
// two invocations touch one pixel, and no sum depends on scheduling). A
// dispatch advances each pixel's paths by up to `params.window.w`
// scattering events, starting none once it has run ITERATION_BUDGET loop
// iterations, and keeps the path under way in `paths` for the next: a
// dispatch stays short on a GPU, and within lavapipe's loop limit
// (common.wgsl).
//
// Mirrors crates/kernel/src/integrator/path.rs (`trace`, `escape`,
// `collide`, `scatter_from`, `roulette`) and path_light.rs (`direct_light`,
// `light_term`) and path_flight.rs (light surfaces met on the way) for
// one grey medium and its lights (lights.wgsl; phase function:
// phase.wgsl): every
// collision scatters with the albedo as weight, every light is sampled at
// every vertex (shadow rays by the settings' estimator, ratio.wgsl), phase-sampled directions
// that escape take the power heuristic against those samples, Russian
// roulette after 3 events below a throughput of 0.1.

const ROULETTE_MIN_DEPTH: u32 = 3u;
const ROULETTE_THROUGHPUT: f32 = 0.1;

fn max3(v: vec3<f32>) -> f32 {
    return max(v.x, max(v.y, v.z));
}

// The camera ray through image point (px, py) (camera.rs, ray).
fn camera_dir(px: f32, py: f32) -> vec3<f32> {
    let sx = 2.0 * px / f32(params.image.x) - 1.0;
    let sy = 1.0 - 2.0 * py / f32(params.image.y);
    return normalize(params.cam_forward.xyz + sx * params.cam_right.xyz + sy * params.cam_up.xyz);
}

// What lights at infinity add along an escaping ray; `pdf`: the density
// its direction was phase-sampled with, 0 for a camera ray (full weight).
fn escape_radiance(dir: vec3<f32>, pdf: f32) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < params.counts.x; i++) {
        iterations += 1u;
        let e = escaped_light(i, dir);
        if e.w > 0.0 {
            let w = select(1.0, power_heuristic(pdf, e.w), pdf > 0.0);
            sum += e.xyz * w;
        }
    }
    return sum;
}

// What the light surfaces (balls) a ray from `origin` along `dir` meets
// before `reach` add: lights do not block rays, and a flight reaches a
// surface before its collision with the transmittance's odds, as the
// CPU's flight split at each surface does (path_flight.rs, `fly`,
// `gather_surface`). `pdf`: the density its direction was phase-sampled
// with, weighed against each light's own sampling; a camera ray
// (`camera`) sees the camera-visible ones whole.
fn surface_radiance(origin: vec3<f32>, dir: vec3<f32>, reach: f32, pdf: f32, camera: bool) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < params.counts.x; i++) {
        iterations += 1u;
        let h = hit_light(i, origin, dir, reach, camera);
        if h.w > 0.0 {
            sum += h.xyz * select(power_heuristic(pdf, h.w), 1.0, camera);
        }
    }
    return sum;
}

// Next-event estimation at `p`, reached along `dir_in`: one sample of
// every light, weighed against phase sampling where `mis`.
fn direct_light(p: vec3<f32>, dir_in: vec3<f32>, mis: bool, rng: ptr<function, u32>) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < params.counts.x; i++) {
        iterations += 1u;
        let s = sample_light(i, p, dir_in, mis, rng);
        let f = phase_eval(dot(dir_in, s.to_light));
        var weight = 0.0;
        if s.pdf < 0.0 {
            weight = f;
        } else if s.pdf > 0.0 {
            let w = select(1.0, power_heuristic(s.pdf, f), mis);
            weight = f * w / s.pdf;
        }
        // Outside a spot's cone: no light, no shadow ray.
        if weight > 0.0 && max3(s.radiance) > 0.0 {
            sum += s.radiance * (weight * transmittance(p, s.to_light, s.distance, rng));
        }
    }
    return sum;
}

// The camera path of sample `sample` of image pixel (x, y), started.
fn start_path(x: u32, y: u32, pixel: u32, sample: u32) -> PathState {
    var st: PathState;
    var rng = rng_key(pixel, sample);
    let jx = random(&rng);
    let jy = random(&rng);
    st.origin = vec4<f32>(params.cam_origin.xyz, 0.0);
    st.dir = vec4<f32>(camera_dir(f32(x) + jx, f32(y) + jy), 0.0);
    st.beta = vec4<f32>(1.0);
    st.radiance = vec4<f32>(0.0);
    st.rng = rng;
    st.depth = 0u;
    st.sample = sample;
    st.under_way = 1u;
    return st;
}

// One free flight of the path and the events at its end: escape, or the
// collision's scattering (albedo, next-event estimation, the phase-sampled
// direction, roulette). Returns true when the path has ended.
fn advance(st: ptr<function, PathState>, rng: ptr<function, u32>) -> bool {
    let origin = (*st).origin.xyz;
    let dir = (*st).dir.xyz;
    var weighed = (*st).beta.xyz;
    let flight = free_flight(origin, dir, &weighed, rng);
    (*st).beta = vec4<f32>(weighed, 0.0);
    if (*st).depth == 0u {
        // Alpha: the track-length estimate of 1 - T along the camera ray
        // (for a chromatic medium's escape, 1 - avg(beta) with the
        // flight's weights: spectrum.rs, `escaped_alpha`).
        var alpha = 1.0;
        if flight.kind == FLIGHT_ESCAPED {
            alpha = select(0.0, 1.0 - (weighed.x + weighed.y + weighed.z) / 3.0, chromatic());
        }
        (*st).dir.w = alpha;
    }
    if flight.kind != FLIGHT_CAPPED {
        let reach = select(flight.t, FAR, flight.kind == FLIGHT_ESCAPED);
        let e = surface_radiance(origin, dir, reach, (*st).origin.w, (*st).depth == 0u);
        (*st).radiance += vec4<f32>((*st).beta.xyz * e, 0.0);
    }
    if flight.kind == FLIGHT_ESCAPED {
        let e = escape_radiance(dir, (*st).origin.w);
        (*st).radiance += vec4<f32>((*st).beta.xyz * e, 0.0);
        return true;
    }
    let max_depth = params.seed.z;
    if flight.kind == FLIGHT_CAPPED || (*st).depth == max_depth {
        return true;
    }
    let p = origin + dir * flight.t;
    (*st).depth += 1u;
    let beta = (*st).beta.xyz * params.albedo.xyz;
    (*st).beta = vec4<f32>(beta, 0.0);
    if max3(beta) <= 0.0 {
        return true;
    }
    let last = (*st).depth == max_depth;
    (*st).radiance += vec4<f32>(beta * direct_light(p, dir, !last, rng), 0.0);
    if last {
        return true;
    }
    let s = phase_sample(dir, rng);
    (*st).origin = vec4<f32>(p, s.w);
    (*st).dir = vec4<f32>(s.xyz, (*st).dir.w);
    if (*st).depth >= ROULETTE_MIN_DEPTH {
        let m = max3(beta);
        if m < ROULETTE_THROUGHPUT {
            if random(rng) >= m {
                return true;
            }
            (*st).beta = vec4<f32>(beta / m, 0.0);
        }
    }
    return false;
}

// Adds a finished sample (radiance, alpha) to the pixel's moments; a
// non-finite sample counts as zero and is counted (crates/render/src/
// film.rs, Tile::add).
fn accumulate(acc: ptr<function, PixelSlot>, sample: vec4<f32>) {
    var v = sample;
    if !(finite(v.x) && finite(v.y) && finite(v.z) && finite(v.w)) {
        v = vec4<f32>(0.0);
        (*acc).nonfinite += 1u;
    }
    (*acc).n += 1u;
    let delta = v - (*acc).mean;
    (*acc).mean += delta / f32((*acc).n);
    (*acc).m2 += delta * (v - (*acc).mean);
}

@compute @workgroup_size(8, 8, 1)
fn render_pass(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = params.window.xy;
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let x = params.image.z + id.x;
    let y = params.image.w + id.y;
    // Keyed by the pixel's index in the full image, as the CPU's samples
    // are, so a crop renders the same pixels as the whole image.
    let pixel = y * params.image.x + x;
    let slot = id.y * size.x + id.x;
    let target_samples = params.window.z;
    var st = paths[slot];
    var acc = film[slot];
    // Between paths, the next sample is the count taken: the host may
    // have cleared the paths (a window rendered band by band, kernel.rs).
    if st.under_way == 0u {
        st.sample = acc.n;
    }
    if st.sample >= target_samples {
        return;
    }
    if st.under_way == 0u {
        st = start_path(x, y, pixel, st.sample);
    }
    var rng = st.rng;
    for (var k = 0u; k < params.window.w && iterations < ITERATION_BUDGET; k++) {
        iterations += 1u;
        let ended = advance(&st, &rng);
        if ended || cut_short {
            // A path cut short ends where it was, as a capped flight
            // ends a CPU path, and is counted.
            if cut_short {
                acc.cut += 1u;
                cut_short = false;
            }
            accumulate(&acc, vec4<f32>(st.radiance.xyz, st.dir.w));
            let next = st.sample + 1u;
            if next >= target_samples {
                st.sample = next;
                st.under_way = 0u;
                break;
            }
            st = start_path(x, y, pixel, next);
            rng = st.rng;
        }
    }
    st.rng = rng;
    acc.reals += real_collisions;
    acc.nulls += null_collisions;
    acc.shadows += shadow_collisions;
    paths[slot] = st;
    film[slot] = acc;
    if st.sample < target_samples {
        atomicAdd(&pending[0], 1u);
    }
}
