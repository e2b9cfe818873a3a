// Area lights: one-sided rectangles and discs (ellipses), and cylinders'
// sides emitting outward, of uniform radiance.
//
// Mirrors crates/kernel/src/light/area.rs (`AreaLight::sample`, `hit`,
// `on_cylinder`, `cylinder_hit`) with one difference: a rectangle is
// sampled uniformly over its area, as the CPU samples it from behind or
// where it subtends too little, never by the solid angle it subtends
// (spherical_rect.rs, in f64 there: in f32 its solid angle cancels
// badly for small rectangles). The density is then the area's, here and
// for rays meeting it, so the estimate is unbiased and only its noise
// differs from the CPU's near a rectangle. Record (flat.rs,
// LightRecord): tag.y camera-visible, tag.z the shape (AREA_*); dir =
// centre, area; radiance; shape[0..3] = half axes u and v, unit normal
// (a cylinder's axis).

const AREA_RECT: u32 = 0u;
const AREA_DISK: u32 = 1u;
const AREA_CYLINDER: u32 = 2u;

// A sample of area light `l` from `p`.
fn sample_area_light(l: LightRecord, p: vec3<f32>, u1: f32, u2: f32) -> LightSample {
    let centre = l.dir.xyz;
    let half_u = l.shape[0].xyz;
    let half_v = l.shape[1].xyz;
    var normal = l.shape[2].xyz;
    var q: vec3<f32>;
    if l.tag.z == AREA_CYLINDER {
        let radius = length(half_v);
        let e1 = half_v / radius;
        let e2 = cross(normal, e1);
        let phi = 2.0 * PI * u2;
        normal = cos(phi) * e1 + sin(phi) * e2;
        q = centre + (2.0 * u1 - 1.0) * half_u + radius * normal;
    } else if l.tag.z == AREA_DISK {
        let ab = concentric_disk(u1, u2);
        q = centre + ab.x * half_u + ab.y * half_v;
    } else {
        q = centre + (2.0 * u1 - 1.0) * half_u + (2.0 * u2 - 1.0) * half_v;
    }
    let to = q - p;
    let d2 = dot(to, to);
    let d = sqrt(d2);
    let dir = to / d;
    let cos_l = -dot(dir, normal);
    if !(cos_l > 0.0 && d > 0.0) {
        return LightSample(dir, vec3<f32>(0.0), 0.0, 0.0);
    }
    return LightSample(dir, l.radiance.xyz, d2 / (l.dir.w * cos_l), d);
}

// Where a ray from `p` along unit `dir` meets a cylinder's side from
// outside before `t_max`: (t, cosine to the side's normal); t < 0 for a
// miss (area.rs, cylinder_hit).
fn cylinder_hit(l: LightRecord, p: vec3<f32>, dir: vec3<f32>, t_max: f32) -> vec2<f32> {
    let axis = l.shape[2].xyz;
    let radius = length(l.shape[1].xyz);
    let o = p - l.dir.xyz;
    let oa = dot(o, axis);
    let da = dot(dir, axis);
    let op = o - oa * axis;
    let dp = dir - da * axis;
    let a = dot(dp, dp);
    let b = dot(op, dp);
    let c = dot(op, op) - radius * radius;
    let disc = b * b - a * c;
    if !(a > 0.0 && c > 0.0 && disc > 0.0) {
        return vec2<f32>(-1.0);
    }
    let t = (-b - sqrt(disc)) / a;
    let in_length = abs(oa + t * da) <= length(l.shape[0].xyz);
    if t > 0.0 && t < t_max && in_length {
        return vec2<f32>(t, sqrt(disc) / radius);
    }
    return vec2<f32>(-1.0);
}

// Where a ray from `p` along unit `dir` meets area light `l` before
// `t_max`: radiance (xyz) and the density with which sample_area_light
// at `p` draws `dir` (w; 0 for a miss or its back).
fn hit_area_light(l: LightRecord, p: vec3<f32>, dir: vec3<f32>, t_max: f32) -> vec4<f32> {
    let area = l.dir.w;
    if l.tag.z == AREA_CYLINDER {
        let h = cylinder_hit(l, p, dir, t_max);
        if h.x < 0.0 {
            return vec4<f32>(0.0);
        }
        return vec4<f32>(l.radiance.xyz, h.x * h.x / (area * h.y));
    }
    let normal = l.shape[2].xyz;
    let cos_l = -dot(dir, normal);
    if cos_l <= 0.0 {
        return vec4<f32>(0.0);
    }
    let t = dot(p - l.dir.xyz, normal) / cos_l;
    if !(t > 0.0 && t < t_max) {
        return vec4<f32>(0.0);
    }
    let r = p + t * dir - l.dir.xyz;
    let half_u = l.shape[0].xyz;
    let half_v = l.shape[1].xyz;
    let a = dot(r, half_u) / dot(half_u, half_u);
    let b = dot(r, half_v) / dot(half_v, half_v);
    var inside = a * a + b * b <= 1.0;
    if l.tag.z == AREA_RECT {
        inside = abs(a) <= 1.0 && abs(b) <= 1.0;
    }
    if !inside {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(l.radiance.xyz, t * t / (area * cos_l));
}
