use cirrus_vdb::*;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

#[test]
fn smoke() {
    for f in ["fog.nvdb", "fog_fp16_zip.nvdb", "fog_fp8_blosc.nvdb", "fog_fp4_zip.nvdb", "fog_fpN_zip.nvdb", "vec3f_blosc.nvdb", "multi_zip.nvdb", "typed_zip.nvdb"] {
        let file = VolumeFile::open(fixture(f)).unwrap();
        for (i, g) in file.grids().iter().enumerate() {
            let grid = file.read_grid(i).unwrap();
            println!("{f} {:?} -> voxels {} leaves {} tiles {:?} bg {:?} class {:?}", g, grid.tree.active_voxel_count(), grid.tree.leaf_count(), grid.tree.active_tile_counts(), grid.tree.background_components(), grid.class);
        }
    }
}
