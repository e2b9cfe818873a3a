//! `convert_file` (a .vdb streamed into bricks, never into the reader's
//! tree) against `convert` of the grid read whole, on every float grid of
//! the corpus: every codec (none, zip, blosc, active mask, half floats),
//! tiles at every level, NaN and negative values, transforms, empty grids.
//! The two `.cbrk` files must be the same bytes at every precision; f16
//! bricks must stay within f16's rounding of the f32 ones; what `convert`
//! refuses, `convert_file` refuses with the same words.

use cirrus_bricks::{convert, convert_file, write_cbrk, BrickError, BrickVolume, Precision};
use cirrus_testkit::{mutate_past_header, SplitMix64};
use cirrus_vdb::{ValueType, VolumeFile};
use glam::IVec3;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

fn corpus() -> Vec<PathBuf> {
    cirrus_testkit::corpus(&["vdb", "nvdb"], None)
}

fn cbrk_bytes(v: &BrickVolume, dir: &Path, name: &str) -> Vec<u8> {
    let path = dir.join(name);
    write_cbrk(v, &path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    bytes
}

/// f16's rounding of a density: half a unit in the last place of its
/// 11-bit significand, 2^-25 below 2^-14 (subnormals).
fn f16_bound(v: f32) -> f32 {
    (v.abs() * (-11f32).exp2()).max((-25f32).exp2())
}

#[test]
fn streamed_bricks_equal_bricks_from_the_tree_bit_for_bit() {
    let dir = std::env::temp_dir().join(format!("cirrus-stream-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (mut compared, mut refused, mut voxels) = (0, 0, 0u64);
    let mut files = std::collections::BTreeSet::new();
    for path in corpus() {
        let Ok(file) = VolumeFile::open(&path) else {
            continue;
        };
        for i in 0..file.grids().len() {
            let info = file.grids()[i].clone();
            let at = format!(
                "{}:{}",
                path.file_name().unwrap().to_string_lossy(),
                info.name
            );
            let whole = |p| {
                file.read_grid(i)
                    .map_err(BrickError::from)
                    .and_then(|g| convert(&g, p))
            };
            let f32s = match (
                whole(Precision::F32),
                convert_file(&file, i, Precision::F32),
            ) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(
                        cbrk_bytes(&a, &dir, "a.cbrk"),
                        cbrk_bytes(&b, &dir, "b.cbrk"),
                        "{at}: f32"
                    );
                    b
                }
                (Err(a), Err(b)) => {
                    assert_eq!(a.to_string(), b.to_string(), "{at}");
                    if info.value_type == Some(ValueType::Float) {
                        refused += 1;
                        files.insert(format!(
                            "refused {}",
                            path.file_name().unwrap().to_string_lossy()
                        ));
                    }
                    continue;
                }
                (a, b) => panic!("{at}: whole {:?}, streamed {:?}", a.err(), b.err()),
            };
            for p in [Precision::F16, Precision::U8] {
                let (a, b) = match (whole(p), convert_file(&file, i, p)) {
                    (Ok(a), Ok(b)) => (a, b),
                    (Err(a), Err(b)) => {
                        // Densities past f16's range (special_values.vdb).
                        assert!(matches!(b, BrickError::F16Overflow(_)), "{at}: {b}");
                        assert_eq!(a.to_string(), b.to_string(), "{at}");
                        continue;
                    }
                    (a, b) => panic!("{at} {p:?}: whole {:?}, streamed {:?}", a.err(), b.err()),
                };
                assert_eq!(
                    cbrk_bytes(&a, &dir, "a.cbrk"),
                    cbrk_bytes(&b, &dir, "b.cbrk"),
                    "{at}: {p:?}"
                );
                if p == Precision::F16 {
                    // Every voxel within f16's rounding of its f32 value.
                    let n = IVec3::from_array(b.dims.map(|d| d as i32)) * 8;
                    for x in 0..n.x {
                        for y in 0..n.y {
                            for z in 0..n.z {
                                let c = IVec3::new(x, y, z);
                                let (h, f) = (b.voxel(c), f32s.voxel(c));
                                assert!((h - f).abs() <= f16_bound(f), "{at} {c}: f16 {h} f32 {f}");
                                voxels += 1;
                            }
                        }
                    }
                    assert!(b.info.max_error <= f16_bound(f32s.max_density()), "{at}");
                }
            }
            compared += 1;
            files.insert(path.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(compared >= 25, "{compared} grids compared");
    // Every codec, half floats, tiles at each level, bad values, no voxels.
    for name in [
        "codec_none.vdb",
        "codec_zip.vdb",
        "codec_blosc.vdb",
        "codec_active.vdb",
        "half_none.vdb",
        "half_blosc.vdb",
        "half_active.vdb",
        "tile_box.vdb",
        "special_values.vdb",
        "empty_grid.vdb",
        "cloud.vdb",
        "xform_affine.vdb",
        "duplicate_names.vdb",
        "sphere_fog.nvdb",
    ] {
        assert!(files.contains(name), "{name} not compared");
    }
    // A 4096^3 root tile makes a brick map past the limit: both refuse it.
    assert!(files.contains("refused leaf_tiles.vdb"));
    assert!(refused >= 4, "{refused} float grids refused by both");
    assert!(voxels > 1_000_000, "{voxels} voxels compared at f16");
}

#[test]
fn refusals_name_the_grid_and_what_is_wrong() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data");
    let msg = |file: &str, grid: &str| {
        let f = VolumeFile::open(data.join(file)).unwrap();
        let i = f.find_grid(grid).unwrap();
        convert_file(&f, i, Precision::F16).unwrap_err().to_string()
    };
    assert!(msg("level_set_sphere.vdb", "surface").contains("level set"));
    assert!(msg("multi_grid.vdb", "temperature").contains("background 293"));
    assert!(msg("multi_grid.vdb", "velocity").contains("only float grids convert"));
    assert!(msg("other_types.vdb", "ids").contains("int32"));
}

#[test]
fn mutated_files_convert_or_fail_naming_the_file_never_panic() {
    let files: Vec<PathBuf> = corpus()
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "vdb"))
        .filter(|p| {
            std::fs::metadata(p)
                .map(|m| m.len() < 200_000)
                .unwrap_or(false)
        })
        .collect();
    let dir = std::env::temp_dir().join(format!("cirrus-stream-bricks-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = SplitMix64(5);
    let (mut errors, mut converted) = (0, 0);
    for round in 0..1500 {
        let src = &files[rng.below(files.len())];
        let mut bytes = std::fs::read(src).unwrap();
        mutate_past_header(&mut rng, &mut bytes, 3);
        let path = dir.join(format!("m{round}.vdb"));
        std::fs::write(&path, &bytes).unwrap();
        let result = catch_unwind(AssertUnwindSafe(|| -> Result<(), String> {
            let f = VolumeFile::open(&path).map_err(|e| e.to_string())?;
            for i in 0..f.grids().len() {
                convert_file(&f, i, Precision::F16).map_err(|e| e.to_string())?;
            }
            Ok(())
        }));
        match result {
            Ok(Ok(())) => converted += 1,
            Ok(Err(msg)) => {
                // The reader's errors name the file; the converter's name the grid.
                assert!(
                    msg.contains(&format!("m{round}.vdb"))
                        || msg.contains("grid")
                        || msg.contains("f16"),
                    "{msg}"
                );
                errors += 1;
            }
            Err(_) => panic!("converting a mutation of {} panicked", src.display()),
        }
        let _ = std::fs::remove_file(&path);
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        errors > 200 && converted > 50,
        "{errors} errors, {converted} converted"
    );
}
