//! The ray marchers converge to the path tracer's single scattering
//! (`max_depth = 1`) as the step (and the two-pass light grid) shrink.

mod common;

use cirrus_render::{render, GridField, Image, IntegratorKind, Lights, Scene, Volumes};
use glam::Vec3;

/// Squared bias of `a` against the reference `b` in one channel, corrected
/// for noise: `B = mean over pixels of (a - b)^2 - se_a^2 - se_b^2`, an
/// unbiased estimate of the mean squared bias, with the standard deviation
/// of its noise part, `s = sqrt(sum of 2 (se_a^2 + se_b^2)^2) / N` (for a
/// Gaussian difference d of variance v, Var(d^2) = 2 v^2).
fn squared_bias(a: &Image, b: &Image) -> (f64, f64) {
    let d = common::differences(a, b, 1);
    let n = (a.width * a.height) as f64;
    let excess = d
        .diff
        .iter()
        .zip(&d.var)
        .map(|(x, v)| x * x - v)
        .sum::<f64>()
        / n;
    let noise = d.var.iter().map(|v| 2.0 * v * v).sum::<f64>().sqrt() / n;
    (excess, noise)
}

fn scene() -> Scene<Volumes<GridField>> {
    // Dense enough (peak optical depth ~12) that coarse steps are visibly
    // wrong; a delta sun and a sky, so both shadow-ray kinds are exercised.
    let lights = Lights::sun_and_sky(common::sun(0.0), common::env(Vec3::new(0.2, 0.3, 0.45)));
    common::scene(
        common::medium(common::cloud_field(4), 20.0, 0.9, 0.3),
        16,
        lights,
    )
}

#[test]
fn ray_marchers_converge_to_single_scattering() {
    let scene = scene();
    let mut path = common::settings(IntegratorKind::Path, 512, 1);
    path.max_depth = Some(1);
    let reference = render(&scene, &path).image;
    let signal =
        reference.rgba.iter().map(|p| p[1] as f64).sum::<f64>() / reference.rgba.len() as f64;

    for kind in [IntegratorKind::RayMarch, IntegratorKind::RayMarch2Pass] {
        let march = |step: f32| {
            let mut s = common::settings(kind, 16, 2);
            s.step_voxels = step;
            s.light_grid.cell_voxels = step;
            s.light_grid.env_directions = 32;
            render(&scene, &s).image
        };
        let (coarse, s_coarse) = squared_bias(&march(8.0), &reference);
        let (fine, s_fine) = squared_bias(&march(1.0), &reference);
        eprintln!(
            "{kind:?}: rms bias {:.5} at 8 voxels, {:.5} at 1 voxel (noise sd of B: {s_coarse:.2e}, {s_fine:.2e}); mean signal {signal:.4}",
            coarse.max(0.0).sqrt(),
            fine.max(0.0).sqrt()
        );
        // The smaller step is closer, by more than 4 noise standard
        // deviations of the difference (measured margin: > 10).
        let improvement_noise = (s_coarse * s_coarse + s_fine * s_fine).sqrt();
        assert!(
            coarse - fine > 4.0 * improvement_noise,
            "{kind:?}: B {coarse:.3e} -> {fine:.3e}"
        );
        // And at one voxel the rms bias is under 2% of the mean signal,
        // allowing 4 noise standard deviations of B (measured: ~1%).
        let bound = (0.02 * signal).powi(2) + 4.0 * s_fine;
        assert!(
            fine <= bound,
            "{kind:?}: B at 1 voxel {fine:.3e} > {bound:.3e}"
        );
    }
}

#[test]
fn light_grid_stores_only_bricks_near_density() {
    use cirrus_kernel::LightGrid;
    use cirrus_render::{Counters, LightGridSettings};
    // 64^3 voxels with density only in a 6^3 corner: at one voxel per cell
    // the lattice has 9^3 bricks, of which the corner touches a few.
    let field = GridField::from_fn([64, 64, 64], Vec3::ZERO, 1.0 / 64.0, 8, |i, j, k| {
        if i < 6 && j < 6 && k < 6 {
            1.0
        } else {
            0.0
        }
    });
    let medium = Volumes::from(common::medium(field, 10.0, 0.9, 0.0));
    let lights = Lights::sun_and_sky(common::sun(0.0), None);
    let settings = LightGridSettings {
        cell_voxels: 1.0,
        env_directions: 1,
    };
    let mut c = Counters::default();
    let grid = LightGrid::build(&medium, &lights, 1.0, &settings, 0, &mut c);
    assert_eq!(grid.total_bricks(), 9 * 9 * 9);
    assert!(
        grid.stored_bricks() >= 1 && grid.stored_bricks() <= 8,
        "{} bricks stored",
        grid.stored_bricks()
    );
}

/// A shadow step three times the step (vdb_render's default ratio) takes
/// about a third of the shadow lookups, and its image stays within a small
/// bias of the fine one: the jittered march estimates each shadow ray's
/// optical depth without bias, and only `exp` of a noisier estimate
/// (Jensen) moves the mean.
#[test]
fn a_coarser_shadow_step_cuts_lookups_not_the_image() {
    let scene = scene();
    let march = |shadow: Option<f32>| {
        let mut s = common::settings(IntegratorKind::RayMarch, 64, 3);
        s.step_voxels = 1.0;
        s.shadow_step_voxels = shadow;
        render(&scene, &s)
    };
    let fine = march(None);
    let coarse = march(Some(3.0));
    let (lf, lc) = (
        fine.stats.counters.density_lookups as f64,
        coarse.stats.counters.density_lookups as f64,
    );
    let mean = |i: &Image| i.rgba.iter().map(|p| p[1] as f64).sum::<f64>() / i.rgba.len() as f64;
    let (mf, mc) = (mean(&fine.image), mean(&coarse.image));
    eprintln!(
        "lookups {lc} vs {lf} ({:.3}); image mean {mc:.5} vs {mf:.5}",
        lc / lf
    );
    assert!(lc < 0.5 * lf, "lookups {lc} vs {lf}");
    assert!((mc / mf - 1.0).abs() < 0.03, "image mean {mc} vs {mf}");
}
