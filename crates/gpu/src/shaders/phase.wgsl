// The phase functions every medium scatters with: a table
// (table_phase.wgsl), or, for every other, as
// one form: a blend `w A + (1 - w) B` of two Draine lobes
// `HG_g(mu) (1 + alpha mu^2) / (1 + alpha (1 + 2 g^2) / 3)`, which is
// Henyey-Greenstein at alpha = 0 and Rayleigh at g = 0, alpha = 1. So HG,
// two-lobe HG, Draine, the approximate Mie fit (HG + Draine) and Rayleigh
// are each a choice of (w, g, alpha) per lobe (flat.rs, `phase_lobes`).
//
// Mirrors crates/kernel/src/phase/hg.rs (eval_cos, sample_cos),
// draine.rs (eval_cos), blend.rs (the lobe picked by u < w, u rescaled).
// A Draine lobe is sampled by rejection rather than draine.rs's quartic
// (whose cancellation-free form needs f64): an HG direction is kept with
// probability (1 + alpha mu^2) / (1 + alpha), which draws exactly the
// lobe's density, in under 3 tries on average for any g and alpha (HG's
// E[mu^2] is at least 1/3). Every sample's density is the function's own
// value, as on the CPU.

// Uniform numbers below 1: a rescaled one stays in [0, 1) (blend.rs).
const ONE_MINUS_EPSILON: f32 = 0.99999994;

// HG density for cosine `mu`, written without cancellation at the peak
// (hg.rs, eval_cos).
fn hg_eval(g: f32, mu_in: f32) -> f32 {
    let mu = clamp(mu_in, -1.0, 1.0);
    var denom: f32;
    if g >= 0.0 {
        denom = (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - mu);
    } else {
        denom = (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + mu);
    }
    return (1.0 - g) * (1.0 + g) / (4.0 * PI * denom * sqrt(denom));
}

// Inverts the HG CDF in `mu` (hg.rs, sample_cos).
fn hg_sample_cos(g: f32, u: f32) -> f32 {
    if g == 0.0 {
        return 1.0 - 2.0 * u;
    }
    let s = (1.0 - g) * (1.0 + g) / (1.0 - g + 2.0 * g * u);
    return clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

// Lobe (g, alpha, norm) at cosine `mu` (draine.rs, eval_cos).
fn lobe_eval(lobe: vec4<f32>, mu_in: f32) -> f32 {
    let mu = clamp(mu_in, -1.0, 1.0);
    return hg_eval(lobe.x, mu) * (1.0 + lobe.y * mu * mu) * lobe.z;
}

// A cosine drawn from lobe (g, alpha, norm), `u` the first number.
fn lobe_sample_cos(lobe: vec4<f32>, u: f32, rng: ptr<function, u32>) -> f32 {
    var mu = hg_sample_cos(lobe.x, u);
    let alpha = lobe.y;
    if alpha == 0.0 {
        return mu;
    }
    loop {
        iterations += 1u;
        if random(rng) * (1.0 + alpha) < 1.0 + alpha * mu * mu {
            break;
        }
        mu = hg_sample_cos(lobe.x, random(rng));
    }
    return mu;
}

// The medium's phase function at scattering-angle cosine `mu`.
fn phase_eval(mu: f32) -> f32 {
    if is_table_phase() {
        return table_eval(mu);
    }
    let w = params.phase.w;
    return w * lobe_eval(params.phase, mu) + (1.0 - w) * lobe_eval(params.phase_b, mu);
}

// A phase-sampled direction (xyz) and its density (w) (phase/mod.rs, sample).
fn phase_sample(dir_in: vec3<f32>, rng: ptr<function, u32>) -> vec4<f32> {
    let u = random(rng);
    let w = params.phase.w;
    var mu: f32;
    if is_table_phase() {
        mu = table_sample_cos(u);
    } else if u < w {
        mu = lobe_sample_cos(params.phase, min(u / w, ONE_MINUS_EPSILON), rng);
    } else {
        mu = lobe_sample_cos(params.phase_b, min((u - w) / (1.0 - w), ONE_MINUS_EPSILON), rng);
    }
    let sin_t = sqrt(max(1.0 - mu * mu, 0.0));
    let phi = 2.0 * PI * random(rng);
    let dir = from_local(dir_in, sin_t * cos(phi), sin_t * sin(phi), mu);
    return vec4<f32>(dir, phase_eval(mu));
}
