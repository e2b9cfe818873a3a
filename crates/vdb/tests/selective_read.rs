//! Only what is asked is read: opening reads the header and the grid index,
//! reading one grid reads that grid's bytes and nothing else.

use cirrus_vdb::VolumeFile;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(name)
}

#[test]
fn one_grid_of_a_four_grid_file_costs_its_own_bytes() {
    let multi = VolumeFile::open(data("multi_grid.vdb")).unwrap();
    assert_eq!(multi.grids().len(), 4);
    let index_bytes = multi.bytes_read();
    // Header, metadata and four descriptors: each descriptor costs one small window.
    assert!(index_bytes <= 8 * 1024, "opening read {index_bytes} bytes");
    let i = multi.find_grid("density").unwrap();
    let grid_bytes = multi.grids()[i].byte_len;
    multi.read_grid(i).unwrap();
    assert_eq!(
        multi.bytes_read() - index_bytes,
        grid_bytes,
        "reading density read other bytes too"
    );
    let others: u64 = multi
        .grids()
        .iter()
        .filter(|g| g.name != "density")
        .map(|g| g.byte_len)
        .sum();
    assert!(
        others > 50_000,
        "the other grids should be big enough to notice ({others} bytes)"
    );
    assert!(multi.bytes_read() + others <= multi.file_len() + 8 * 1024);

    // The same grid alone in its own file costs the same, within the index.
    let alone = VolumeFile::open(data("density_only.vdb")).unwrap();
    alone.read_grid_by_name("density").unwrap();
    let diff = multi.bytes_read().abs_diff(alone.bytes_read());
    assert!(
        diff <= 8 * 1024,
        "density from the 4-grid file read {} bytes, alone {}",
        multi.bytes_read(),
        alone.bytes_read()
    );
}

#[test]
fn nanovdb_segments_are_read_one_grid_at_a_time() {
    let f = VolumeFile::open(data("multi_grid.nvdb")).unwrap();
    let index_bytes = f.bytes_read();
    let n = f.grids().len();
    assert!(n >= 3, "{n} grids");
    let total: u64 = f.grids().iter().map(|g| g.byte_len).sum();
    assert!(
        index_bytes < f.file_len() / 10,
        "opening read {index_bytes} of {} bytes",
        f.file_len()
    );
    let i = f.find_grid("density").unwrap();
    f.read_grid(i).unwrap();
    let read = f.bytes_read() - index_bytes;
    assert!(
        read <= f.grids()[i].byte_len + 1024,
        "reading one grid read {read} bytes, its data is {}",
        f.grids()[i].byte_len
    );
    assert!(read < total, "reading one grid read as much as all of them");
}
