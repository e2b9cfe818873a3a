// The flat scene's bindings and the path's random numbers.
//
// The structs mirror crates/gpu/src/flat.rs (Params, LightRecord) and the
// film's pixel (crates/gpu/src/film.rs, PixelSlot). The generator stands in
// for crates/kernel/src/sampling.rs's counter-based Rng: keyed by (seed,
// pixel, sample) as it is, so an image does not depend on how samples are
// split into passes; its stream is its own (PCG, O'Neill 2014), so CPU and
// GPU images agree in distribution, not bit for bit.

struct Params {
    local_from_render: mat4x4<f32>,
    cam_origin: vec4<f32>,
    cam_forward: vec4<f32>,
    cam_right: vec4<f32>,
    cam_up: vec4<f32>,
    albedo: vec4<f32>,
    extent: vec4<f32>,
    // The phase function's lobes (phase.wgsl): g, alpha, norm and (w)
    // the first lobe's weight.
    phase: vec4<f32>,
    phase_b: vec4<f32>,
    map_dims: vec4<u32>,
    // Lights (x), stored bricks per atlas chunk (y), a tabulated phase
    // function's rows (z).
    counts: vec4<u32>,
    image: vec4<u32>,
    window: vec4<u32>,
    seed: vec4<u32>,
    // The walk (walk.wgsl): the slack past which a finest cell is walked
    // voxel by voxel (x), the volume's largest density (y).
    walk: vec4<f32>,
    // Majorants (x: 0 the hierarchy, 1 one global bound), shadow rays'
    // estimator (y: ratio.wgsl's TRANSMITTANCE_*), the corners of a
    // voxel cell (z: 8, see `corners`).
    walk_mode: vec4<u32>,
    // Level-1 cells of the partition per axis (xyz).
    part_dims: vec4<u32>,
    // Per pyramid level: cells per axis (xyz), its first float in
    // `pyramid` (w).
    levels: array<vec4<u32>, 9>,
    // Each channel's share of the extinction (xyz), and (w) 1 for a
    // chromatic medium (spectral.wgsl).
    tint: vec4<f32>,
}

// Per kind: lights.wgsl.
struct LightRecord {
    tag: vec4<u32>,
    dir: vec4<f32>,
    radiance: vec4<f32>,
    shape: array<vec4<f32>, 3>,
}

// One pixel's running moments (Welford), as the host film keeps them,
// with the samples replaced by zero (non-finite) and cut short (the
// device's loop limit, see path.wgsl).
struct PixelSlot {
    mean: vec4<f32>,
    m2: vec4<f32>,
    n: u32,
    nonfinite: u32,
    cut: u32,
    // Tentative collisions of free flights, real and null, and of shadow
    // rays (crates/kernel/src/counters.rs).
    reals: u32,
    nulls: u32,
    shadows: u32,
    pad0: u32,
    pad1: u32,
}

// A pixel's path under way, kept between dispatches (crates/kernel/src/
// integrator/path_state.rs's Path, for a grey medium).
struct PathState {
    // The ray, and (w) the density its direction was phase-sampled with
    // (0: the camera ray).
    origin: vec4<f32>,
    // Direction, and (w) alpha.
    dir: vec4<f32>,
    beta: vec4<f32>,
    radiance: vec4<f32>,
    rng: u32,
    // Scattering events so far.
    depth: u32,
    // The pixel's sample being traced (or the next to start).
    sample: u32,
    // Whether a path is under way.
    under_way: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> brick_map: array<u32>;
// The atlas's first chunk; the others (`atlas_1`, ...: bindings 11 on)
// and `atlas_word`, which reads any, are written by the host for the
// chunks a scene needs (kernel.rs, `atlas_chunks_source`).
@group(0) @binding(2) var<storage, read> atlas_0: array<u32>;
@group(0) @binding(3) var<storage, read> constants: array<f32>;
// The bounds pyramid: (min, max) pairs, level after level.
@group(0) @binding(4) var<storage, read> pyramid: array<f32>;
@group(0) @binding(5) var<storage, read> lights: array<LightRecord>;
@group(0) @binding(6) var<storage, read_write> film: array<PixelSlot>;
@group(0) @binding(7) var<storage, read_write> paths: array<PathState>;
// Pixels with samples left after a dispatch (an integer count: its value
// does not depend on the order invocations add to it).
@group(0) @binding(8) var<storage, read_write> pending: array<atomic<u32>>;
// The cell partition's codes, a byte a level-1 cell, four to a word.
@group(0) @binding(9) var<storage, read> cell_codes: array<u32>;
// A tabulated phase function's cosines, values and CDF (table_phase.wgsl).
@group(0) @binding(10) var<storage, read> phase_table: array<f32>;

// Set where a loop was left other than by its own exits: lavapipe
// (llvmpipe) ends every loop once an invocation has run 65535 iterations
// of loops in all, and a walk cut there is no estimate of anything.
var<private> cut_short: bool;

// Loop iterations this invocation has run (every loop counts one a turn,
// as llvmpipe counts them): a dispatch stops starting scattering events
// past ITERATION_BUDGET, which leaves the event under way as many
// iterations again before that limit.
var<private> iterations: u32;
const ITERATION_BUDGET: u32 = 32768u;

// This invocation's collisions, added to its pixel's slot at its end.
var<private> real_collisions: u32;
var<private> null_collisions: u32;
var<private> shadow_collisions: u32;

// The corners of a voxel cell, 8, read from the parameters so that no
// compiler unrolls a loop over them. Lavapipe (llvmpipe) runs a branch
// that any invocation of a SIMD batch takes with all of them masked, so
// every voxel lookup written out in a loop's body costs each turn of that
// loop whether taken or not; a loop whose trip count it cannot see stays
// one lookup long (and is skipped where no invocation enters it). Eight
// lookups unrolled into the walk's thick-cell branch and the trilinear
// filter made the kernel 2-3 times slower there.
fn corners() -> i32 {
    return i32(params.walk_mode.z);
}

const PI: f32 = 3.14159265358979;
const FAR: f32 = 3.0e38;

// PCG's output permutation (RXS-M-XS) of a 32-bit state.
fn pcg_permute(s: u32) -> u32 {
    let w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}

fn pcg_hash(x: u32) -> u32 {
    return pcg_permute(x * 747796405u + 2891336453u);
}

// The generator's state for sample `sample` of image pixel `pixel`.
fn rng_key(pixel: u32, sample: u32) -> u32 {
    let s = pcg_hash(params.seed.x ^ pcg_hash(params.seed.y));
    return pcg_hash(pcg_hash(s ^ pixel) ^ sample);
}

// A uniform number in [0, 1), 24 bits, advancing the state.
fn random(state: ptr<function, u32>) -> f32 {
    let old = *state;
    *state = old * 747796405u + 2891336453u;
    return f32(pcg_permute(old) >> 8u) * (1.0 / 16777216.0);
}

// An optical depth with density exp(-tau) (sampling.rs, sample_exponential).
fn sample_exponential(u: f32) -> f32 {
    return -log(1.0 - u);
}

fn finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}
