//! Walks along and near the axes end, and take no more steps than the
//! cells they cross: every direction whose components are 0, -0, 1e-7,
//! 1e-30 or the smallest subnormal beside a unit one, from origins inside
//! the volume, on each of its faces, edges and corners, and outside it,
//! over an infinite `t_max` (a ray toward a light at infinity).
//!
//! Each walk runs under a step budget set here: a walk that does not end
//! fails the test by its count instead of hanging it.

use cirrus_bricks::{convert_tree, BrickVolume, Lattice, Precision, CELL_LOG2};
use cirrus_vdb::{Coord, Tree};
use glam::Vec3;

/// A 40 x 24 x 32 voxel box of density with a hollow, so the walks
/// cross kept cells, empty cells and the volume's faces.
fn volume() -> BrickVolume {
    let mut tree = Tree::new(0.0f32);
    for x in 0..40 {
        for y in 0..24 {
            for z in 0..32 {
                let hollow = (12..28).contains(&x) && (8..16).contains(&y);
                if !hollow {
                    let d = 0.2 + 0.01 * ((x * 7 + y * 3 + z) % 50) as f32;
                    tree.set_value_on(Coord::new(x, y, z), d);
                }
            }
        }
    }
    convert_tree(&tree, Precision::F32).expect("converts")
}

/// Directions with one unit component and every mix of the near-zero
/// values in the other two, each sign.
fn directions() -> Vec<Vec3> {
    let small = [0.0, -0.0, 1e-7, -1e-7, 1e-30, f32::from_bits(1)];
    let mut out = Vec::new();
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            for a in small {
                for b in small {
                    let mut d = [a, b];
                    let mut v = [0.0; 3];
                    v[axis] = sign;
                    v[(axis + 1) % 3] = d[0];
                    v[(axis + 2) % 3] = std::mem::take(&mut d[1]);
                    out.push(Vec3::from_array(v));
                }
            }
        }
    }
    out
}

/// Origins inside, on faces, edges and corners (each coordinate 0, a
/// cell boundary, an inner point or the far face), and outside.
fn origins(extent: Vec3) -> Vec<Vec3> {
    let picks = |e: f32| [0.0, 4.0, 5.5, e, -3.0, e + 3.0];
    let mut out = Vec::new();
    for x in picks(extent.x) {
        for y in picks(extent.y) {
            for z in picks(extent.z) {
                out.push(Vec3::new(x, y, z));
            }
        }
    }
    out
}

/// The most cells a line can cross in the box: one per cell boundary it
/// passes on each axis, plus the one it starts in, with a little slack
/// for the nudge past each face.
fn cells_crossed_bound(extent: Vec3) -> u32 {
    let cell = (1 << CELL_LOG2) as f32;
    let per_axis = (extent / cell).ceil() + 2.0;
    (per_axis.x + per_axis.y + per_axis.z) as u32 + 4
}

/// Runs `body` on a thread and fails if it has not ended within a
/// generous budget (it takes well under a second): a walk that never
/// ends fails the test instead of hanging the suite.
fn within_budget(body: impl FnOnce() + Send + 'static) {
    let (done, wait) = std::sync::mpsc::channel();
    let worker = std::thread::spawn(move || {
        body();
        let _ = done.send(());
    });
    match wait.recv_timeout(std::time::Duration::from_secs(120)) {
        Ok(()) => worker.join().unwrap(),
        // The body panicked: report its panic.
        Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
            std::panic::resume_unwind(worker.join().unwrap_err())
        }
        Err(_) => panic!("a walk did not end"),
    }
}

#[test]
fn axis_parallel_walks_end_within_the_cells_they_cross() {
    within_budget(walks_end_within_the_cells_they_cross);
}

#[test]
fn axis_parallel_marches_visit_at_most_their_length_in_steps() {
    within_budget(marches_visit_at_most_their_length_in_steps);
}

fn walks_end_within_the_cells_they_cross() {
    let vol = volume();
    let extent = vol.local_extent();
    let bound = cells_crossed_bound(extent);
    let partitions = [
        ("finest", vol.partition(0.0, f32::INFINITY)),
        ("voxel cells", vol.partition(0.0, 0.0)),
        ("occupancy", vol.occupancy_partition(1)),
    ];
    let (mut walks, mut with_density) = (0u32, 0u32);
    for (name, cells) in &partitions {
        // Voxel cells split a level-0 cell into its voxels.
        let bound = if *name == "voxel cells" {
            bound << CELL_LOG2
        } else {
            bound
        };
        for o in origins(extent) {
            for d in directions() {
                let mut walk = vol.segments_in(cells, o, d, 0.0, f32::INFINITY);
                let mut segments = 0u32;
                for s in walk.by_ref() {
                    assert!(s.t0.is_finite() && s.t1.is_finite() && s.t0 <= s.t1);
                    segments += 1;
                    assert!(
                        segments <= bound,
                        "{name}: walk from {o} along {d:?} passed {bound} segments"
                    );
                }
                assert!(
                    walk.steps <= bound,
                    "{name}: walk from {o} along {d:?} took {} steps, over {bound}",
                    walk.steps
                );
                walks += 1;
                with_density += (segments > 0) as u32;
            }
        }
    }
    // The walks did cross density: the test is not passing on empty rays.
    assert!(with_density > walks / 20, "{with_density} of {walks}");
}

fn marches_visit_at_most_their_length_in_steps() {
    let vol = volume();
    let extent = vol.local_extent();
    let cells = vol.occupancy_partition(1);
    let h = 0.5;
    // Points along the longest line through the box, plus one per segment.
    let bound = (extent.length() / h) as u32 + cells_crossed_bound(extent);
    let mut visited_any = 0u32;
    for o in origins(extent) {
        for d in directions() {
            let mut visits = 0u32;
            let steps =
                vol.march_occupied(&cells, o, d, f32::INFINITY, Lattice::new(h, 0.5), |t, _| {
                    assert!(t.is_finite());
                    visits += 1;
                    visits <= bound
                });
            assert!(
                visits <= bound && steps <= bound as u64,
                "march from {o} along {d:?}: {visits} points, {steps} steps, bound {bound}"
            );
            visited_any += (visits > 0) as u32;
        }
        for d in directions() {
            // The segment form of the march, as fields without occupancy
            // cells take it.
            let mut visits = 0u32;
            Lattice::new(h, 0.5).visit_segments(vol.segments(o, d, 0.0, f32::INFINITY), |t| {
                assert!(t.is_finite());
                visits += 1;
                visits <= bound
            });
            assert!(
                visits <= bound,
                "segment march from {o} along {d:?}: {visits}"
            );
        }
    }
    assert!(visited_any > 0);
}
