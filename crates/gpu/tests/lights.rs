//! The GPU's lights against the CPU's: sphere, point and spot lights
//! (balls sampled by the cone they subtend, points as deltas, spots'
//! cones with soft edges, soft falloff's facing discs), met by camera and
//! scattered rays and sampled at every vertex, agree with a CPU render
//! block by block (`common::agrees_with_cpu`). Small images, a few
//! seconds each on lavapipe.

mod common;

use common::{agrees_with_cpu, block_mean, gpu, render_gpu, scene};

/// A camera-visible ball between the camera and the cloud, a large ball
/// sunk into the cloud's top (vertices inside it take every direction,
/// rays leaving it see it), a point light in the cloud and a spot light
/// with a softened edge above it, under a dim sky: the GPU's image is the
/// CPU's within their standard errors. (The cloud's box spans x 32..272,
/// y 24..144, z 24..176; the camera looks at it from +x +y +z.)
#[test]
fn gpu_agrees_with_cpu_under_sphere_point_and_spot_lights() {
    agrees_with_cpu(
        r#"
        [environment]
        radiance = [0.05, 0.05, 0.08]
        [[volume]]
        file = "cloud.vdb"
        density_scale = 0.05
        albedo = 0.9
        g = 0.4
        [[light]]
        type = "sphere"
        position = [330, 170, 330]
        radius = 6
        intensity = 2
        visible_to_camera = true
        [[light]]
        type = "sphere"
        position = [152, 160, 100]
        radius = 40
        intensity = 1.5
        color = [1.0, 0.8, 0.6]
        [[light]]
        type = "point"
        position = [60, 100, 100]
        intensity = 1e4
        [[light]]
        type = "spot"
        position = [200, 300, 100]
        direction = [-0.2, -1, 0]
        cone_angle = 25
        cone_softness = 0.5
        intensity = 5e4
        color = [0.6, 0.8, 1.0]
        "#,
    );
}

/// Soft falloff: a ball and a spot's ball light each point from the disc
/// through their centre facing it, sampled and met with its density;
/// paths of at most two events (the last vertex takes no MIS): the same
/// agreement.
#[test]
fn gpu_agrees_with_cpu_under_soft_falloff() {
    agrees_with_cpu(
        r#"        [render]
        max_depth = 2
        [environment]
        radiance = [0.01, 0.01, 0.01]
        [[volume]]
        file = "cloud.vdb"
        density_scale = 0.08
        albedo = 0.95
        g = 0.7
        [[light]]
        type = "sphere"
        position = [200, 120, 150]
        radius = 30
        intensity = 50
        soft_falloff = true
        [[light]]
        type = "spot"
        position = [150, 180, 120]
        direction = [0, -1, -0.2]
        cone_angle = 35
        cone_softness = 0.3
        radius = 10
        intensity = 1000
        soft_falloff = true
        "#,
    );
}

/// A ball of radiance 1 around the whole cloud (albedo 1), unseen by the
/// camera: every vertex lies inside it and sees radiance 1 along every
/// direction, part by next-event samples uniform over the sphere, part by
/// phase-sampled rays meeting the ball where they leave it, weighed by
/// MIS. A pixel's expectation is exactly its alpha (the odds its camera
/// ray collides): the image means of RGB and alpha agree within 4
/// standard errors.
#[test]
fn a_ball_around_the_cloud_is_a_white_furnace() {
    lit_furnace(
        r#"
        [[light]]
        type = "sphere"
        position = [152, 84, 100]
        radius = 200
        intensity = 1
        "#,
    );
}

/// Six rectangles facing in, radiance 1, closing a box around the cloud
/// (albedo 1): every direction from inside meets one, by next-event
/// samples over each one's area or by phase-sampled rays, weighed by
/// MIS; the camera, outside, sees their backs or none. The same furnace:
/// the image means of RGB and alpha agree within 4 standard errors.
#[test]
fn a_box_of_rectangles_around_the_cloud_is_a_white_furnace() {
    lit_furnace(
        r#"
        [[light]]
        type = "rect"
        position = [290, 85, 100]
        direction = [-1, 0, 0]
        width = 180
        height = 150
        intensity = 1
        [[light]]
        type = "rect"
        position = [20, 85, 100]
        direction = [1, 0, 0]
        width = 180
        height = 150
        intensity = 1
        [[light]]
        type = "rect"
        position = [155, 160, 100]
        direction = [0, -1, 0]
        width = 270
        height = 180
        intensity = 1
        [[light]]
        type = "rect"
        position = [155, 10, 100]
        direction = [0, 1, 0]
        width = 270
        height = 180
        intensity = 1
        [[light]]
        type = "rect"
        position = [155, 85, 190]
        direction = [0, 0, -1]
        width = 270
        height = 150
        intensity = 1
        [[light]]
        type = "rect"
        position = [155, 85, 10]
        direction = [0, 0, 1]
        width = 270
        height = 150
        intensity = 1
        "#,
    );
}

/// Renders the cloud (albedo 1, g 0.5) lit by the `lights` tables alone,
/// which enclose it with radiance 1 seen from everywhere inside, and
/// checks each channel's image mean is the alpha's within 4 standard
/// errors.
fn lit_furnace(lights: &str) {
    let Some(gpu) = gpu() else { return };
    let s = scene(&format!(
        r#"
        [render]
        spp = 64
        seed = 2
        [camera]
        res = "16x16"
        [[volume]]
        file = "cloud.vdb"
        density_scale = 0.5
        albedo = 1.0
        g = 0.5
        {lights}
        "#
    ));
    let image = render_gpu(&gpu, &s).expect("GPU render").image;
    let all = (0, 0, 16, 16);
    let (alpha, se_alpha) = block_mean(&image, 3, all);
    assert!(alpha > 0.15, "the cloud covers {alpha} of the image");
    for c in 0..3 {
        let (mean, se) = block_mean(&image, c, all);
        let se = (se * se + se_alpha * se_alpha).sqrt();
        eprintln!("lit furnace channel {c}: {mean} against alpha {alpha} +- {se}");
        assert!(se > 0.0);
        assert!(
            (mean - alpha).abs() < 4.0 * se,
            "channel {c}: image mean {mean} is {} standard errors ({se}) from alpha {alpha}",
            (mean - alpha) / se
        );
    }
}

/// A rectangle over the cloud facing down (the camera, above, sees its
/// back: nothing), an elliptical disc beside it and a cylinder's side
/// inside it, under a faint sky: the GPU's image is the CPU's within
/// their standard errors (the GPU samples the rectangle by area, the CPU
/// by the solid angle it subtends: the expectation is the same).
#[test]
fn gpu_agrees_with_cpu_under_area_lights() {
    agrees_with_cpu(
        r#"
        [environment]
        radiance = [0.01, 0.01, 0.01]
        [[volume]]
        file = "cloud.vdb"
        density_scale = 0.08
        albedo = 0.9
        g = 0.5
        [[light]]
        type = "rect"
        position = [160, 170, 110]
        direction = [0, -1, 0]
        width = 80
        height = 40
        intensity = 10
        visible_to_camera = true
        [[light]]
        type = "disk"
        position = [290, 90, 100]
        direction = [-1, 0, 0.2]
        width = 60
        height = 30
        intensity = 12
        color = [0.6, 0.8, 1.0]
        [[light]]
        type = "cylinder"
        position = [100, 80, 100]
        direction = [0, 0, 1]
        radius = 4
        length = 60
        intensity = 60
        color = [1.0, 0.7, 0.5]
        "#,
    );
}
