//! Property tests of conversion, lookups and the majorant walk against the
//! reader's own tree (the independent reference).

use cirrus_bricks::{
    convert_tree, BrickVolume, Cell, Lattice, MajorantSegment, Precision, TIGHT_ENOUGH,
};
use cirrus_vdb::{Coord, Tree};
use glam::{IVec3, Vec3};
use proptest::prelude::*;

/// A tree with a few random blobs of density, some isolated voxels, some
/// special values, and an 8^3-aligned constant region.
fn random_tree(seed: u64, origin: IVec3) -> Tree<f32> {
    let mut rng = seed;
    let mut next = move || {
        rng = rng
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((rng >> 33) as f32) / (1u64 << 31) as f32
    };
    let mut tree = Tree::new(0.0f32);
    for _ in 0..3 {
        let c = Vec3::new(next(), next(), next()) * 40.0;
        let r = 3.0 + next() * 8.0;
        let ri = r.ceil() as i32;
        for x in -ri..=ri {
            for y in -ri..=ri {
                for z in -ri..=ri {
                    let p = c + Vec3::new(x as f32, y as f32, z as f32);
                    let d = 1.0 - (p - c).length() / r;
                    if d > 0.0 {
                        let ijk = origin + p.floor().as_ivec3();
                        tree.set_value_on(Coord::new(ijk.x, ijk.y, ijk.z), d * (0.5 + next()));
                    }
                }
            }
        }
    }
    for _ in 0..20 {
        let ijk = origin + (Vec3::new(next(), next(), next()) * 60.0).as_ivec3();
        tree.set_value_on(Coord::new(ijk.x, ijk.y, ijk.z), next() * 3.0);
    }
    // A constant 8^3 block: becomes a constant brick.
    for x in 48..56 {
        for y in 0..8 {
            for z in 0..8 {
                tree.set_value_on(Coord::new(origin.x + x, origin.y + y, origin.z + z), 0.75);
            }
        }
    }
    tree
}

/// The reference density: trilinear over the tree's active values (inactive
/// = background 0), with the same arithmetic as the bricks.
fn reference_trilinear(tree: &Tree<f32>, p: Vec3) -> f32 {
    let f0 = p.floor();
    let c = f0.as_ivec3();
    let f = p - f0;
    let mut acc = tree.accessor();
    let mut at = |dx: i32, dy: i32, dz: i32| {
        let (v, on) = acc.probe(Coord::new(c.x + dx, c.y + dy, c.z + dz));
        if on {
            v
        } else {
            0.0
        }
    };
    let v = [
        at(0, 0, 0),
        at(0, 0, 1),
        at(0, 1, 0),
        at(0, 1, 1),
        at(1, 0, 0),
        at(1, 0, 1),
        at(1, 1, 0),
        at(1, 1, 1),
    ];
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x0 = lerp(lerp(v[0], v[1], f.z), lerp(v[2], v[3], f.z), f.y);
    let x1 = lerp(lerp(v[4], v[5], f.z), lerp(v[6], v[7], f.z), f.y);
    lerp(x0, x1, f.x)
}

fn local(vol: &BrickVolume, p: Vec3) -> Vec3 {
    p - vol.origin.as_vec3()
}

fn check_ray(
    vol: &BrickVolume,
    tree: &Tree<f32>,
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
    samples: &[f32],
) {
    let lo = local(vol, o);
    // The plain walk, a coarse one (cells refined only when their bounds
    // differ by over 2 density x voxels), one that goes voxel by voxel, and
    // the marchers' occupancy cells at levels 1 and 2.
    let partitions = [
        vol.partition(0.0, f32::INFINITY),
        vol.partition(2.0, f32::INFINITY),
        vol.partition(0.0, 0.0),
        vol.occupancy_partition(1),
        vol.occupancy_partition(2),
    ];
    for cells in &partitions {
        let segs: Vec<MajorantSegment> = vol.segments_in(cells, lo, d, t_min, t_max).collect();
        check_segments(tree, o, d, t_min, t_max, samples, &segs);
    }
}

fn check_segments(
    tree: &Tree<f32>,
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
    samples: &[f32],
    segs: &[MajorantSegment],
) {
    for w in segs.windows(2) {
        assert!(
            w[0].t1 <= w[1].t0,
            "segments overlap or are out of order: {w:?}"
        );
    }
    for s in segs {
        assert!(
            s.t0 >= t_min && s.t1 <= t_max && s.t0 < s.t1,
            "segment {s:?} outside [{t_min}, {t_max}]"
        );
        assert!(s.minorant <= s.majorant);
    }
    for &u in samples {
        let t = t_min + (t_max - t_min) * u;
        let density = reference_trilinear(tree, o + d * t);
        match segs.iter().find(|s| s.t0 < t && t < s.t1) {
            Some(s) => assert!(
                s.minorant <= density && density <= s.majorant,
                "density {density} at t={t} outside [{}, {}] of {s:?}",
                s.minorant,
                s.majorant
            ),
            // Points on a segment end are covered by either neighbour: skip exact ends.
            None if segs.iter().any(|s| s.t0 == t || s.t1 == t) => {}
            None => assert_eq!(
                density, 0.0,
                "density {density} at t={t} lies in no segment"
            ),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn brick_lookups_equal_the_tree_exactly_at_f32(seed in 0u64..1000, px in -4f32..70.0, py in -4f32..70.0, pz in -4f32..70.0) {
        let origin = IVec3::new(-13, 5, 200);
        let tree = random_tree(seed, origin);
        let vol = convert_tree(&tree, Precision::F32).unwrap();
        for k in 0..64 {
            // Points on a 1/64 lattice, so moving them to the volume's local frame is exact.
            let q = Vec3::new(px, py, pz) + Vec3::new(k as f32 * 0.37, k as f32 * 0.11, -(k as f32) * 0.23);
            let p = origin.as_vec3() + (q * 64.0).round() / 64.0;
            prop_assert_eq!(vol.trilinear(local(&vol, p)), reference_trilinear(&tree, p));
        }
    }

    #[test]
    fn segments_bound_the_density_and_cover_it(
        seed in 0u64..1000,
        o in prop::array::uniform3(-20f32..80.0),
        d in prop::array::uniform3(-1f32..1.0),
        samples in prop::collection::vec(0f32..1.0, 64),
    ) {
        let tree = random_tree(seed, IVec3::ZERO);
        let vol = convert_tree(&tree, Precision::F32).unwrap();
        let d = Vec3::from(d);
        prop_assume!(d.length() > 1e-3);
        check_ray(&vol, &tree, Vec3::from(o), d, 0.0, 200.0, &samples);
    }

    #[test]
    fn partition_holds_the_cells_a_search_from_the_top_keeps_and_empty_distances(seed in 0u64..1000, split in prop::sample::select(vec![0.0f32, 0.5, 2.0, 8.0, 1e9])) {
        // The rule searched level by level from the coarsest cell down, for
        // every level-0 cell, against the table built once by recursion.
        let tree = random_tree(seed, IVec3::new(3, -40, 17));
        let vol = convert_tree(&tree, Precision::F32).unwrap();
        let cells = vol.partition(split, f32::INFINITY);
        let top = vol.levels.len() - 1;
        let [dx, dy, dz] = vol.levels[0].dims;
        let mut kept_levels = [0usize; 10];
        let mut far_empty = 0;
        let d1 = vol.levels[1].dims;
        let occupied: Vec<IVec3> = (0..d1[0] as i32)
            .flat_map(|x| (0..d1[1] as i32).flat_map(move |y| (0..d1[2] as i32).map(move |z| IVec3::new(x, y, z))))
            .filter(|c| vol.levels[1].get(c.to_array()).1 > 0.0)
            .collect();
        for x in 0..dx as i32 {
            for y in 0..dy as i32 {
                for z in 0..dz as i32 {
                    let c0 = IVec3::new(x, y, z);
                    let mut l = top;
                    loop {
                        let (lo, hi) = vol.levels[l].get((c0 >> l as i32).to_array());
                        let width = (4u32 << l) as f32;
                        if l == 0 || hi <= 0.0 || lo >= hi * TIGHT_ENOUGH || (hi - lo) * width <= split {
                            break;
                        }
                        l -= 1;
                    }
                    kept_levels[l] += 1;
                    let c1 = IVec3::new(x >> 1, y >> 1, z >> 1);
                    let expect = if vol.levels[1].get(c1.to_array()).1 > 0.0 {
                        Cell::Kept(l)
                    } else {
                        // Chessboard distance to the nearest level-1 cell with density.
                        let distance = occupied
                            .iter()
                            .map(|&o| (o - c1).abs().max_element() as u32)
                            .min()
                            .unwrap_or(127)
                            .min(127);
                        far_empty += usize::from(distance >= 2);
                        Cell::Empty { distance }
                    };
                    prop_assert_eq!(cells.cell_at(c1), Some(expect), "level-0 cell {:?}, split {}", c0, split);
                }
            }
        }
        // The case is not trivial: some empty cells are 2 or more cells from
        // density, some cells are kept below the top, and
        // with an unbounded split only top cells are.
        prop_assert!(far_empty > 0);
        let below_top: usize = kept_levels[..top].iter().sum();
        prop_assert_eq!(below_top == 0, split >= 1e9, "kept per level {:?}", kept_levels);
    }

    #[test]
    fn axis_rays_along_faces_edges_and_corners_terminate_and_bound(
        seed in 0u64..200,
        axis in 0usize..3,
        sign in prop::bool::ANY,
        a in 0i32..8, b in 0i32..8,
        samples in prop::collection::vec(0f32..1.0, 64),
    ) {
        let tree = random_tree(seed, IVec3::ZERO);
        let vol = convert_tree(&tree, Precision::F32).unwrap();
        // Origins on brick faces, edges and corners (multiples of 8), and on voxel centres.
        let mut o = [a as f32 * 8.0, b as f32 * 8.0, 0.0];
        o.rotate_right(axis);
        let mut d = Vec3::ZERO;
        d[axis] = if sign { 1.0 } else { -1.0 };
        let start = if sign { -10.0 } else { 90.0 };
        let mut o = Vec3::from(o);
        o[axis] = start;
        check_ray(&vol, &tree, o, d, 0.0, 120.0, &samples);
        check_ray(&vol, &tree, o + Vec3::splat(0.5), d, 0.0, 120.0, &samples);
    }
}

#[test]
fn quantised_bricks_stay_within_their_stated_error() {
    let tree = random_tree(7, IVec3::ZERO);
    let exact = convert_tree(&tree, Precision::F32).unwrap();
    assert_eq!(exact.info.max_error, 0.0);
    let h = convert_tree(&tree, Precision::F16).unwrap();
    let q = convert_tree(&tree, Precision::U8).unwrap();
    // f16 keeps 11 significant bits: relative error at most 2^-11 (values here are normal).
    let vmax = 3.0f32 * 1.5;
    assert!(
        h.info.max_error <= vmax * 2f32.powi(-11),
        "f16 error {}",
        h.info.max_error
    );
    let mut worst_u8 = 0f32;
    for x in -1..70 {
        for y in -1..70 {
            for z in -1..70 {
                let c = IVec3::new(x, y, z);
                let v = exact.voxel(c - exact.origin);
                let eh = (h.voxel(c - h.origin) - v).abs();
                assert!(eh <= v * 2f32.powi(-11) + 1e-30, "f16 voxel {c} error {eh}");
                worst_u8 = worst_u8.max((q.voxel(c - q.origin) - v).abs());
            }
        }
    }
    // u8: half a step of the brick's range; the widest range here is below vmax.
    assert!(
        worst_u8 <= q.info.max_error + 1e-6 && q.info.max_error <= vmax / 510.0 * 1.001,
        "u8 error {worst_u8} / {}",
        q.info.max_error
    );
    // The atlas shrinks by the voxel size exactly; the map and bounds do not change.
    assert_eq!(q.memory_bytes().2 * 4, exact.memory_bytes().2);
    assert_eq!(h.memory_bytes().2 * 2, exact.memory_bytes().2);
}

#[test]
fn conversion_counts_bricks_and_sanitises_bad_values() {
    let mut tree = Tree::new(0.0f32);
    tree.set_value_on(Coord::new(1, 1, 1), 1.0);
    tree.set_value_on(Coord::new(2, 1, 1), f32::NAN);
    tree.set_value_on(Coord::new(3, 1, 1), f32::INFINITY);
    tree.set_value_on(Coord::new(4, 1, 1), -2.0);
    for x in 16..24 {
        for y in 0..8 {
            for z in 0..8 {
                tree.set_value_on(Coord::new(x, y, z), 0.5);
            }
        }
    }
    let vol = convert_tree(&tree, Precision::F32).unwrap();
    assert_eq!(vol.info.sanitized_voxels, 3);
    assert_eq!(vol.info.bricks_stored, 1);
    assert_eq!(vol.info.bricks_constant, 1);
    assert_eq!(vol.voxel(IVec3::new(2, 1, 1) - vol.origin), 0.0);
    assert_eq!(vol.voxel(IVec3::new(1, 1, 1) - vol.origin), 1.0);
    assert_eq!(vol.max_density(), 1.0 + 1.0 / (1 << 20) as f32);
}

#[test]
fn cbrk_round_trip_is_bit_identical_and_corruption_is_an_error() {
    let tree = random_tree(3, IVec3::new(-40, 7, 1000));
    let dir = std::env::temp_dir().join(format!("cirrus-cbrk-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for precision in [Precision::F32, Precision::F16, Precision::U8] {
        let mut vol = convert_tree(&tree, precision).unwrap();
        vol.info.grid_name = "density".into();
        let path = dir.join(format!("v_{}.cbrk", precision.name()));
        cirrus_bricks::write_cbrk(&vol, &path).unwrap();
        let back = cirrus_bricks::read_cbrk(&path).unwrap();
        assert_eq!(back.info, vol.info);
        assert_eq!(
            (back.origin, back.dims, back.levels.len()),
            (vol.origin, vol.dims, vol.levels.len())
        );
        for (a, b) in back.levels.iter().zip(&vol.levels) {
            assert_eq!(
                a.cells.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                b.cells.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
            );
        }
        for x in -45..30 {
            for y in 0..70 {
                let p = Vec3::new(x as f32 + 0.3, y as f32 + 0.6, 1020.25) - vol.origin.as_vec3();
                assert_eq!(back.trilinear(p).to_bits(), vol.trilinear(p).to_bits());
            }
        }
        // Truncations and flipped bytes are errors, never panics.
        let bytes = std::fs::read(&path).unwrap();
        for cut in [0, 7, 100, 1023, bytes.len() / 2, bytes.len() - 1] {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            assert!(
                cirrus_bricks::read_cbrk(&path).is_err(),
                "truncated at {cut}"
            );
        }
        for at in [0, 9, 20, 300, 1030, bytes.len() - 3] {
            let mut b = bytes.clone();
            b[at] ^= 0x5a;
            std::fs::write(&path, &b).unwrap();
            assert!(
                cirrus_bricks::read_cbrk(&path).is_err(),
                "flipped byte {at}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn baselines_bound_the_density_too_and_the_hierarchy_is_tighter() {
    use cirrus_bench::baseline::{FixedMajorantGrid, GlobalMajorant};
    use cirrus_bench::measure::{density_integral, measure, random_rays};
    let tree = random_tree(11, IVec3::ZERO);
    let vol = convert_tree(&tree, Precision::F32).unwrap();
    let global = GlobalMajorant::new(&vol);
    let fixed = FixedMajorantGrid::build(&vol, 16);
    let rays = random_rays(&vol, 300, 5);
    let integrals: Vec<f64> = rays.iter().map(|r| density_integral(&vol, r)).collect();
    for r in &rays {
        for s in fixed.segments(r.origin, r.dir, 0.0, r.t_max) {
            for k in 1..8 {
                let t = s.t0 + (s.t1 - s.t0) * k as f32 / 8.0;
                let d = vol.trilinear(r.origin + r.dir * t);
                assert!(
                    d <= s.majorant,
                    "fixed grid: density {d} above majorant {}",
                    s.majorant
                );
            }
        }
    }
    let a = measure("global", &rays, &integrals, |r| {
        global.segments(r.origin, r.dir, 0.0, r.t_max)
    });
    let b = measure("fixed", &rays, &integrals, |r| {
        fixed.segments(r.origin, r.dir, 0.0, r.t_max)
    });
    let c = measure("hierarchy", &rays, &integrals, |r| {
        vol.segments(r.origin, r.dir, 0.0, r.t_max)
    });
    // Every structure bounds the density, so no tightness can fall below 1.
    for m in [&a, &b, &c] {
        assert!(
            m.tightness >= 1.0 - 1e-3,
            "{} tightness {}",
            m.name,
            m.tightness
        );
    }
    assert!(
        c.tightness < b.tightness && b.tightness < a.tightness,
        "{a:?}\n{b:?}\n{c:?}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The marchers' partition keeps every level-1 cell holding density at
    /// the level asked for (the top one at most) and leaves empty space as
    /// the refined partition has it, distances included.
    #[test]
    fn occupancy_cells_are_the_occupied_cells_at_one_level(seed in 0u64..1000, level in 1usize..4) {
        let tree = random_tree(seed, IVec3::new(-7, 2, 30));
        let vol = convert_tree(&tree, Precision::F32).unwrap();
        let top = vol.levels.len() - 1;
        let occupancy = vol.occupancy_partition(level);
        let refined = vol.partition(0.0, f32::INFINITY);
        let [dx, dy, dz] = vol.levels[1].dims.map(|d| d as i32);
        let (mut kept, mut empty) = (0, 0);
        for x in -1..=dx {
            for y in -1..=dy {
                for z in -1..=dz {
                    let c = IVec3::new(x, y, z);
                    let inside = x >= 0 && y >= 0 && z >= 0 && x < dx && y < dy && z < dz;
                    let occupied = inside && vol.levels[1].get(c.to_array()).1 > 0.0;
                    match occupancy.cell_at(c) {
                        Some(Cell::Kept(l)) => {
                            prop_assert!(occupied);
                            prop_assert_eq!(l, level.min(top));
                            kept += 1;
                        }
                        Some(e @ Cell::Empty { .. }) => {
                            prop_assert!(!occupied);
                            prop_assert_eq!(Some(e), refined.cell_at(c));
                            empty += 1;
                        }
                        None => prop_assert!(!inside),
                    }
                }
            }
        }
        prop_assert_eq!(kept + empty, (dx * dy * dz) as usize);
        prop_assert!(kept > 0);
    }
}

proptest! {
    // About a third of these rays meet a blob.
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// The march over occupied cells finds every lattice point with
    /// density: the same points, at the same `t` and with the same density,
    /// as a march over the occupancy segments, and as a brute-force march
    /// of every lattice point inside the volume's box from the same origin
    /// (the first positive segment's start).
    #[test]
    fn the_occupied_march_finds_every_lattice_point_with_density(
        seed in 0u64..1000,
        o in prop::array::uniform3(-20f32..80.0),
        target in prop::array::uniform3(4f32..40.0),
        h in 0.2f32..4.0,
        u in 0f32..1.0,
    ) {
        let tree = random_tree(seed, IVec3::new(-7, 2, 30));
        let vol = convert_tree(&tree, Precision::F32).unwrap();
        // Rays through the blobs' region, from anywhere around it.
        let d = (Vec3::from(target) - Vec3::from(o)) / 64.0;
        prop_assume!(d.length() > 1e-3);
        let lo = local(&vol, Vec3::from(o) + IVec3::new(-7, 2, 30).as_vec3());
        let cells = vol.occupancy_partition(1);
        let lattice = Lattice::new(h, u);
        let t_max = 300.0;
        let with_density = |t: f32| (t, vol.trilinear(lo + d * t));
        let mut by_segments = Vec::new();
        lattice.visit_segments(vol.segments_in(&cells, lo, d, 0.0, t_max), |t| {
            by_segments.push(with_density(t));
            true
        });
        let mut by_cells = Vec::new();
        vol.march_occupied(&cells, lo, d, t_max, lattice, |t, v| {
            by_cells.push((t, v));
            true
        });
        for &(t, v) in &by_cells {
            prop_assert_eq!(v, with_density(t).1);
        }
        let positive = |v: &Vec<(f32, f32)>| v.iter().copied().filter(|p| p.1 > 0.0).collect::<Vec<_>>();
        prop_assert_eq!(positive(&by_cells), positive(&by_segments));
        let org = vol
            .segments_in(&cells, lo, d, 0.0, t_max)
            .find(|s| s.majorant > 0.0)
            .map(|s| s.t0);
        let extent = vol.local_extent();
        let mut brute = Vec::new();
        if let Some(org) = org {
            let mut k = 0;
            loop {
                let t = lattice.at(org, k);
                let p = lo + d * t;
                if t >= t_max || (k > 0 && !(p.cmpge(Vec3::ZERO).all() && p.cmplt(extent).all()) && t > org + 2.0 * h) {
                    break;
                }
                if p.cmpge(Vec3::ZERO).all() && p.cmplt(extent).all() {
                    brute.push(with_density(t));
                }
                k += 1;
            }
        }
        prop_assert_eq!(positive(&by_cells), positive(&brute));
        prop_assert!(by_cells.len() <= brute.len());
    }
}
