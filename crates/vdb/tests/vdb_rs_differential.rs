//! Differential check against vdb-rs 0.6 on the corpus files it reads
//! correctly: full-precision float grids with uniform-scale or
//! scale-translate maps (crates.md lists what it misreads). Every active
//! voxel and active internal tile it reports must match our tree's value and
//! state, and the counts must agree.

use cirrus_vdb::{Coord, GridTree, Level, MapKind, VolumeFile};
use std::fs::File;
use std::io::BufReader;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

#[test]
fn our_trees_match_vdb_rs_voxel_for_voxel() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data");
    let mut entries: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    let (mut grids_compared, mut voxels_compared) = (0, 0u64);
    for path in entries
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "vdb"))
    {
        let Ok(file) = VolumeFile::open(path) else {
            continue;
        };
        for (i, info) in file.grids().into_iter().enumerate() {
            let Ok(grid) = file.read_grid(i) else {
                continue;
            };
            let GridTree::Float(tree) = &grid.tree else {
                continue;
            };
            let readable_map = matches!(
                grid.transform.kind,
                MapKind::UniformScale | MapKind::UniformScaleTranslate | MapKind::ScaleTranslate
            );
            let has_root_tiles = tree.active_tile_counts().root > 0;
            if info.half_float || !readable_map || has_root_tiles || info.unique_name != info.name {
                continue;
            }
            // vdb-rs aborts or panics on some inputs; a file it cannot read is not compared.
            let theirs = catch_unwind(AssertUnwindSafe(|| {
                let mut r =
                    vdb_rs::VdbReader::new(BufReader::new(File::open(path).unwrap())).ok()?;
                let g = r.read_grid::<f32>(&info.name).ok()?;
                Some(
                    g.iter()
                        .map(|(p, v, level)| (p.to_array().map(|x| x as i32), v, level))
                        .collect::<Vec<_>>(),
                )
            }));
            let Ok(Some(theirs)) = theirs else { continue };
            let mut acc = tree.accessor();
            let mut voxels = 0u64;
            for (p, v, level) in &theirs {
                let c = Coord::new(p[0], p[1], p[2]);
                let (ours, active, our_level) = tree.probe(c);
                let expected_level = match level {
                    vdb_rs::VdbLevel::Voxel => Level::Leaf,
                    vdb_rs::VdbLevel::Node3 => Level::Lower,
                    vdb_rs::VdbLevel::Node4 => Level::Upper,
                };
                assert!(active && same(ours, *v) && our_level == expected_level,
                    "{}:{} at {c:?}: ours {ours} (active {active}, {our_level:?}), vdb-rs {v} ({expected_level:?})",
                    path.display(), info.name);
                assert!(same(acc.get(c), ours));
                if our_level == Level::Leaf {
                    voxels += 1;
                }
            }
            let our_voxels: u64 = tree
                .leaves()
                .iter()
                .map(|l| l.value_mask.count_on() as u64)
                .sum();
            let tiles = tree.active_tile_counts();
            assert_eq!(voxels, our_voxels, "{}: leaf voxel count", path.display());
            assert_eq!(
                theirs.len() as u64 - voxels,
                tiles.lower + tiles.upper,
                "{}: tile count",
                path.display()
            );
            grids_compared += 1;
            voxels_compared += voxels;
        }
    }
    eprintln!("compared {grids_compared} grids, {voxels_compared} voxels with vdb-rs");
    assert!(
        grids_compared >= 8,
        "only {grids_compared} grids were comparable with vdb-rs"
    );
}
