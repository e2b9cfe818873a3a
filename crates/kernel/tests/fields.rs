//! The test fields: GridField's DDA and bounds, ConstantBox; GlobalMedia's one segment.

use cirrus_kernel::Bounds3;
use cirrus_kernel::{ConstantBox, DensityField, GlobalMedia, MajorantSegment, Media, Medium};
use cirrus_kernel::{GridField, Rng};
use glam::Vec3;

/// Relative slack for `minorant <= density <= majorant`: the trilinear lerp
/// `a + t (b - a)` may round one ulp past its end points.
const LERP_SLACK: f32 = 1e-6;

fn random_dir(rng: &mut Rng) -> Vec3 {
    cirrus_kernel::sampling::uniform_sphere(rng.uniform(), rng.uniform())
}

/// Rays of every kind: from outside through the field, from inside, along
/// axes (zero direction components), unnormalised, with finite and
/// infinite `t_max` and positive `t_min`.
fn test_rays(lo: Vec3, hi: Vec3, n: usize) -> Vec<(Vec3, Vec3, f32, f32)> {
    let mut rng = Rng::new(5, 0, 0);
    let centre = 0.5 * (lo + hi);
    let size = hi - lo;
    let mut rays = Vec::new();
    for i in 0..n {
        let inside = lo + size * Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        let (origin, mut dir) = match i % 4 {
            0 | 1 => {
                let o = centre + 2.0 * size.length() * random_dir(&mut rng);
                (o, inside - o)
            }
            2 => (inside, random_dir(&mut rng)),
            _ => {
                let mut d = Vec3::ZERO;
                d[i % 3] = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
                (inside - 3.0 * d * size.length(), d)
            }
        };
        dir *= 0.5 + 2.0 * rng.uniform(); // t is in units of dir
        let t_min = if i % 5 == 0 { rng.uniform() } else { 0.0 };
        let t_max = if i % 3 == 0 {
            t_min + 5.0 * rng.uniform()
        } else {
            f32::INFINITY
        };
        rays.push((origin, dir, t_min, t_max));
    }
    rays
}

fn check_segments<F: DensityField>(field: &F, contiguous: bool) {
    let Bounds3 { min: lo, max: hi } = field.bounds();
    let mut rng = Rng::new(9, 0, 0);
    let mut checked_points = 0;
    for (o, d, t_min, t_max) in test_rays(lo, hi, 400) {
        let segs: Vec<MajorantSegment> = field.segments(o, d, t_min, t_max).collect();
        let overlap = Bounds3::new(lo, hi)
            .clip_ray(o, d, t_min, t_max)
            .filter(|(a, b)| b > a);
        let Some((enter, exit)) = overlap else {
            assert!(segs.is_empty(), "segments for a ray that misses");
            continue;
        };
        // Ordered, disjoint, inside the overlap, bounds ordered.
        let eps = 1e-5 * (1.0 + exit.abs().min(1e6));
        for s in &segs {
            assert!(s.t0 < s.t1 && s.minorant <= s.majorant, "{s:?}");
            assert!(
                s.t0 >= enter - eps && s.t1 <= exit + eps,
                "{s:?} outside [{enter}, {exit}]"
            );
        }
        for w in segs.windows(2) {
            assert!(w[0].t1 <= w[1].t0, "overlap {w:?}");
            if contiguous {
                assert_eq!(w[0].t1, w[1].t0, "gap");
            }
        }
        if contiguous && exit.is_finite() {
            // Covering: the union is the whole overlap.
            assert!(
                (segs[0].t0 - enter).abs() <= eps && (segs.last().unwrap().t1 - exit).abs() <= eps
            );
        }
        // Random points of the overlap: inside a segment the density lies
        // within its bounds; outside every segment it is zero.
        let span_end = if exit.is_finite() { exit } else { enter + 10.0 };
        for _ in 0..32 {
            let t = enter + (span_end - enter) * rng.uniform();
            let rho = field.density(o + t * d);
            match segs.iter().find(|s| s.t0 <= t && t < s.t1) {
                Some(s) => {
                    let slack = LERP_SLACK * s.majorant.abs().max(1.0);
                    assert!(
                        rho >= s.minorant - slack && rho <= s.majorant + slack,
                        "{rho} not in {s:?}"
                    );
                }
                None => assert_eq!(rho, 0.0, "density {rho} at t = {t} outside every segment"),
            }
            checked_points += 1;
        }
    }
    assert!(checked_points > 5000);
}

#[test]
fn grid_field_dda_segments_are_ordered_disjoint_covering_and_bounding() {
    for cell_voxels in [1, 3, 4, 16] {
        check_segments(&GridField::cloud(cell_voxels, Vec3::ZERO), true);
    }
}

#[test]
fn grid_field_interpolates_its_voxels() {
    let f = GridField::cloud(4, Vec3::ZERO);
    let vs = f.voxel_size();
    let origin = Vec3::splat(0.5 * vs);
    // At voxel sample positions the density is the voxel; between two it is
    // the average; outside the bounds it is 0.
    let p = |i: f32, j: f32, k: f32| origin + vs * Vec3::new(i, j, k);
    let (a, b) = (f.density(p(8.0, 7.0, 9.0)), f.density(p(9.0, 7.0, 9.0)));
    assert!(a > 0.0 && b > 0.0);
    assert!((f.density(p(8.5, 7.0, 9.0)) - 0.5 * (a + b)).abs() <= 1e-6);
    let Bounds3 { min: lo, max: hi } = f.bounds();
    assert_eq!(f.density(lo - 0.01), 0.0);
    assert_eq!(f.density(hi + 0.01), 0.0);
    assert_eq!(f.density(Vec3::NAN), 0.0);
    // The global majorant bounds every voxel.
    let mut rng = Rng::new(1, 1, 1);
    for _ in 0..10_000 {
        let q = lo + (hi - lo) * Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        assert!(f.density(q) <= f.global_majorant() * (1.0 + LERP_SLACK));
    }
}

#[test]
fn constant_box_has_one_exact_segment() {
    let b = ConstantBox::new(Vec3::splat(-0.5), Vec3::splat(0.5), 2.0, 0.1);
    check_segments(&b, true);
    let segs: Vec<_> = b
        .segments(Vec3::new(-2.0, 0.1, 0.2), Vec3::X, 0.0, f32::INFINITY)
        .collect();
    assert_eq!(segs.len(), 1);
    let s = segs[0];
    assert_eq!((s.t0, s.t1, s.minorant, s.majorant), (1.5, 2.5, 2.0, 2.0));
}

#[test]
fn global_media_collapse_to_one_segment() {
    let f = GridField::cloud(4, Vec3::ZERO);
    let max = f.global_majorant();
    let Bounds3 { min: lo, max: hi } = f.bounds();
    let medium = cirrus_kernel::Volumes::from(Medium::new(f, 2.0, Vec3::ONE, 0.0));
    let g = GlobalMedia::new(&medium);
    for (o, d, t_min, t_max) in test_rays(lo, hi, 100) {
        let segs: Vec<_> = g.majorants(o, d, t_min, t_max).collect();
        let overlap = Bounds3::new(lo, hi)
            .clip_ray(o, d, t_min, t_max)
            .filter(|(a, b)| b > a);
        assert_eq!(segs.len(), usize::from(overlap.is_some()));
        if let (Some(s), Some((t0, t1))) = (segs.first(), overlap) {
            assert_eq!((s.t0, s.t1), (t0, t1));
            assert_eq!((s.minorant, s.majorant), (0.0, 2.0 * max));
        }
    }
}
