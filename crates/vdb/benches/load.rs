//! Load time of a large fog volume: cirrus against `vdb_print -l` (Debian's
//! OpenVDB, which reads and measures every voxel) and vdb-rs, on the same
//! file in the same run, printed as ratios. Machines here are shared and
//! noisy, so each figure is the best of several runs.
//!
//! `cargo bench -p cirrus-vdb --bench load [-- FILE.vdb]`; without a file it
//! makes `target/large.vdb` with `tools/make_large.py` (tens of millions of
//! active voxels, not committed).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const RUNS: usize = 3;

fn best_of(mut f: impl FnMut()) -> f64 {
    (0..RUNS)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn large_file() -> PathBuf {
    if let Some(arg) = std::env::args().skip(1).find(|a| !a.starts_with('-')) {
        return PathBuf::from(arg);
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let path = root.join("target/large.vdb");
    if !path.exists() {
        eprintln!("making {} with tools/make_large.py ...", path.display());
        let ok = Command::new("/usr/bin/python3")
            .arg(root.join("tools/make_large.py"))
            .arg(&path)
            .status()
            .is_ok_and(|s| s.success());
        assert!(
            ok,
            "tools/make_large.py failed (it needs Debian's python3-openvdb)"
        );
    }
    path
}

fn main() {
    let path = large_file();
    let file = cirrus_vdb::VolumeFile::open(&path).expect("open");
    let index = file.find_grid("density").unwrap_or(0);
    let name = file.grids()[index].name.clone();
    let mut voxels = 0;
    let ours = best_of(|| {
        let f = cirrus_vdb::VolumeFile::open(&path).unwrap();
        let g = f.read_grid(index).unwrap();
        voxels = g.tree.active_voxel_count();
    });
    // The same work as vdb_print -l: load, then count voxels and the value range.
    let ours_stats = best_of(|| {
        let f = cirrus_vdb::VolumeFile::open(&path).unwrap();
        let g = f.read_grid(index).unwrap();
        std::hint::black_box((
            g.tree.active_voxel_count(),
            g.tree.value_range(),
            g.tree.active_bbox(),
        ));
    });
    // The same figures streamed: topology, then leaf buffers decoded in
    // parallel into a range per chunk, no tree (what `cirrus info --stats` does).
    let streamed = best_of(|| {
        let f = cirrus_vdb::VolumeFile::open(&path).unwrap();
        let s = f.stream_grid::<f32>(index).unwrap();
        let ranges = std::sync::Mutex::new(Vec::new());
        s.decode_leaves(Range(f32::INFINITY, f32::NEG_INFINITY, &ranges))
            .map_err(|_| ())
            .unwrap();
        std::hint::black_box(ranges.into_inner().unwrap());
    });
    let vdb_print = best_of(|| {
        let out = Command::new("vdb_print")
            .arg("-l")
            .arg(&path)
            .output()
            .expect("vdb_print (apt install libopenvdb-tools)");
        assert!(out.status.success());
    });
    let vdb_rs = best_of(|| {
        let mut r =
            vdb_rs::VdbReader::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()))
                .unwrap();
        let g = r.read_grid::<f32>(&name).unwrap();
        std::hint::black_box(g.iter().count());
    });
    println!(
        "file {} ({} MB, {} active voxels, {} threads)",
        path.display(),
        std::fs::metadata(&path).unwrap().len() / 1_000_000,
        voxels,
        rayon::current_num_threads()
    );
    println!("  cirrus load                 {ours:.3} s");
    println!(
        "  cirrus load + stats         {ours_stats:.3} s  = {:.2} x vdb_print -l",
        ours_stats / vdb_print
    );
    println!(
        "  cirrus stream + stats       {streamed:.3} s  = {:.2} x vdb_print -l",
        streamed / vdb_print
    );
    println!("  vdb_print -l                {vdb_print:.3} s");
    println!(
        "  vdb-rs load + iterate       {vdb_rs:.3} s  -> cirrus is {:.2} x faster",
        vdb_rs / ours_stats
    );
}

/// Minimum and maximum of the active values of a run of leaves.
struct Range<'a>(f32, f32, &'a std::sync::Mutex<Vec<(f32, f32)>>);

impl cirrus_vdb::LeafSink<f32> for Range<'_> {
    type Error = ();
    fn split_front(&mut self, _: usize) -> Self {
        Range(f32::INFINITY, f32::NEG_INFINITY, self.2)
    }
    fn leaf(
        &mut self,
        _: usize,
        mask: &cirrus_vdb::BitMask<8>,
        values: &[f32; 512],
    ) -> Result<(), ()> {
        for n in mask.iter_on() {
            self.0 = self.0.min(values[n]);
            self.1 = self.1.max(values[n]);
        }
        Ok(())
    }
    fn finish(self) {
        self.2.lock().unwrap().push((self.0, self.1));
    }
}
