//! The NanoVDB reader against files written by NanoVDB 32.4.2's own tools
//! (tests/fixtures, made by tools/make_nvdb_fixtures.sh): counts as
//! `nanovdb_print` reports them, values as pyopenvdb reads the source .vdb
//! files (expected.json), transforms, the newer (32.6+) file layouts, and
//! corrupt files.

use cirrus_vdb::*;
use glam::DVec3;
use serde_json::Value as Json;
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn expected(grid: &str) -> Json {
    let text = std::fs::read_to_string(fixture("expected.json")).unwrap();
    let all: Json = serde_json::from_str(&text).unwrap();
    all[grid].clone()
}

/// A scratch file holding `bytes`, removed on drop.
struct Scratch(PathBuf);
impl Scratch {
    fn new(tag: &str, bytes: &[u8]) -> Scratch {
        let p = std::env::temp_dir().join(format!("cirrus-nvdb-{}-{tag}.nvdb", std::process::id()));
        std::fs::write(&p, bytes).unwrap();
        Scratch(p)
    }
    fn path(&self) -> &Path {
        &self.0
    }
}
impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn open_and_read_all(path: &Path) -> Result<Vec<Grid>> {
    let file = VolumeFile::open(path)?;
    (0..file.grids().len()).map(|i| file.read_grid(i)).collect()
}

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

// ---------------------------------------------------------------------------
// Newer layouts: NanoVDB 32.6+ (OpenVDB 11+) "NanoVDB2" segments, "NanoVDB1"
// grid buffers and raw grid-buffer files, built here from 32.4.2 files.

fn read(name: &str) -> Vec<u8> {
    std::fs::read(fixture(name)).unwrap()
}

/// Offsets of each segment's header and of its grids' metadata, walking the file.
fn segments(bytes: &[u8]) -> Vec<(usize, Vec<usize>)> {
    let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    let (mut pos, mut out) = (0, Vec::new());
    while pos < bytes.len() {
        let count = u16::from_le_bytes([bytes[pos + 12], bytes[pos + 13]]) as usize;
        let (mut at, mut metas, mut data) = (pos + 16, Vec::new(), 0);
        for _ in 0..count {
            metas.push(at);
            data += u64_at(at + 8) as usize;
            at += 176 + u32_at(at + 136) as usize;
        }
        out.push((pos, metas));
        pos = at + data;
    }
    out
}

const V32_7_0: u32 = (32 << 21) | (7 << 10);

/// Rewrites a 32.4 file as a 32.7 writer built with `NANOVDB_USE_NEW_MAGIC_NUMBERS`
/// writes it: FileHeader magic "NanoVDB2" and version 32.7.0, FileMetaData version
/// 32.7.0 and no name hash (FileGridMetaData leaves nameKey 0), and for
/// uncompressed grids the grid magic "NanoVDB1". FileHeader (16 bytes) and
/// FileMetaData (176 bytes) are otherwise laid out as in 32.4 (NanoVDB.h, 32.7).
fn to_v32_7(mut bytes: Vec<u8>) -> Vec<u8> {
    for (seg, metas) in segments(&bytes) {
        let codec = u16::from_le_bytes([bytes[seg + 14], bytes[seg + 15]]);
        bytes[seg..seg + 8].copy_from_slice(b"NanoVDB2");
        bytes[seg + 8..seg + 12].copy_from_slice(&V32_7_0.to_le_bytes());
        let name_size =
            |m: usize| u32::from_le_bytes(bytes[m + 136..m + 140].try_into().unwrap()) as usize;
        let mut data = metas.last().map_or(seg + 16, |&m| m + 176 + name_size(m));
        for m in metas {
            bytes[m + 16..m + 24].fill(0);
            bytes[m + 172..m + 176].copy_from_slice(&V32_7_0.to_le_bytes());
            if codec == 0 {
                bytes[data..data + 8].copy_from_slice(b"NanoVDB1");
                bytes[data + 16..data + 20].copy_from_slice(&V32_7_0.to_le_bytes());
            }
            data += u64::from_le_bytes(bytes[m + 8..m + 16].try_into().unwrap()) as usize;
        }
    }
    bytes
}

fn assert_same_trees<V: Value>(a: &Tree<V>, b: &Tree<V>) {
    assert_eq!(a.background(), b.background());
    assert_eq!(a.root_entries(), b.root_entries());
    assert_eq!(a.leaf_count(), b.leaf_count());
    for (x, y) in a.leaves().iter().zip(b.leaves()) {
        assert_eq!((x.origin, &x.value_mask), (y.origin, &y.value_mask));
        assert!(x.values.iter().zip(y.values.iter()).all(|(p, q)| p == q));
    }
    for (x, y) in a.upper_nodes().iter().zip(b.upper_nodes()) {
        assert_eq!(
            (
                x.origin,
                &x.child_mask,
                &x.value_mask,
                &x.children,
                &x.tiles
            ),
            (
                y.origin,
                &y.child_mask,
                &y.value_mask,
                &y.children,
                &y.tiles
            )
        );
    }
    for (x, y) in a.lower_nodes().iter().zip(b.lower_nodes()) {
        assert_eq!(
            (
                x.origin,
                &x.child_mask,
                &x.value_mask,
                &x.children,
                &x.tiles
            ),
            (
                y.origin,
                &y.child_mask,
                &y.value_mask,
                &y.children,
                &y.tiles
            )
        );
    }
}

fn assert_same_grids(a: &[Grid], b: &[Grid]) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!(
            (&x.name, x.class, x.transform, x.half_float),
            (&y.name, y.class, y.transform, y.half_float)
        );
        match (&x.tree, &y.tree) {
            (GridTree::Float(p), GridTree::Float(q)) => assert_same_trees(p, q),
            (GridTree::Double(p), GridTree::Double(q)) => assert_same_trees(p, q),
            (GridTree::Int32(p), GridTree::Int32(q)) => assert_same_trees(p, q),
            (GridTree::Int64(p), GridTree::Int64(q)) => assert_same_trees(p, q),
            (GridTree::Bool(p), GridTree::Bool(q)) | (GridTree::Mask(p), GridTree::Mask(q)) => {
                assert_same_trees(p, q)
            }
            (GridTree::Vec3f(p), GridTree::Vec3f(q)) => assert_same_trees(p, q),
            (GridTree::Vec3d(p), GridTree::Vec3d(q)) => assert_same_trees(p, q),
            _ => panic!("{}: tree types differ", x.name),
        }
    }
}

#[test]
fn nanovdb2_segments_read_as_their_nanovdb0_originals() {
    for name in [
        "fog.nvdb",
        "fog_fp16_zip.nvdb",
        "vec3f_blosc.nvdb",
        "multi_zip.nvdb",
        "typed_zip.nvdb",
    ] {
        let old = read(name);
        let new = to_v32_7(old.clone());
        assert_eq!(&new[..8], b"NanoVDB2");
        let scratch = Scratch::new(&format!("v2-{name}"), &new);
        let a = open_and_read_all(&fixture(name)).unwrap();
        let b = open_and_read_all(scratch.path()).unwrap();
        assert_same_grids(&a, &b);
        let infos_a: Vec<GridInfo> = VolumeFile::open(fixture(name))
            .unwrap()
            .grids()
            .into_iter()
            .cloned()
            .collect();
        let infos_b: Vec<GridInfo> = VolumeFile::open(scratch.path())
            .unwrap()
            .grids()
            .into_iter()
            .cloned()
            .collect();
        assert_eq!(infos_a, infos_b);
    }
    let fog = to_v32_7(read("fog.nvdb"));
    assert_eq!(&fog[200..208], b"NanoVDB1");
    let g = open_and_read_all(Scratch::new("v2-meta", &fog).path()).unwrap();
    assert_eq!(
        meta_get(&g[0].metadata, "nanovdb_version").and_then(|v| v.as_str()),
        Some("32.7.0")
    );
}

#[test]
fn raw_grid_buffers_and_concatenated_files() {
    let fog = read("fog.nvdb");
    let buffer = &fog[200..];
    let original = open_and_read_all(&fixture("fog.nvdb")).unwrap();
    // A bare grid buffer (32.6+ handle.write), with the old and the new grid magic.
    for magic in [b"NanoVDB0", b"NanoVDB1"] {
        let mut raw = buffer.to_vec();
        raw[..8].copy_from_slice(magic);
        let scratch = Scratch::new(&format!("raw-{}", magic[7] as char), &raw);
        let file = VolumeFile::open(scratch.path()).unwrap();
        let info = file.grids()[0].clone();
        assert_eq!(
            (info.name.as_str(), info.type_name.as_str(), info.byte_len),
            ("density", "Float", raw.len() as u64)
        );
        assert_same_grids(&original, &[file.read_grid(0).unwrap()]);
    }
    // Segments and raw buffers one after another; duplicate names get OpenVDB-style suffixes.
    let mut cat = fog.clone();
    cat.extend_from_slice(&read("vec3f_blosc.nvdb"));
    cat.extend_from_slice(buffer);
    let scratch = Scratch::new("concat", &cat);
    let file = VolumeFile::open(scratch.path()).unwrap();
    let names: Vec<_> = file.grids().iter().map(|g| g.unique_name.clone()).collect();
    assert_eq!(names, ["density\u{1e}0", "velocity", "density\u{1e}1"]);
    assert_eq!(file.find_grid("density").unwrap(), 0);
    assert_eq!(file.find_grid("density\u{1e}1").unwrap(), 2);
    assert_eq!(file.read_grid(1).unwrap().name, "velocity");
    assert_same_grids(&original, &[file.read_grid(2).unwrap()]);
}

// ---------------------------------------------------------------------------
// Corrupt files: errors, never panics.

fn kind_of(r: Result<Vec<Grid>>) -> ErrorKind {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.kind,
    }
}

#[test]
fn truncated_files_are_errors() {
    let small = read("fog_fp16_zip.nvdb");
    for len in 0..small.len() {
        let s = Scratch::new("trunc-small", &small[..len]);
        let r = open_and_read_all(s.path());
        assert!(r.is_err(), "truncated to {len} bytes and still read");
    }
    let fog = read("fog.nvdb");
    for len in [
        8,
        15,
        16,
        100,
        191,
        192,
        199,
        200,
        872,
        1000,
        300_000,
        fog.len() - 1,
    ] {
        let s = Scratch::new("trunc-fog", &fog[..len]);
        match kind_of(open_and_read_all(s.path())) {
            ErrorKind::Truncated { .. } => {}
            k => panic!("truncated to {len}: {k}"),
        }
    }
}

fn mutated(bytes: &[u8], at: usize, patch: &[u8]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    b[at..at + patch.len()].copy_from_slice(patch);
    b
}

#[test]
fn mutated_headers_give_clear_errors() {
    let fog = read("fog.nvdb");
    let zip = read("fog_fp16_zip.nvdb");
    let check = |bytes: Vec<u8>, want: &dyn Fn(&ErrorKind) -> bool, what: &str| {
        let s = Scratch::new("mut", &bytes);
        let k = kind_of(open_and_read_all(s.path()));
        assert!(want(&k), "{what}: got {k}");
    };
    let unsupported = |text: &'static str| move |k: &ErrorKind| matches!(k, ErrorKind::Unsupported(m) if m.contains(text));
    let corrupt = |k: &ErrorKind| matches!(k, ErrorKind::Corrupt(_));
    check(
        mutated(&fog, 0, b"NanoVDBX"),
        &|k| matches!(k, ErrorKind::BadMagic(_)),
        "magic",
    );
    // a pre-32 version (major 31) in the segment header
    check(
        mutated(&fog, 8, &((31u32 << 21) | (2 << 10)).to_le_bytes()),
        &unsupported("31.2.0"),
        "old version",
    );
    check(
        mutated(&zip, 14, &7u16.to_le_bytes()),
        &unsupported("codec 7"),
        "codec",
    );
    check(
        mutated(&fog, 16, &u64::MAX.to_le_bytes()),
        &corrupt,
        "grid size",
    );
    check(
        mutated(&fog, 16, &8u64.to_le_bytes()),
        &corrupt,
        "tiny grid size",
    );
    check(
        mutated(&fog, 24, &(1u64 << 40).to_le_bytes()),
        &|k| matches!(k, ErrorKind::Truncated { .. }),
        "file size",
    );
    check(
        mutated(&fog, 16 + 136, &u32::MAX.to_le_bytes()),
        &|k| matches!(k, ErrorKind::Truncated { .. }),
        "name size",
    );
    check(
        mutated(&fog, 16 + 32, &2u32.to_le_bytes()),
        &corrupt,
        "metadata type disagrees with the grid",
    );
    // The grid: magic, version, size, type.
    check(mutated(&fog, 200, b"NanoVDBZ"), &corrupt, "grid magic");
    check(
        mutated(&fog, 216, &(33u32 << 21).to_le_bytes()),
        &unsupported("33.0.0"),
        "grid version",
    );
    check(
        mutated(&fog, 232, &5u64.to_le_bytes()),
        &corrupt,
        "grid size field",
    );
    let half = mutated(
        &mutated(&fog, 16 + 32, &9u32.to_le_bytes()),
        200 + 636,
        &9u32.to_le_bytes(),
    );
    let s = Scratch::new("half", &half);
    let f = VolumeFile::open(s.path()).unwrap();
    assert_eq!(
        (f.grids()[0].type_name.as_str(), f.grids()[0].value_type),
        ("Half", None)
    );
    assert!(
        matches!(f.read_grid(0).unwrap_err().kind, ErrorKind::Unsupported(m) if m == "NanoVDB grid type Half")
    );
    // Trailing bytes that are not a segment.
    let mut tail = fog.clone();
    tail.extend_from_slice(&[0u8; 40]);
    check(tail, &corrupt, "trailing garbage");
}

/// Every byte of the headers and the start of the grid flipped three ways:
/// whatever happens, no panic, and a file that still opens lists one grid.
#[test]
fn byte_flips_in_headers_never_panic() {
    let zip = read("fog_fp16_zip.nvdb");
    for at in 0..300 {
        for f in [0x00u8, 0xff, 0x80] {
            let mut b = zip.clone();
            b[at] = if f == 0x80 { b[at] ^ f } else { f };
            let s = Scratch::new("flip", &b);
            if let Ok(file) = VolumeFile::open(s.path()) {
                for i in 0..file.grids().len() {
                    let _ = file.read_grid(i);
                }
            }
        }
    }
}
