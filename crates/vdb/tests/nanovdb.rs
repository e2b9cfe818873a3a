//! The NanoVDB reader against files written by NanoVDB 32.4.2's own tools
//! (tests/fixtures, made by tools/make_nvdb_fixtures.sh): counts as
//! `nanovdb_print` reports them, values as pyopenvdb reads the source .vdb
//! files and as NanoVDB's accessor reads the quantised ones (expected.json),
//! and transforms. Newer layouts and corrupt files: nanovdb_files.rs.

mod nanovdb_support;

use cirrus_vdb::*;
use glam::DVec3;
use nanovdb_support::*;
use serde_json::Value as Json;

fn coord(j: &Json) -> Coord {
    let a: Vec<i32> = j
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_i64().unwrap() as i32)
        .collect();
    Coord::new(a[0], a[1], a[2])
}

fn components(j: &Json) -> Vec<f64> {
    match j {
        Json::Array(a) => a.iter().map(|v| v.as_f64().unwrap()).collect(),
        Json::Bool(b) => vec![*b as u8 as f64],
        v => vec![v.as_f64().unwrap()],
    }
}

/// Every probe of expected.json: the active state exactly, the value within `tol(ijk, expected)`;
/// returns how many there were.
fn check_probes(grid: &Grid, exp: &Json, tol: impl Fn(Coord, f64) -> f64) -> usize {
    let probes = exp["probes"].as_array().unwrap();
    for p in probes {
        let c = coord(&p["ijk"]);
        let (v, n, active) = grid.tree.probe_components(c);
        let want = components(&p["value"]);
        assert_eq!(n, want.len(), "{} at {c:?}", grid.name);
        assert_eq!(
            active,
            p["active"].as_bool().unwrap(),
            "{} active at {c:?}",
            grid.name
        );
        for k in 0..n {
            // The JSON grids are all single precision: compare there (serde_json's
            // default float parsing may be one double ulp off Python's repr).
            let t = tol(c, want[k]);
            let d = (v[k] as f32 - want[k] as f32).abs() as f64;
            assert!(
                d <= t,
                "{} at {c:?}: {} vs {} (tolerance {t})",
                grid.name,
                v[k],
                want[k]
            );
        }
    }
    probes.len()
}

fn check_transform(grid: &Grid, exp: &Json, tol: f64) {
    for pair in exp["index_to_world"].as_array().unwrap() {
        let ijk = components(&pair[0]);
        let want = components(&pair[1]);
        let got = grid
            .transform
            .index_to_world(DVec3::new(ijk[0], ijk[1], ijk[2]));
        let d = (got - DVec3::new(want[0], want[1], want[2]))
            .abs()
            .max_element();
        assert!(
            d <= tol,
            "{}: index {ijk:?} -> {got:?}, pyopenvdb says {want:?}",
            grid.name
        );
    }
}

#[test]
fn float_fog_volume_matches_pyopenvdb() {
    let file = VolumeFile::open(fixture("fog.nvdb")).unwrap();
    assert_eq!(file.format(), Format::NanoVdb);
    let infos = file.grids();
    assert_eq!(infos.len(), 1);
    let info = infos[0].clone();
    assert_eq!(
        (
            info.name.as_str(),
            info.unique_name.as_str(),
            info.type_name.as_str()
        ),
        ("density", "density", "Float")
    );
    assert_eq!(
        (info.value_type, info.half_float),
        (Some(ValueType::Float), false)
    );
    // The header (16), metadata (176) and name ("density\0") precede the grid.
    assert_eq!(info.byte_len, file.file_len() - 200);
    let after_open = file.bytes_read();
    assert!(after_open < 300, "open read {after_open} bytes");

    let grid = file.read_grid(0).unwrap();
    assert_eq!(
        file.bytes_read() - after_open,
        info.byte_len,
        "read exactly the grid's bytes"
    );
    let exp = expected("density");
    assert_eq!(grid.name, "density");
    assert_eq!(grid.class, GridClass::FogVolume);
    assert!(!grid.half_float);
    let tree = grid.float_tree().unwrap();
    assert_eq!(tree.background(), 0.0);
    // nanovdb_print: 68721576191 voxels, 1->1->13 nodes, 1->1->1 active tiles.
    assert_eq!(
        grid.tree.active_voxel_count(),
        exp["active_voxel_count"].as_u64().unwrap()
    );
    assert_eq!(grid.tree.active_voxel_count(), 68_721_576_191);
    assert_eq!(grid.tree.leaf_count(), 13);
    assert_eq!(
        grid.tree.leaf_count() as u64,
        exp["leaf_count"].as_u64().unwrap()
    );
    assert_eq!((tree.upper_nodes().len(), tree.lower_nodes().len()), (1, 1));
    assert_eq!(
        grid.tree.active_tile_counts(),
        tree::TileCounts {
            lower: 1,
            upper: 1,
            root: 1
        }
    );
    // nanovdb_print's index bounding box (17,0,0) -> (8191,4095,4095), inclusive.
    assert_eq!(
        grid.tree.active_bbox(),
        Some(CoordBBox::new(
            Coord::new(17, 0, 0),
            Coord::new(8191, 4095, 4095)
        ))
    );
    assert!(check_probes(&grid, &exp, |_, _| 0.0) > 300);

    // Tiles at each level, an inactive leaf value, and outside every node.
    assert_eq!(
        tree.probe(Coord::new(5000, 100, 4000)),
        (0.125, true, Level::Root)
    );
    assert_eq!(
        tree.probe(Coord::new(200, 5, 127)),
        (0.25, true, Level::Upper)
    );
    assert_eq!(
        tree.probe(Coord::new(300, 64, 64)),
        (0.3, false, Level::Upper)
    );
    assert_eq!(tree.probe(Coord::new(71, 7, 0)), (0.5, true, Level::Lower));
    assert_eq!(
        tree.probe(Coord::new(30, 30, 30)),
        (0.75, false, Level::Leaf)
    );
    assert_eq!(
        tree.probe(Coord::new(-1, 0, 0)),
        (0.0, false, Level::Background)
    );
    assert_eq!(
        tree.probe(Coord::new(8192, 0, 0)),
        (0.0, false, Level::Background)
    );

    // world = 0.5 * ijk + (1, 2, 3)
    check_transform(&grid, &exp, 1e-12);
    assert_eq!(grid.transform.voxel_size(), DVec3::splat(0.5));
    assert_eq!(grid.transform.kind, MapKind::UniformScaleTranslate);
    assert_eq!(
        grid.transform.index_to_world(DVec3::new(17.0, 0.0, 0.0)),
        DVec3::new(9.5, 2.0, 3.0)
    );
    assert_eq!(
        meta_get(&grid.metadata, "class").and_then(|v| v.as_str()),
        Some("fog volume")
    );
    assert_eq!(
        meta_get(&grid.metadata, "nanovdb_version").and_then(|v| v.as_str()),
        Some("32.4.2")
    );
}

/// Quantised grids: `value = code * quantum + minimum` per leaf, where the
/// writer (OpenToNanoVDB, no dithering) rounds `(v - minimum) / quantum` to
/// the nearest code and `quantum = (max - min) / (2^bits - 1)` over the
/// leaf's 512 values. So each value is within quantum / 2 of the float grid's,
/// plus f32 rounding. FpN instead meets the absolute tolerance it was written
/// with (`-a 0.001`).
#[test]
fn quantised_grids_are_within_their_bounds() {
    let float = VolumeFile::open(fixture("fog.nvdb"))
        .unwrap()
        .read_grid(0)
        .unwrap();
    let exact = float.float_tree().unwrap();
    for (file, type_name, bits) in [
        ("fog_fp16_zip.nvdb", "Fp16", Some(16)),
        ("fog_fp8_blosc.nvdb", "Fp8", Some(8)),
        ("fog_fp4_zip.nvdb", "Fp4", Some(4)),
        ("fog_fpN_zip.nvdb", "FpN", None),
    ] {
        let f = VolumeFile::open(fixture(file)).unwrap();
        let info = f.grids()[0].clone();
        assert_eq!(info.type_name, type_name);
        assert_eq!(
            (info.value_type, info.half_float),
            (Some(ValueType::Float), true)
        );
        let grid = f.read_grid(0).unwrap();
        assert!(grid.half_float);
        assert_eq!(grid.class, GridClass::FogVolume);
        assert_eq!(grid.tree.active_voxel_count(), 68_721_576_191);
        assert_eq!(grid.tree.leaf_count(), 13);
        assert_eq!(
            grid.tree.active_tile_counts(),
            float.tree.active_tile_counts()
        );
        assert_eq!(grid.transform, float.transform);
        let q = grid.float_tree().unwrap();
        let mut worst = 0.0f32;
        for (a, b) in q.leaves().iter().zip(exact.leaves()) {
            assert_eq!((a.origin, &a.value_mask), (b.origin, &b.value_mask));
            let (lo, hi) = b
                .values
                .iter()
                .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
            let bound = match bits {
                Some(bits) => 0.5 * (hi - lo) / ((1u32 << bits) - 1) as f32 + 2e-7,
                None => 0.001 + 2e-7,
            };
            for n in 0..512 {
                let err = (a.values[n] - b.values[n]).abs();
                worst = worst.max(err);
                assert!(
                    err <= bound,
                    "{file}: voxel {:?} off by {err} > {bound}",
                    a.coord_of(n)
                );
            }
        }
        assert!(worst > 0.0, "{file} should not be lossless");
        // And against pyopenvdb's reading of the source, with the loosest per-leaf bound
        // (all values lie in [0, 1.011]); tiles and the background are stored exactly.
        let global = bits.map_or(0.001, |b| 0.5 * 1.011 / ((1u32 << b) - 1) as f64) + 1e-6;
        check_probes(&grid, &expected("density"), |c, _| {
            if q.probe(c).2 == Level::Leaf {
                global
            } else {
                0.0
            }
        });
    }
}

#[test]
fn vec3f_grid_with_an_affine_transform() {
    let file = VolumeFile::open(fixture("vec3f_blosc.nvdb")).unwrap();
    let info = file.grids()[0].clone();
    assert_eq!(
        (info.name.as_str(), info.type_name.as_str()),
        ("velocity", "Vec3f")
    );
    assert_eq!(info.value_type, Some(ValueType::Vec3f));
    let grid = file.read_grid(0).unwrap();
    let exp = expected("velocity");
    assert_eq!(grid.class, GridClass::Staggered);
    let GridTree::Vec3f(tree) = &grid.tree else {
        panic!("not a Vec3f tree")
    };
    assert_eq!(tree.background(), [0.0; 3]);
    // nanovdb_print: 1792 voxels, 1->1->12 nodes, 0->0->1 active tiles
    assert_eq!(grid.tree.active_voxel_count(), 1792);
    assert_eq!(grid.tree.leaf_count(), 12);
    assert_eq!(
        grid.tree.active_tile_counts(),
        tree::TileCounts {
            lower: 1,
            upper: 0,
            root: 0
        }
    );
    assert_eq!(tree.get(Coord::new(7, 9, 4)), [3.5, -2.25, 4.125]);
    assert_eq!(
        tree.probe(Coord::new(20, 35, 17)),
        ([1.0, 2.0, 3.0], true, Level::Lower)
    );
    check_probes(&grid, &exp, |_, _| 0.0);
    // A 30 degree rotation about z, scale (0.25, 0.5, 0.75), translation (10, -5, 2).
    check_transform(&grid, &exp, 1e-12);
    assert_eq!(grid.transform.kind, MapKind::Affine);
    assert!(!grid.transform.is_axis_aligned());
    assert!(
        (grid.transform.voxel_size() - DVec3::new(0.25, 0.5, 0.75))
            .abs()
            .max_element()
            < 1e-15
    );
    let w = grid.transform.index_to_world(DVec3::new(4.0, 0.0, 0.0));
    let c = 30f64.to_radians().cos();
    assert!(
        (w - DVec3::new(10.0 + c, -5.0 + 0.5, 2.0))
            .abs()
            .max_element()
            < 1e-12
    );
}

#[test]
fn level_set_and_bool_grids_in_two_segments() {
    let file = VolumeFile::open(fixture("multi_zip.nvdb")).unwrap();
    let names: Vec<_> = file
        .grids()
        .iter()
        .map(|g| (g.name.clone(), g.type_name.clone()))
        .collect();
    assert_eq!(
        names,
        [
            ("flags".to_string(), "Boolean".to_string()),
            ("sphere_sdf".into(), "Float".into())
        ]
    );

    let sdf = file.read_grid_by_name("sphere_sdf").unwrap();
    let exp = expected("sphere_sdf");
    assert_eq!(sdf.class, GridClass::LevelSet);
    assert_eq!(sdf.float_tree().unwrap().background(), 3.0);
    assert_eq!(sdf.tree.active_voxel_count(), 2846);
    assert_eq!(sdf.tree.leaf_count(), 27);
    assert_eq!(
        check_probes(&sdf, &exp, |_, _| 0.0),
        exp["probes"].as_array().unwrap().len()
    );
    check_transform(&sdf, &exp, 1e-12);

    let flags = file.read_grid_by_name("flags").unwrap();
    let exp = expected("flags");
    let GridTree::Bool(tree) = &flags.tree else {
        panic!("not a bool tree")
    };
    assert!(!tree.background());
    assert_eq!(flags.tree.active_voxel_count(), 560);
    assert_eq!(flags.tree.leaf_count(), 2);
    assert_eq!(tree.probe(Coord::new(3, 0, 5)), (true, true, Level::Leaf));
    assert_eq!(tree.probe(Coord::new(4, 0, 5)), (false, true, Level::Leaf));
    assert_eq!(
        tree.probe(Coord::new(35, 33, 39)),
        (true, true, Level::Lower)
    );
    check_probes(&flags, &exp, |_, _| 0.0);
}

/// One segment with five grids written by `io::writeGrids`; values follow
/// the formulas of tools/make_nvdb_fixtures.sh.
#[test]
fn other_value_types_in_one_segment() {
    let file = VolumeFile::open(fixture("typed_zip.nvdb")).unwrap();
    let types: Vec<_> = file
        .grids()
        .iter()
        .map(|g| (g.name.clone(), g.type_name.clone(), g.value_type))
        .collect();
    let want = [
        ("temperature", "Double", ValueType::Double),
        ("labels", "Int32", ValueType::Int32),
        ("ids", "Int64", ValueType::Int64),
        ("normals", "Vec3d", ValueType::Vec3d),
        ("topology", "Mask", ValueType::Mask),
    ];
    assert_eq!(types.len(), want.len());
    for ((n, t, v), (wn, wt, wv)) in types.iter().zip(want) {
        assert_eq!((n.as_str(), t.as_str(), *v), (wn, wt, Some(wv)));
    }
    let grids = open_and_read_all(&fixture("typed_zip.nvdb")).unwrap();
    let tile = CoordBBox::new(Coord::new(16, 0, 0), Coord::new(23, 7, 7));
    for g in &grids {
        assert_eq!(g.class, GridClass::Unknown);
        assert_eq!(g.transform, Transform::identity());
        assert_eq!(
            g.tree.active_voxel_count(),
            if g.name == "topology" { 662 } else { 812 },
            "{}",
            g.name
        );
    }
    let (
        GridTree::Double(d),
        GridTree::Int32(i),
        GridTree::Int64(l),
        GridTree::Vec3d(v),
        GridTree::Mask(m),
    ) = (
        &grids[0].tree,
        &grids[1].tree,
        &grids[2].tree,
        &grids[3].tree,
        &grids[4].tree,
    )
    else {
        panic!("unexpected tree types")
    };
    assert_eq!(
        (
            d.background(),
            i.background(),
            l.background(),
            v.background()
        ),
        (-1.0, -1, -1, [0.0; 3])
    );
    for x in 0..10 {
        for y in 0..6 {
            for z in 0..5 {
                let c = Coord::new(x, y, z);
                let (xf, yf, zf) = (x as f64, y as f64, z as f64);
                assert_eq!(
                    d.probe(c),
                    (300.0 + xf * 0.1 + yf * 0.01 + zf * 0.001, true, Level::Leaf)
                );
                assert_eq!(
                    i.probe(c),
                    (x * 10000 + y * 100 + z - 5000, true, Level::Leaf)
                );
                assert_eq!(
                    l.probe(c),
                    (
                        (1i64 << 40) + x as i64 * 1_000_000 + y as i64 * 1000 + z as i64,
                        true,
                        Level::Leaf
                    )
                );
                assert_eq!(
                    v.probe(c),
                    ([xf * 0.5, yf * 0.25, -zf * 2.0], true, Level::Leaf)
                );
                let on = (x + y + z) % 2 == 0;
                assert_eq!(m.probe(c), (on, on, Level::Leaf));
            }
        }
    }
    for c in [tile.min, tile.max, Coord::new(20, 3, 5)] {
        assert_eq!(d.probe(c), (2.5, true, Level::Lower));
        assert_eq!(i.probe(c), (7, true, Level::Lower));
        assert_eq!(l.probe(c), (1i64 << 50, true, Level::Lower));
        assert_eq!(v.probe(c), ([1.0, -2.0, 3.0], true, Level::Leaf)); // written voxel by voxel
        assert_eq!(m.probe(c), (true, true, Level::Lower));
    }
    assert_eq!(d.probe(Coord::new(9, 9, 9)), (42.0, false, Level::Leaf));
    assert_eq!(i.probe(Coord::new(9, 9, 9)), (42, false, Level::Leaf));
    assert_eq!(d.probe(Coord::new(40, 0, 0)), (-1.0, false, Level::Lower));
    assert_eq!(
        m.probe(Coord::new(-8, 0, 0)),
        (false, false, Level::Background)
    );
}
