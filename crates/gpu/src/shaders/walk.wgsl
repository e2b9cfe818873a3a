// The walk every tracker shares: tentative collisions of a Poisson process
// whose rate is the majorant of each cell a DDA crosses.
//
// Mirrors crates/kernel/src/tracking/walk.rs (draw an optical depth,
// subtract majorant x length cell by cell, step back to the collision when
// it runs out, draw afresh after each collision; cells of zero majorant are
// crossed without a draw) over an Amanatides-Woo DDA through one level of
// the bounds pyramid (crates/bricks/src/dda.rs walks the whole hierarchy;
// one level is this kernel's first form). Cells outside the pyramid hold
// nothing, so the ray is clipped to the brick grid's box first.

const MAX_COLLISIONS: u32 = 1000000u;

const EVENT_COLLISION: u32 = 0u;
const EVENT_END: u32 = 1u;
const EVENT_CAPPED: u32 = 2u;

struct Walk {
    // The ray in local index space (the parameter t is render space's).
    o: vec3<f32>,
    d: vec3<f32>,
    // DDA: where the current cell starts, where the ray leaves the box,
    // the cell, its step per axis, the t of the next face per axis and
    // the t between faces.
    t: f32,
    t_end: f32,
    cell: vec3<i32>,
    step: vec3<i32>,
    t_next: vec3<f32>,
    t_delta: vec3<f32>,
    // The cell being walked: its end and majorant (extinction units);
    // `inside` is false until one is entered.
    inside: bool,
    seg_end: f32,
    rate: f32,
    // Optical depth left before the next tentative collision.
    tau: f32,
    collisions: u32,
}

struct Event {
    kind: u32,
    t: f32,
    majorant: f32,
}

// The walk along render-space ray (origin, dir), its first depth drawn.
fn walk_start(origin: vec3<f32>, dir: vec3<f32>, rng: ptr<function, u32>) -> Walk {
    var w: Walk;
    w.o = (params.local_from_render * vec4<f32>(origin, 1.0)).xyz;
    w.d = (params.local_from_render * vec4<f32>(dir, 0.0)).xyz;
    w.tau = sample_exponential(random(rng));
    w.inside = false;
    w.collisions = 0u;
    let edge = params.extent.w;
    let cells = vec3<i32>(params.cell_dims.xyz);
    var t0 = 0.0;
    var t1 = FAR;
    for (var k = 0; k < 3; k++) {
        let o = w.o[k];
        let d = w.d[k];
        if abs(d) < 1.0e-30 {
            // Parallel to the slab: inside it or never.
            if o < 0.0 || o > params.extent[k] {
                t1 = -1.0;
            }
            w.step[k] = 0;
            w.t_next[k] = FAR;
            w.t_delta[k] = FAR;
        } else {
            let ta = (0.0 - o) / d;
            let tb = (params.extent[k] - o) / d;
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        }
    }
    w.t = t0;
    w.t_end = t1;
    if t0 >= t1 {
        w.t_end = t0;
        return w;
    }
    let p = w.o + w.d * t0;
    w.cell = clamp(vec3<i32>(floor(p / edge)), vec3<i32>(0), cells - vec3<i32>(1));
    for (var k = 0; k < 3; k++) {
        let d = w.d[k];
        if abs(d) >= 1.0e-30 {
            let forward = d > 0.0;
            w.step[k] = select(-1, 1, forward);
            let face = f32(w.cell[k] + select(0, 1, forward)) * edge;
            w.t_next[k] = (face - w.o[k]) / d;
            w.t_delta[k] = edge / abs(d);
        }
    }
    return w;
}

// Enters the next cell; false when the ray has left the box.
fn walk_enter(w: ptr<function, Walk>) -> bool {
    if (*w).t >= (*w).t_end {
        return false;
    }
    let tn = (*w).t_next;
    let m = min(tn.x, min(tn.y, tn.z));
    let c = vec3<u32>((*w).cell);
    let dims = params.cell_dims;
    (*w).rate = params.albedo.w * majorants[c.x * (dims.y * dims.z) + (c.y * dims.z + c.z)];
    (*w).seg_end = min(m, (*w).t_end);
    (*w).inside = true;
    // Step the DDA past this cell's exit face.
    var axis = 2;
    if tn.x == m {
        axis = 0;
    } else if tn.y == m {
        axis = 1;
    }
    (*w).cell[axis] += (*w).step[axis];
    (*w).t_next[axis] += (*w).t_delta[axis];
    let next = (*w).cell[axis];
    if next < 0 || next >= i32(dims[axis]) {
        // The walk ends at this cell's end.
        (*w).t_end = (*w).seg_end;
    }
    return true;
}

// The next event of the walk.
fn walk_next(w: ptr<function, Walk>, rng: ptr<function, u32>) -> Event {
    loop {
        iterations += 1u;
        if !(*w).inside {
            if !walk_enter(w) {
                return Event(EVENT_END, 0.0, 0.0);
            }
        }
        let rate = (*w).rate;
        // `rate > 0` is false for NaN too: such cells are skipped.
        if rate > 0.0 {
            let depth = rate * ((*w).seg_end - (*w).t);
            if (*w).tau < depth {
                (*w).collisions += 1u;
                if (*w).collisions > MAX_COLLISIONS {
                    return Event(EVENT_CAPPED, 0.0, 0.0);
                }
                (*w).t = min((*w).t + (*w).tau / rate, (*w).seg_end);
                (*w).tau = sample_exponential(random(rng));
                return Event(EVENT_COLLISION, (*w).t, rate);
            }
            (*w).tau -= depth;
        }
        (*w).t = (*w).seg_end;
        (*w).inside = false;
    }
    cut_short = true;
    return Event(EVENT_CAPPED, 0.0, 0.0);
}

// Extinction at the walk's ray parameter `t`.
fn walk_sigma(w: ptr<function, Walk>, t: f32) -> f32 {
    return sigma_t((*w).o + (*w).d * t);
}
