// Sphere lights: a ball of uniform radiance, a point (radius 0), either
// shaped by a spot cone, or lighting a point from the disc through its
// centre facing it (soft falloff).
//
// Mirrors crates/kernel/src/light/sphere.rs (`SphereLight::sample`,
// `hit`, `cone`, `hit_distance`, `exit_distance`, `Spot::falloff`) and
// facing_disk.rs (`FacingDisk::sample`, `hit`), area.rs's
// `concentric_disk`. Record (flat.rs, LightRecord): tag.y camera-visible,
// tag.z soft falloff; dir = centre, radius; radiance = the surface's
// radiance I / (pi r^2), or a point's intensity I; shape[0] = the spot's
// axis, cos of its outer angle (-2 without a spot); shape[1].x = cos of
// its inner angle.

// The spot's fraction of the light sent along unit `dir` from the light.
fn spot_falloff(l: LightRecord, dir: vec3<f32>) -> f32 {
    let cos_outer = l.shape[0].w;
    let cos_inner = l.shape[1].x;
    let c = dot(l.shape[0].xyz, dir);
    if c <= cos_outer {
        return 0.0;
    }
    if c >= cos_inner {
        return 1.0;
    }
    let t = (c - cos_outer) / (cos_inner - cos_outer);
    return t * t * (3.0 - 2.0 * t);
}

// `1 - cos theta_max` of the cone the ball subtends at squared distance
// `d2`; negative from inside the ball.
fn ball_cone(radius: f32, d2: f32) -> f32 {
    let r2 = radius * radius;
    if d2 <= r2 {
        return -1.0;
    }
    let sin2 = r2 / d2;
    return sin2 / (1.0 + sqrt(1.0 - sin2));
}

// The near root from outside the ball along unit `dir` (negative: a miss).
fn ball_hit_distance(radius: f32, to_centre: vec3<f32>, dir: vec3<f32>) -> f32 {
    let b = dot(to_centre, dir);
    let perp = to_centre - b * dir;
    let h2 = radius * radius - dot(perp, perp);
    if b > 0.0 && h2 >= 0.0 {
        return max(b - sqrt(h2), 0.0);
    }
    return -1.0;
}

// The far root from inside the ball: where the ray leaves it.
fn ball_exit_distance(radius: f32, to_centre: vec3<f32>, dir: vec3<f32>) -> f32 {
    let b = dot(to_centre, dir);
    let perp = to_centre - b * dir;
    return b + sqrt(max(radius * radius - dot(perp, perp), 0.0));
}

fn concentric_disk(u1: f32, u2: f32) -> vec2<f32> {
    let a = 2.0 * u1 - 1.0;
    let b = 2.0 * u2 - 1.0;
    if a == 0.0 && b == 0.0 {
        return vec2<f32>(0.0);
    }
    var r = b;
    var theta = 0.5 * PI - 0.25 * PI * (a / b);
    if abs(a) > abs(b) {
        r = a;
        theta = 0.25 * PI * (b / a);
    }
    return r * vec2<f32>(cos(theta), sin(theta));
}

// The unit normal of the disc through the light's centre facing `p`.
fn facing_normal(p: vec3<f32>, centre: vec3<f32>) -> vec3<f32> {
    let n = p - centre;
    let len2 = dot(n, n);
    if len2 > 0.0 && len2 < FAR {
        return n / sqrt(len2);
    }
    return vec3<f32>(0.0, 0.0, 1.0);
}

// The soft-falloff disc's density per solid angle at distance t, cosine cos.
fn facing_pdf(radius: f32, t: f32, cos_l: f32) -> f32 {
    return t * t / (PI * radius * radius * cos_l);
}

// A sample of sphere light `l` from `p` (sphere.rs, SphereLight::sample).
fn sample_sphere_light(l: LightRecord, p: vec3<f32>, u1: f32, u2: f32) -> LightSample {
    let centre = l.dir.xyz;
    let radius = l.dir.w;
    let to_centre = centre - p;
    let d2 = dot(to_centre, to_centre);
    let d = sqrt(d2);
    let axis = to_centre / d;
    if radius <= 0.0 {
        return LightSample(axis, l.radiance.xyz * (spot_falloff(l, -axis) / d2), -1.0, d);
    }
    if l.tag.z != 0u {
        let n = facing_normal(p, centre);
        let ab = concentric_disk(u1, u2) * radius;
        let q = centre + tangent_point(n, ab.x, ab.y);
        let to = q - p;
        let dist = length(to);
        let dir = to / dist;
        let cos_l = -dot(dir, n);
        if !(cos_l > 0.0 && dist > 0.0) {
            return LightSample(axis, vec3<f32>(0.0), 0.0, 0.0);
        }
        return LightSample(dir, l.radiance.xyz * spot_falloff(l, -dir), facing_pdf(radius, dist, cos_l), dist);
    }
    let one_minus_cos = ball_cone(radius, d2);
    if one_minus_cos < 0.0 {
        let dir = uniform_sphere(u1, u2);
        return LightSample(dir, l.radiance.xyz, UNIFORM_SPHERE_PDF, ball_exit_distance(radius, to_centre, dir));
    }
    let dir = uniform_cone(axis, one_minus_cos, u1, u2);
    var distance = ball_hit_distance(radius, to_centre, dir);
    if distance < 0.0 {
        distance = d;
    }
    let pdf = 1.0 / (2.0 * PI * one_minus_cos);
    return LightSample(dir, l.radiance.xyz * spot_falloff(l, -dir), pdf, distance);
}

// Where a ray from `p` along unit `dir` meets sphere light `l` before
// `t_max` (sphere.rs, SphereLight::hit): radiance (xyz) and the density
// with which sample_sphere_light at `p` draws `dir` (w); w = 0 for a miss
// or a point.
fn hit_sphere_light(l: LightRecord, p: vec3<f32>, dir: vec3<f32>, t_max: f32) -> vec4<f32> {
    let centre = l.dir.xyz;
    let radius = l.dir.w;
    if radius <= 0.0 {
        return vec4<f32>(0.0);
    }
    if l.tag.z != 0u {
        let n = facing_normal(p, centre);
        let height = dot(p - centre, n);
        let cos_l = -dot(dir, n);
        if !(height > 0.0 && cos_l > 0.0) {
            return vec4<f32>(0.0);
        }
        let t = height / cos_l;
        let off = p + t * dir - centre;
        if !(dot(off, off) < radius * radius && t < t_max) {
            return vec4<f32>(0.0);
        }
        return vec4<f32>(l.radiance.xyz * spot_falloff(l, -dir), facing_pdf(radius, t, cos_l));
    }
    let to_centre = centre - p;
    let one_minus_cos = ball_cone(radius, dot(to_centre, to_centre));
    if one_minus_cos < 0.0 {
        if ball_exit_distance(radius, to_centre, dir) < t_max {
            return vec4<f32>(l.radiance.xyz, UNIFORM_SPHERE_PDF);
        }
        return vec4<f32>(0.0);
    }
    let t = ball_hit_distance(radius, to_centre, dir);
    if t < 0.0 || !(t < t_max) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(l.radiance.xyz * spot_falloff(l, -dir), 1.0 / (2.0 * PI * one_minus_cos));
}
