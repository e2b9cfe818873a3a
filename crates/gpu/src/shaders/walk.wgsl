// The walk every tracker shares: tentative collisions of a Poisson process
// whose rate is constant on each majorant segment.
//
// Segments: crates/bricks/src/dda.rs (`SegmentIter::walk`, `voxel_cell`,
// `CellRay::leave`, `leave_empty`) over the host's cell partition
// (crates/bricks/src/partition.rs): at each step the cell holding the ray
// just past `t` is read from one table (the kept level of the bounds
// pyramid, or an empty cube of bricks to jump), its bounds from that
// level, and the ray leaves the cell's box. Finest cells too thick for
// their slack are walked voxel by voxel, bounded by their eight corner
// voxels. Under `--majorant global` the walk is one segment over the box
// at the volume's largest density (crates/kernel/src/medium/global.rs).
//
// Collisions: crates/kernel/src/tracking/walk.rs (draw an optical depth,
// subtract rate x length segment by segment, step back to the collision
// when it runs out, draw afresh after each collision; segments of zero
// rate are crossed without a draw). The rate is the majorant, or for
// residual ratio tracking the majorant less the minorant.

const MAX_COLLISIONS: u32 = 1000000u;

const EVENT_COLLISION: u32 = 0u;
const EVENT_END: u32 = 1u;
const EVENT_CAPPED: u32 = 2u;
// The walk entered a segment with a minorant under residual tracking
// (which applies its control transmittance here).
const EVENT_ENTER: u32 = 3u;

// Partition codes (partition.rs): an empty level-1 cell's flag; a cell
// outside the volume (`cell_at`'s None).
const CELL_EMPTY: u32 = 0x80u;
const CELL_OUTSIDE: u32 = 0xffffffffu;

struct Walk {
    // The ray in local index space (the parameter t is render space's),
    // and 1 / d (FAR on axes it never crosses).
    o: vec3<f32>,
    d: vec3<f32>,
    inv_d: vec3<f32>,
    // Where the walk is, and where the ray leaves the box.
    t: f32,
    t_end: f32,
    // Absolute part of the nudge: 1e-5 voxels along the major axis.
    nudge_abs: f32,
    // The segment being walked: its ends, bounds (extinction units) and
    // rate; `inside` is false until one is entered.
    inside: bool,
    seg_t0: f32,
    seg_t1: f32,
    seg_lo: f32,
    seg_hi: f32,
    rate: f32,
    residual: bool,
    // Optical depth left before the next tentative collision.
    tau: f32,
    collisions: u32,
}

struct Event {
    kind: u32,
    t: f32,
}

// The walk along render-space ray (origin, dir) with rates for residual
// tracking where `residual`, its first depth drawn. The ray is clipped to
// the brick grid's box (aabb.rs, clip_ray): a component below 1e-30 lies
// in its slab or not by the origin alone.
fn walk_start(origin: vec3<f32>, dir: vec3<f32>, residual: bool, rng: ptr<function, u32>) -> Walk {
    var w: Walk;
    w.o = (params.local_from_render * vec4<f32>(origin, 1.0)).xyz;
    w.d = (params.local_from_render * vec4<f32>(dir, 0.0)).xyz;
    w.tau = sample_exponential(random(rng));
    w.inside = false;
    w.residual = residual;
    w.collisions = 0u;
    w.nudge_abs = 1.0e-5 / max(abs(w.d.x), max(abs(w.d.y), abs(w.d.z)));
    var t0 = 0.0;
    var t1 = FAR;
    for (var k = 0; k < 3; k++) {
        let o = w.o[k];
        let d = w.d[k];
        if abs(d) < 1.0e-30 {
            if o < 0.0 || o > params.extent[k] {
                t1 = -1.0;
            }
            w.inv_d[k] = FAR;
        } else {
            w.inv_d[k] = 1.0 / d;
            let ta = (0.0 - o) / d;
            let tb = (params.extent[k] - o) / d;
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        }
    }
    // An exit that is not finite (a direction too small to leave the box)
    // is no walk.
    if !(t0 < t1) || t1 >= FAR {
        t0 = 0.0;
        t1 = 0.0;
    }
    w.t = t0;
    w.t_end = t1;
    return w;
}

// Moves `t` to where the ray leaves the box [lo, hi] through its far
// faces, by at least `nudge` and at most to the ray's end; returns the t
// it left from (dda.rs, CellRay::leave: an exit rounding put at or behind
// `t` is moved on by the time its coordinate takes to pass the face).
fn walk_leave(w: ptr<function, Walk>, lo: vec3<f32>, hi: vec3<f32>, nudge: f32) -> f32 {
    let d = (*w).d;
    let upward = d >= vec3<f32>(0.0);
    let far = select(lo, hi, upward);
    let never = abs(d) < vec3<f32>(1.0e-30);
    var exits = (far - (*w).o) * (*w).inv_d;
    let t0 = (*w).t;
    let behind = exits <= vec3<f32>(t0);
    let creep = abs(far) * 1.1920929e-7 * abs((*w).inv_d);
    exits = select(exits, exits + creep, behind);
    exits = select(exits, vec3<f32>(FAR), never | !(exits > vec3<f32>(t0)));
    let exit = min(exits.x, min(exits.y, exits.z));
    let least = t0 + nudge;
    var t = least;
    if exit > least && exit < FAR {
        t = exit;
    }
    (*w).t = min(t, (*w).t_end);
    return t0;
}

// (min, max) of cell `c` of pyramid level `l` ((0, 0) outside it).
fn level_bounds(l: u32, c: vec3<i32>) -> vec2<f32> {
    let info = params.levels[l];
    let dims = vec3<i32>(info.xyz);
    if any(c < vec3<i32>(0)) || any(c >= dims) {
        return vec2<f32>(0.0);
    }
    let u = vec3<u32>(c);
    let i = info.w + 2u * (u.x * (info.y * info.z) + (u.y * info.z + u.z));
    return vec2<f32>(pyramid[i], pyramid[i + 1u]);
}

// The partition's code of level-1 cell `c1` (CELL_OUTSIDE outside it):
// one byte each, four to a word.
fn cell_code(c1: vec3<i32>) -> u32 {
    let dims = vec3<i32>(params.part_dims.xyz);
    if any(c1 < vec3<i32>(0)) || any(c1 >= dims) {
        return CELL_OUTSIDE;
    }
    let u = vec3<u32>(c1);
    let i = u.x * (params.part_dims.y * params.part_dims.z) + (u.y * params.part_dims.z + u.z);
    return (cell_codes[i >> 2u] >> ((i & 3u) * 8u)) & 0xffu;
}

// (min, max) of the eight voxels bounding voxel cell [c, c + 1)
// (volume.rs, voxel_cell_range), one voxel a turn of a loop the compiler
// cannot unroll (common.wgsl, `corners`).
fn voxel_cell_bounds(c: vec3<i32>) -> vec2<f32> {
    var lo = FAR;
    var hi = -FAR;
    for (var k = 0; k < corners(); k++) {
        iterations += 1u;
        let v = voxel(c + vec3<i32>((k >> 2u) & 1, (k >> 1u) & 1, k & 1));
        lo = min(lo, v);
        hi = max(hi, v);
    }
    return vec2<f32>(lo, hi);
}

// The next segment with density into the walk's `seg_*` (density units);
// false at the end of the ray.
fn walk_segment(w: ptr<function, Walk>) -> bool {
    if params.walk_mode.x == 1u {
        // The global bound: the clipped ray, once.
        let hi = params.walk.y;
        let t0 = (*w).t;
        (*w).t = (*w).t_end;
        (*w).seg_t0 = t0;
        (*w).seg_t1 = (*w).t_end;
        (*w).seg_lo = 0.0;
        (*w).seg_hi = hi;
        return t0 < (*w).t_end && hi > 0.0;
    }
    loop {
        if (*w).t >= (*w).t_end {
            break;
        }
        iterations += 1u;
        let nudge = abs((*w).t) * 1.0e-6 + (*w).nudge_abs;
        let voxel = vec3<i32>(floor((*w).o + (*w).d * ((*w).t + nudge)));
        let c1 = voxel >> vec3<u32>(3u);
        let code = cell_code(c1);
        var l = 0u;
        var b = vec2<f32>(0.0);
        if code == CELL_OUTSIDE {
            // A nudge past the box's face: an empty level-0 cell.
        } else if (code & CELL_EMPTY) != 0u {
            // Past the empty cube of level-1 cells within distance - 1.
            let r = i32(code & 0x7fu) - 1;
            let lo = vec3<f32>(c1 - vec3<i32>(r)) * 8.0;
            let hi = vec3<f32>(c1 + vec3<i32>(r + 1)) * 8.0;
            walk_leave(w, lo, hi, nudge);
            continue;
        } else {
            l = code;
            b = level_bounds(l, voxel >> vec3<u32>(2u + l));
        }
        var size = f32(1u << (2u + l));
        var cell_lo = vec3<f32>(voxel >> vec3<u32>(2u + l)) * size;
        if l == 0u && b.y > b.x && (b.y - b.x) * size > params.walk.x {
            b = voxel_cell_bounds(voxel);
            size = 1.0;
            cell_lo = vec3<f32>(voxel);
        }
        let t0 = walk_leave(w, cell_lo, cell_lo + vec3<f32>(size), nudge);
        if b.y > 0.0 {
            (*w).seg_t0 = t0;
            (*w).seg_t1 = (*w).t;
            (*w).seg_lo = b.x;
            (*w).seg_hi = b.y;
            return true;
        }
    }
    return false;
}

// The next event of the walk.
fn walk_next(w: ptr<function, Walk>, rng: ptr<function, u32>) -> Event {
    loop {
        iterations += 1u;
        if !(*w).inside {
            if !walk_segment(w) {
                return Event(EVENT_END, 0.0);
            }
            // Extinction units: the medium's density scale.
            let scale = params.albedo.w;
            (*w).seg_lo *= scale;
            (*w).seg_hi *= scale;
            (*w).rate = select((*w).seg_hi, (*w).seg_hi - (*w).seg_lo, (*w).residual);
            (*w).inside = true;
            (*w).t = (*w).seg_t0;
            // Only residual tracking has anything to do on entering a
            // segment: the others walk on in this loop rather than
            // another turn of the caller's, whose body is long.
            if (*w).residual && (*w).seg_lo > 0.0 {
                return Event(EVENT_ENTER, (*w).seg_t0);
            }
        }
        let rate = (*w).rate;
        // `rate > 0` is false for NaN too: such segments are skipped.
        if rate > 0.0 {
            let depth = rate * ((*w).seg_t1 - (*w).t);
            if (*w).tau < depth {
                (*w).collisions += 1u;
                if (*w).collisions > MAX_COLLISIONS {
                    return Event(EVENT_CAPPED, 0.0);
                }
                (*w).t = min((*w).t + (*w).tau / rate, (*w).seg_t1);
                (*w).tau = sample_exponential(random(rng));
                return Event(EVENT_COLLISION, (*w).t);
            }
            (*w).tau -= depth;
        }
        (*w).t = (*w).seg_t1;
        (*w).inside = false;
    }
    cut_short = true;
    return Event(EVENT_CAPPED, 0.0);
}

// Extinction at the walk's ray parameter `t`, clamped to the segment's
// majorant (tracking/lookup.rs).
fn walk_sigma(w: ptr<function, Walk>, t: f32) -> f32 {
    return min(sigma_t((*w).o + (*w).d * t), (*w).seg_hi);
}
