// The lights, one question each (crates/kernel/src/light/interface.rs:
// `sample_toward`, `hit`, `escaped`), dispatched on the record's tag.
// Lights at infinity here: crates/kernel/src/light/distant.rs (a delta
// sun, or a cone of uniform radiance irradiance / solid angle),
// crates/kernel/src/light/dome.rs (a constant sky sampled uniformly) and
// crates/kernel/src/sampling.rs (uniform_sphere, uniform_cone,
// from_local, power_heuristic); sphere lights: sphere_light.wgsl; area
// lights: area_light.wgsl.
//
// Records (flat.rs, LightRecord; the same five vec4 for every kind):
// tag.x the kind, then per kind
// - sun: dir = direction from the light, 1 - cos of its half angle;
//   radiance = irradiance, solid angle (0: a delta sun);
// - sky: radiance = its radiance;
// - sphere: sphere_light.wgsl;
// - area: area_light.wgsl.

const LIGHT_SUN: u32 = 0u;
const LIGHT_SKY: u32 = 1u;
const LIGHT_SPHERE: u32 = 2u;
const LIGHT_AREA: u32 = 3u;
const UNIFORM_SPHERE_PDF: f32 = 0.0795774715459;

// x s + y t for the tangents (s, t) of a frame whose z axis is `axis`
// (Duff et al. 2017, glam's any_orthonormal_pair).
fn tangent_point(axis: vec3<f32>, x: f32, y: f32) -> vec3<f32> {
    let sign = select(-1.0, 1.0, axis.z >= 0.0);
    let a = -1.0 / (sign + axis.z);
    let b = axis.x * axis.y * a;
    let s = vec3<f32>(1.0 + sign * axis.x * axis.x * a, sign * b, -sign * axis.x);
    let t = vec3<f32>(b, sign + axis.y * axis.y * a, -axis.y);
    return x * s + y * t;
}

// The direction (x, y, z) in a frame whose z axis is `axis`.
fn from_local(axis: vec3<f32>, x: f32, y: f32, z: f32) -> vec3<f32> {
    return normalize(tangent_point(axis, x, y) + z * axis);
}

fn uniform_sphere(u1: f32, u2: f32) -> vec3<f32> {
    let z = 1.0 - 2.0 * u1;
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = 2.0 * PI * u2;
    return vec3<f32>(r * cos(phi), r * sin(phi), z);
}

fn uniform_cone(axis: vec3<f32>, one_minus_cos: f32, u1: f32, u2: f32) -> vec3<f32> {
    let omc = u1 * one_minus_cos;
    let sin_t = sqrt(max(omc * (2.0 - omc), 0.0));
    let phi = 2.0 * PI * u2;
    return from_local(axis, sin_t * cos(phi), sin_t * sin(phi), 1.0 - omc);
}

fn power_heuristic(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    let b2 = b * b;
    if a2 + b2 > 0.0 {
        return a2 / (a2 + b2);
    }
    return 0.0;
}

// A direction toward a light with its radiance, solid-angle density
// (pdf < 0: a delta light, `radiance` its irradiance) and the distance a
// shadow ray travels toward it (FAR: to infinity).
struct LightSample {
    to_light: vec3<f32>,
    radiance: vec3<f32>,
    pdf: f32,
    distance: f32,
}

// Light `i`'s sample at `p`, reached along `dir_in`. A constant sky at
// a vertex without MIS (the last one) is drawn from the phase function
// (path_light.rs, sample_toward).
fn sample_light(i: u32, p: vec3<f32>, dir_in: vec3<f32>, mis: bool, rng: ptr<function, u32>) -> LightSample {
    let u1 = random(rng);
    let u2 = random(rng);
    let l = lights[i];
    if l.tag.x == LIGHT_SPHERE {
        return sample_sphere_light(l, p, u1, u2);
    }
    if l.tag.x == LIGHT_AREA {
        return sample_area_light(l, p, u1, u2);
    }
    if l.tag.x == LIGHT_SUN {
        let solid_angle = l.radiance.w;
        if solid_angle <= 0.0 {
            return LightSample(-l.dir.xyz, l.radiance.xyz, -1.0, FAR);
        }
        let to_light = uniform_cone(-l.dir.xyz, l.dir.w, u1, u2);
        return LightSample(to_light, l.radiance.xyz / solid_angle, 1.0 / solid_angle, FAR);
    }
    if mis {
        return LightSample(uniform_sphere(u1, u2), l.radiance.xyz, UNIFORM_SPHERE_PDF, FAR);
    }
    let s = phase_sample(dir_in, rng);
    return LightSample(s.xyz, l.radiance.xyz, s.w, FAR);
}

// Radiance (xyz) and sampling density (w) of light `i` seen by a ray
// escaping along `dir`; w = 0 where it sees none (a delta sun, or outside
// the sun's disc, or a light not at infinity).
fn escaped_light(i: u32, dir: vec3<f32>) -> vec4<f32> {
    let l = lights[i];
    if l.tag.x == LIGHT_SPHERE || l.tag.x == LIGHT_AREA {
        return vec4<f32>(0.0);
    }
    if l.tag.x == LIGHT_SUN {
        let solid_angle = l.radiance.w;
        if solid_angle <= 0.0 || 1.0 + dot(dir, l.dir.xyz) > l.dir.w {
            return vec4<f32>(0.0);
        }
        return vec4<f32>(l.radiance.xyz / solid_angle, 1.0 / solid_angle);
    }
    return vec4<f32>(l.radiance.xyz, UNIFORM_SPHERE_PDF);
}

// Where a ray from `p` along unit `dir` meets light `i`'s surface before
// `t_max`: radiance (xyz) and the density with which sample_light at `p`
// draws `dir` (w; 0 where it meets none: lights at infinity, points, a
// miss). A camera ray (`camera`) meets only lights the camera sees
// (path_flight.rs, next_surface).
fn hit_light(i: u32, p: vec3<f32>, dir: vec3<f32>, t_max: f32, camera: bool) -> vec4<f32> {
    let l = lights[i];
    if camera && l.tag.y == 0u {
        return vec4<f32>(0.0);
    }
    if l.tag.x == LIGHT_SPHERE {
        return hit_sphere_light(l, p, dir, t_max);
    }
    if l.tag.x == LIGHT_AREA {
        return hit_area_light(l, p, dir, t_max);
    }
    return vec4<f32>(0.0);
}
