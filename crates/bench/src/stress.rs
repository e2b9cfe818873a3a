//! `cirrus bench stress`: numerical stability under extreme inputs.
//!
//! Every case renders a tiny image of a synthetic volume and must give
//! finite pixels, a bounded number of collisions per path (the trackers'
//! hard cap counts and reports when it is hit), and, where an answer is
//! known in closed form, that answer within its statistical bound.
//!
//! The analytic case is a constant box of density 1 over voxels
//! `[0, N-1]^3`, seen through its centre by a pixel whose rays are all
//! nearly parallel to an axis, with albedo 0, a unit environment and no
//! sun: the pixel is the transmittance exp(-tau), where trilinear
//! interpolation makes the chord's integral exactly N voxels (density 1
//! over N - 1 voxels plus two half-voxel ramps), so tau = scale x N x
//! voxel size. Its estimator (delta tracking, escape or not) is Bernoulli,
//! so the bound is 5 standard errors sqrt(T (1 - T) / spp) plus the chord
//! error of rays up to half a pixel off axis.
//!
//! Density policy under test: NaN, infinite and negative voxels are stored
//! as 0 and counted (`SourceInfo::sanitized_voxels`).

use crate::BenchResult;
use cirrus_bricks::{convert, BrickVolume, Precision};
use cirrus_kernel::medium::BrickField;
use cirrus_render::{
    render, Budget, Camera, Environment, Lights, Medium, RenderSettings, RenderStats, Scene, Sun,
    TransmittanceEstimator, Volumes,
};
use cirrus_vdb::{Coord, Grid, GridClass, GridTree, MapKind, Transform, Tree};
use glam::{DMat4, DVec3, Vec3};

/// Side of the constant box in voxels.
const N: i32 = 16;
/// Image side; odd so the centre pixel looks through the box's centre.
const RES: u32 = 9;
/// Samples per pixel where an answer strictly between 0 and 1 is checked:
/// a 5-sigma Bernoulli bound of at most 5 sqrt(0.25 / 4096) = 0.039.
const SPP_ANALYTIC: u32 = 4096;
/// Elsewhere: enough to exercise every code path.
const SPP: u32 = 64;

#[derive(clap::Args)]
pub struct StressArgs {
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The outcome of one case.
#[derive(Debug, serde::Serialize)]
pub struct CaseResult {
    pub name: String,
    pub finite: bool,
    pub collision_cap_hits: u64,
    pub max_collisions_per_path: f64,
    /// (measured, expected, bound) for the centre pixel, when known.
    pub analytic: Option<(f64, f64, f64)>,
    pub sanitized_voxels: u64,
    pub passed: bool,
}

/// A grid of `voxels` (index coordinates and values) with the given voxel
/// size and translation.
fn grid(voxels: impl IntoIterator<Item = ([i32; 3], f32)>, voxel: f64, translate: DVec3) -> Grid {
    let mut tree = Tree::new(0.0f32);
    for (c, v) in voxels {
        tree.set_value_on(Coord::new(c[0], c[1], c[2]), v);
    }
    Grid {
        name: "density".into(),
        class: GridClass::FogVolume,
        transform: Transform::scale_translate(
            MapKind::ScaleTranslate,
            DVec3::splat(voxel),
            translate,
        )
        .expect("valid transform"),
        metadata: Vec::new(),
        tree: GridTree::Float(tree),
        half_float: false,
    }
}

fn cube(n: i32, value: f32) -> impl Iterator<Item = ([i32; 3], f32)> {
    (0..n).flat_map(move |x| (0..n).flat_map(move |y| (0..n).map(move |z| ([x, y, z], value))))
}

/// What a case renders: the volume, where the camera is (in voxels,
/// relative to the box), the scale, lights and estimator.
struct Case {
    name: String,
    grid: Grid,
    /// Camera position and target in index space (voxels).
    from: Vec3,
    to: Vec3,
    fov: f32,
    /// Extinction per density per world unit.
    scale: f32,
    sun: bool,
    transmittance: TransmittanceEstimator,
    /// Expected centre-pixel transmittance.
    expected: Option<f64>,
    spp: u32,
}

fn cases() -> Vec<Case> {
    let mut v = closed_form_cases();
    v.extend(hard_input_cases());
    v
}

/// A uniform cube seen head on, its transmittance in closed form, at
/// extreme density scales, voxel sizes and distances from the origin.
fn closed_form_cases() -> Vec<Case> {
    let centre = Vec3::splat((N - 1) as f32 / 2.0);
    let front = centre - Vec3::Z * 200.0;
    let analytic = |name: String, voxel: f64, translate: DVec3, scale: f32| {
        let tau = scale as f64 * N as f64 * voxel;
        Case {
            name,
            grid: grid(cube(N, 1.0), voxel, translate),
            from: front,
            to: centre,
            fov: 1.0,
            scale,
            sun: false,
            transmittance: TransmittanceEstimator::Ratio,
            expected: Some((-tau).exp()),
            spp: if tau > 1e-9 && tau < 30.0 {
                SPP_ANALYTIC
            } else {
                SPP
            },
        }
    };
    let mut v = Vec::new();
    for s in [1e-6f32, 1e-3, 1.0 / N as f32, 1.0, 1e3, 1e6] {
        v.push(analytic(
            format!("density scale {s:e}"),
            1.0,
            DVec3::ZERO,
            s,
        ));
    }
    for vs in [1e-4f64, 1e-2, 1e2, 1e4] {
        // Optical depth 1 whatever the voxel size.
        v.push(analytic(
            format!("voxel size {vs:e}"),
            vs,
            DVec3::ZERO,
            (1.0 / (N as f64 * vs)) as f32,
        ));
    }
    v.push(analytic(
        "volume 1e6 units from the origin".into(),
        1.0,
        DVec3::new(1e6, -1e6, 1e6),
        1.0 / N as f32,
    ));
    v.push(analytic(
        "voxel 1e-3 at 1e6 units".into(),
        1e-3,
        DVec3::splat(1e6),
        1.0 / (N as f32 * 1e-3),
    ));
    v
}

/// A case under the sun with no closed form: it must render finite pixels.
fn plain_case(name: &str, grid: Grid, from: Vec3, to: Vec3, scale: f32) -> Case {
    Case {
        name: name.into(),
        grid,
        from,
        to,
        fov: 60.0,
        scale,
        sun: true,
        transmittance: TransmittanceEstimator::Ratio,
        expected: None,
        spp: SPP,
    }
}

/// Rays along faces, edges and corners, cameras inside the volume, a
/// single voxel; then bad voxel values and extreme optical depth.
fn hard_input_cases() -> Vec<Case> {
    let centre = Vec3::splat((N - 1) as f32 / 2.0);
    let plain = plain_case;
    let mut v = Vec::new();
    // Rays along faces, edges and corners: the camera sits on the box's face
    // planes (voxel centres at 0 and N-1, support edges at -1 and N).
    for (k, from) in [
        Vec3::new(-1.0, -1.0, -100.0),
        Vec3::new(-0.5, 7.5, -100.0),
        Vec3::new(N as f32, N as f32, -100.0),
    ]
    .into_iter()
    .enumerate()
    {
        v.push(plain(
            &format!("grazing rays {k}"),
            grid(cube(N, 1.0), 1.0, DVec3::ZERO),
            from,
            from + Vec3::Z,
            1.0,
        ));
    }
    v.push(plain(
        "axis-parallel rays",
        grid(cube(N, 1.0), 1.0, DVec3::ZERO),
        centre - Vec3::X * 100.0,
        centre,
        1.0,
    ));
    v.push(plain(
        "camera inside the volume",
        grid(cube(N, 0.5), 1.0, DVec3::ZERO),
        centre,
        centre + Vec3::ONE,
        0.5,
    ));
    let shell = cube(3 * N, 1.0).filter(|(c, _)| c.iter().any(|&x| !(N..2 * N).contains(&x)));
    v.push(plain(
        "camera in an empty region inside the volume",
        grid(shell, 1.0, DVec3::ZERO),
        Vec3::splat(1.5 * N as f32),
        Vec3::splat(2.0 * N as f32),
        0.2,
    ));
    v.push(plain(
        "single voxel",
        grid([([0, 0, 0], 5.0)], 1.0, DVec3::ZERO),
        Vec3::new(0.0, 0.0, -10.0),
        Vec3::ZERO,
        1.0,
    ));
    v.extend(hard_value_cases());
    v
}

/// NaN, infinite and negative voxels, optical depth 1e5 under each
/// shadow estimator, an all-zero volume.
fn hard_value_cases() -> Vec<Case> {
    let centre = Vec3::splat((N - 1) as f32 / 2.0);
    let front = centre - Vec3::Z * 200.0;
    let plain = plain_case;
    let mut v = Vec::new();
    let special = cube(N, 1.0).map(|(c, v)| {
        let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -3.0];
        (
            c,
            if (c[0] + c[1] + c[2]) % 5 == 0 {
                bad[(c[0] as usize) % 4]
            } else {
                v
            },
        )
    });
    v.push(plain(
        "NaN, inf and negative voxels",
        grid(special, 1.0, DVec3::ZERO),
        front,
        centre,
        1.0,
    ));
    for (t, tn) in [
        (TransmittanceEstimator::Ratio, "ratio"),
        (TransmittanceEstimator::Residual, "residual"),
        (TransmittanceEstimator::TrackLength, "track-length"),
    ] {
        // Optical depth 1e5 through the box: exp() underflows in f32 past 87 or so.
        let mut c = plain(
            &format!("optical depth 1e5, {tn} shadows"),
            grid(cube(N, 1.0), 1.0, DVec3::ZERO),
            front,
            centre,
            1e4,
        );
        c.transmittance = t;
        v.push(c);
    }
    let mut zero = plain(
        "all-zero volume",
        grid(cube(N, 0.0), 1.0, DVec3::ZERO),
        front,
        centre,
        1.0,
    );
    zero.expected = Some(1.0);
    zero.sun = false;
    v.push(zero);
    v
}

fn run_case(case: &Case) -> Result<(CaseResult, RenderStats), Box<dyn std::error::Error>> {
    let volume: BrickVolume = convert(&case.grid, Precision::F32)?;
    let to_world = |p: Vec3| case.grid.transform.index_to_world(p.as_dvec3());
    let centre = to_world(Vec3::splat((N - 1) as f32 / 2.0));
    let field = BrickField::new(&volume, DMat4::IDENTITY, centre).with_refinement(case.scale, 1.0);
    let (from, to) = (
        (to_world(case.from) - centre).as_vec3(),
        (to_world(case.to) - centre).as_vec3(),
    );
    let camera = Camera::new(
        from,
        to,
        if (to - from).normalize().y.abs() > 0.9 {
            Vec3::Z
        } else {
            Vec3::Y
        },
        case.fov,
        RES,
        RES,
    );
    let lights = Lights::sun_and_sky(
        case.sun
            .then(|| Sun::new(Vec3::new(0.3, -0.8, 0.5), Vec3::splat(3.0), 0.0)),
        Some(Environment::new(Vec3::ONE)),
    );
    let albedo = if case.expected.is_some() { 0.0 } else { 0.8 };
    let scene = Scene {
        media: Volumes::from(Medium::new(field, case.scale, Vec3::splat(albedo), 0.5)),
        camera,
        lights,
    };
    let settings = RenderSettings {
        budget: Budget::Spp(case.spp),
        transmittance: case.transmittance,
        seed: 7,
        progress: false,
        ..Default::default()
    };
    let r = render(&scene, &settings);
    let finite = r.image.rgba.iter().all(|p| p.iter().all(|c| c.is_finite()));
    let s = r.stats.clone();
    let collisions = (s.counters.real_collisions
        + s.counters.null_collisions
        + s.counters.shadow_collisions) as f64
        / s.counters.paths.max(1) as f64;
    let analytic = case.expected.map(|t| {
        let c = RES / 2;
        let measured = r.image.pixel(c, c)[0] as f64;
        // Rays up to half a pixel diagonal off axis cross a chord longer by
        // 1/cos(theta): their transmittance is T^(1/cos), lower by at most
        // T (1 - T^(1/cos - 1)).
        let theta = (case.fov as f64).to_radians() / RES as f64 / 2.0 * std::f64::consts::SQRT_2;
        let chord = t * (1.0 - t.powf(1.0 / theta.cos() - 1.0));
        let bound = 5.0 * (t * (1.0 - t) / case.spp as f64).sqrt() + chord + 1e-6;
        (measured, t, bound)
    });
    let passed = finite
        && s.counters.collision_cap_hits == 0
        && analytic.is_none_or(|(m, t, b)| (m - t).abs() <= b);
    Ok((
        CaseResult {
            name: case.name.clone(),
            finite,
            collision_cap_hits: s.counters.collision_cap_hits,
            max_collisions_per_path: collisions,
            analytic,
            sanitized_voxels: volume.info.sanitized_voxels,
            passed,
        },
        s,
    ))
}

pub fn run(args: &StressArgs) -> BenchResult {
    let mut results = Vec::new();
    for case in cases() {
        let start = std::time::Instant::now();
        let (r, _) = run_case(&case)?;
        if !args.json {
            eprintln!("{:<46} {:.2} s", r.name, start.elapsed().as_secs_f64());
        }
        results.push(r);
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&results)?);
    } else {
        println!(
            "{:<46} {:>7} {:>9} {:>12} {:>34}",
            "case",
            "finite",
            "cap hits",
            "coll./path",
            "centre pixel (measured / expected ± bound)"
        );
        for r in &results {
            let a = r.analytic.map_or(String::from("-"), |(m, t, b)| {
                format!("{m:.6} / {t:.6} ± {b:.6}")
            });
            println!(
                "{:<46} {:>7} {:>9} {:>12.2} {:>34} {}",
                r.name,
                r.finite,
                r.collision_cap_hits,
                r.max_collisions_per_path,
                a,
                if r.passed { "ok" } else { "FAILED" }
            );
        }
    }
    let failed: Vec<&str> = results
        .iter()
        .filter(|r| !r.passed)
        .map(|r| r.name.as_str())
        .collect();
    if failed.is_empty() {
        Ok(())
    } else {
        Err(format!("stress cases failed: {}", failed.join(", ")).into())
    }
}
