//! A depth holdout against the same cut made in the density itself: the
//! corpus cloud (`data/cloud.vdb`, at half resolution) behind a plane
//! across the view, its depth image written as an EXR and read back as
//! `--holdout-depth` reads it.
//!
//! Single scattering under a sun behind the camera keeps the two
//! renders' light the same: every shadow ray travels toward the camera,
//! so it never meets the density the cut removed.

mod common;

use std::sync::Arc;

use cirrus_kernel::medium::{Bounds3, DensityField};
use cirrus_render::{
    render, Camera, DepthHoldout, GridField, IntegratorKind, Lights, Medium, Rendered, Scene, Sun,
};
use cirrus_vdb::{Coord, VolumeFile};
use glam::Vec3;

const SIZE: u32 = 32;

/// The corpus cloud's density, 2x2x2 voxels averaged, in index units.
fn corpus_cloud() -> GridField {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cloud.vdb");
    let file = VolumeFile::open(std::path::Path::new(path)).unwrap();
    let grid = file.read_grid(file.find_grid("density").unwrap()).unwrap();
    let bbox = grid.tree.active_bbox().unwrap();
    let (lo, hi) = (bbox.min.to_array(), bbox.max.to_array());
    let dims = [0, 1, 2].map(|a| ((hi[a] - lo[a] + 2) / 2) as usize);
    GridField::from_fn(dims, Vec3::ONE, 2.0, 4, |i, j, k| {
        let mut sum = 0.0;
        for d in 0..8 {
            let c = Coord::new(
                lo[0] + 2 * i as i32 + (d & 1),
                lo[1] + 2 * j as i32 + ((d >> 1) & 1),
                lo[2] + 2 * k as i32 + (d >> 2),
            );
            sum += grid.tree.probe_components(c).0[0];
        }
        (sum / 8.0) as f32
    })
}

/// A field with no density beyond planar depth `depth` of a camera at
/// `eye` looking along `forward`: its segments end at the plane.
struct PlaneCut<F> {
    inner: F,
    eye: Vec3,
    forward: Vec3,
    depth: f32,
}

impl<F: DensityField> PlaneCut<F> {
    /// The part of `[t_min, t_max]` in front of the plane.
    fn in_front(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> (f32, f32) {
        let (a, b) = ((origin - self.eye).dot(self.forward), dir.dot(self.forward));
        let edge = (self.depth - a) / b;
        match b {
            b if b > 0.0 => (t_min, t_max.min(edge)),
            b if b < 0.0 => (t_min.max(edge), t_max),
            _ if a <= self.depth => (t_min, t_max),
            _ => (0.0, -1.0),
        }
    }
}

impl<F: DensityField> DensityField for PlaneCut<F> {
    type Segments<'a>
        = std::iter::Flatten<std::option::IntoIter<F::Segments<'a>>>
    where
        Self: 'a;

    fn bounds(&self) -> Bounds3 {
        self.inner.bounds()
    }

    fn density(&self, p: Vec3) -> f32 {
        if (p - self.eye).dot(self.forward) > self.depth {
            0.0
        } else {
            self.inner.density(p)
        }
    }

    fn segments(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self::Segments<'_> {
        let (t0, t1) = self.in_front(origin, dir, t_min, t_max);
        (t0 < t1)
            .then(|| self.inner.segments(origin, dir, t0, t1))
            .into_iter()
            .flatten()
    }

    fn global_majorant(&self) -> f32 {
        self.inner.global_majorant()
    }

    fn voxel_size(&self) -> f32 {
        self.inner.voxel_size()
    }
}

fn setup() -> (GridField, Camera, Lights) {
    let field = corpus_cloud();
    let b = field.bounds();
    let centre = b.centre();
    let eye = centre - Vec3::new(0.0, 0.0, 2.2 * b.size().max_element());
    let camera = Camera::new(eye, centre, Vec3::Y, 30.0, SIZE, SIZE);
    // Sunlight travels along the view: the sun is behind the camera.
    let sun = Sun::new(camera.forward(), Vec3::splat(3.0), 0.0);
    let lights = Lights::sun_and_sky(Some(sun), None);
    (field, camera, lights)
}

fn render_field<F: DensityField>(
    field: F,
    camera: Camera,
    lights: &Lights,
    holdout: Option<f32>,
) -> Rendered {
    let mut s = common::settings(IntegratorKind::Path, 32, 3);
    s.max_depth = Some(1);
    if let Some(d) = holdout {
        s.compositing.holdout_depth = Some(Arc::new(depth_image(d)));
    }
    let scene = Scene {
        media: cirrus_render::Volumes::from(Medium::new(field, 0.08, Vec3::splat(0.95), 0.3)),
        camera,
        lights: lights.clone(),
    };
    render(&scene, &s)
}

/// A plane across the view at planar depth `d`, as another renderer's Z
/// pass would hold it, through an EXR file.
fn depth_image(d: f32) -> DepthHoldout {
    use exr::prelude::*;
    let dir = std::env::temp_dir().join(format!("cirrus-holdout-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("plane-{d}.exr"));
    let channel = AnyChannel::new(
        "ViewLayer.Depth.Z",
        FlatSamples::F32(vec![d; (SIZE * SIZE) as usize]),
    );
    let layer = Layer::new(
        (SIZE as usize, SIZE as usize),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(smallvec::smallvec![channel]),
    );
    Image::from_layer(layer).write().to_file(&path).unwrap();
    let holdout = DepthHoldout::read(&path, None, 1e10, (SIZE, SIZE)).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    holdout
}

#[test]
fn a_depth_holdout_is_the_density_cut_at_its_plane() {
    let (field, camera, lights) = setup();
    let b = field.bounds();
    let mid = (b.centre() - camera.from()).dot(camera.forward());
    let cut = PlaneCut {
        inner: field.clone(),
        eye: camera.from(),
        forward: camera.forward(),
        depth: mid,
    };
    let held = render_field(field.clone(), camera, &lights, Some(mid));
    let reference = render_field(cut, camera, &lights, None);
    let whole = render_field(field.clone(), camera, &lights, None);
    let alpha = |r: &Rendered| r.image.rgba.iter().map(|p| p[3]).sum::<f32>();
    eprintln!(
        "alpha summed: {} whole, {} held out, {} cut",
        alpha(&whole),
        alpha(&held),
        alpha(&reference)
    );
    assert!(
        alpha(&held) < 0.9 * alpha(&whole),
        "the plane must cut the cloud"
    );
    let largest = held
        .image
        .rgba
        .iter()
        .zip(&reference.image.rgba)
        .flat_map(|(a, b)| (0..4).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0f32, f32::max);
    eprintln!("largest difference from the cut density: {largest:e}");
    for c in 0..4 {
        let d = common::differences(&held.image, &reference.image, c);
        common::assert_pooled_agreement(&format!("channel {c}"), &d);
    }
    // In front of all density, the plane leaves nothing: alpha 0, black.
    let front = (b.min - camera.from()).dot(camera.forward()) - 1.0;
    let nothing = render_field(field, camera, &lights, Some(front));
    assert!(nothing.image.rgba.iter().all(|p| *p == [0.0; 4]));
}
