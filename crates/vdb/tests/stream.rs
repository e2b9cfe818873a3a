//! Streaming a grid (topology, then leaves decoded in parallel chunks)
//! gives exactly what reading it whole gives: the same leaves in the same
//! order with the same masks and values bit for bit, the same tiles,
//! counts, bounds and memory figure; and bad input is an error naming the
//! file, never a panic.

use cirrus_testkit::{mutate_past_header, SplitMix64};
use cirrus_vdb::{
    BitMask, DecodeError, Format, GridTree, LeafSink, Tree, Value, ValueType, VolumeFile,
};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

fn corpus() -> Vec<PathBuf> {
    cirrus_testkit::corpus(&["vdb"], None)
}

/// Leaves by index: mask and values.
type Leaves<V> = Mutex<Vec<Option<(BitMask<8>, Vec<V>)>>>;

/// Collects every leaf it is given, by index, from whatever thread.
struct Collect<'a, V> {
    out: &'a Leaves<V>,
    parts: &'a Mutex<Vec<(usize, usize)>>,
    first: usize,
    len: usize,
}

impl<V: Value> LeafSink<V> for Collect<'_, V> {
    type Error = String;
    fn split_front(&mut self, n: usize) -> Self {
        assert!(n > 0 && n <= self.len, "split of {n} from {}", self.len);
        let part = Collect {
            out: self.out,
            parts: self.parts,
            first: self.first,
            len: n,
        };
        self.first += n;
        self.len -= n;
        part
    }
    fn leaf(&mut self, index: usize, mask: &BitMask<8>, values: &[V; 512]) -> Result<(), String> {
        assert!(index >= self.first && index < self.first + self.len);
        let mut out = self.out.lock().unwrap();
        assert!(out[index].is_none(), "leaf {index} twice");
        out[index] = Some((mask.clone(), values.to_vec()));
        Ok(())
    }
    fn finish(self) {
        self.parts.lock().unwrap().push((self.first, self.len));
    }
}

fn bits<V: Value>(v: V) -> Vec<u64> {
    let (c, n) = v.components();
    c[..n].iter().map(|x| x.to_bits()).collect()
}

/// Streams grid `i` as `V` and compares it with the tree read whole.
fn compare<V: Value>(file: &VolumeFile, i: usize, tree: &Tree<V>, at: &str) -> usize {
    let stream = file
        .stream_grid::<V>(i)
        .unwrap_or_else(|e| panic!("{at}: {e}"));
    let topo = &stream.topology;
    assert_eq!(topo.active_voxels, tree.active_voxel_count(), "{at}");
    assert_eq!(topo.active_bbox, tree.active_bbox(), "{at}");
    assert_eq!(topo.tile_counts(), tree.active_tile_counts(), "{at}");
    assert_eq!(topo.memory_bytes(), tree.memory_bytes(), "{at}");
    assert_eq!(bits(topo.background), bits(tree.background()), "{at}");
    let mut tiles = Vec::new();
    tree.for_each_active_tile(|b, v, l| tiles.push((b, bits(v), l)));
    let mut ours: Vec<_> = topo
        .tiles
        .iter()
        .map(|t| (t.bbox, bits(t.value), t.level))
        .collect();
    let key = |t: &(cirrus_vdb::CoordBBox, Vec<u64>, cirrus_vdb::Level)| t.0.min.to_array();
    tiles.sort_by_key(key);
    ours.sort_by_key(key);
    assert_eq!(ours, tiles, "{at}: tiles");
    let origins: Vec<_> = tree.leaves().iter().map(|l| l.origin).collect();
    assert_eq!(topo.leaf_origins, origins, "{at}: leaf order");
    let n = origins.len();
    let out = Mutex::new(vec![None; n]);
    let parts = Mutex::new(Vec::new());
    stream
        .decode_leaves(Collect {
            out: &out,
            parts: &parts,
            first: 0,
            len: n,
        })
        .unwrap_or_else(|e| match e {
            DecodeError::File(e) => panic!("{at}: {e}"),
            DecodeError::Sink(e) => panic!("{at}: {e}"),
        });
    let out = out.into_inner().unwrap();
    let mut parts = parts.into_inner().unwrap();
    parts.sort();
    let covered: usize = parts.iter().map(|p| p.1).sum();
    assert_eq!(covered, n, "{at}: parts cover every leaf once");
    for (k, (leaf, got)) in tree.leaves().iter().zip(out).enumerate() {
        let (mask, values) = got.unwrap_or_else(|| panic!("{at}: leaf {k} never came"));
        assert_eq!(mask, leaf.value_mask, "{at}: leaf {k} mask");
        for (n, (a, b)) in values.iter().zip(leaf.values.iter()).enumerate() {
            assert_eq!(bits(*a), bits(*b), "{at}: leaf {k} voxel {n}");
        }
    }
    n
}

#[test]
fn streamed_grids_equal_the_grids_read_whole() {
    let mut leaves = 0;
    let mut grids = 0;
    for path in corpus() {
        let file = VolumeFile::open(&path).unwrap();
        for (i, info) in file.grids().iter().enumerate() {
            let at = format!(
                "{}:{}",
                path.file_name().unwrap().to_string_lossy(),
                info.name
            );
            let Ok(grid) = file.read_grid(i) else {
                assert!(file.stream_grid::<f32>(i).is_err(), "{at}");
                continue;
            };
            leaves += match &grid.tree {
                GridTree::Float(t) => compare(&file, i, t, &at),
                GridTree::Double(t) => compare(&file, i, t, &at),
                GridTree::Int32(t) => compare(&file, i, t, &at),
                GridTree::Int64(t) => compare(&file, i, t, &at),
                GridTree::Vec3f(t) => compare(&file, i, t, &at),
                GridTree::Vec3d(t) => compare(&file, i, t, &at),
                GridTree::Bool(_) | GridTree::Mask(_) => {
                    let e = file.stream_grid::<bool>(i).err().unwrap();
                    assert!(e.to_string().contains("streaming"), "{at}: {e}");
                    continue;
                }
            };
            grids += 1;
            // The wrong value type is refused, naming the file.
            if grid.tree.value_type() != ValueType::Double {
                let e = file.stream_grid::<f64>(i).err().unwrap();
                assert!(e
                    .to_string()
                    .contains(path.file_name().unwrap().to_str().unwrap()));
            }
        }
    }
    assert!(grids >= 30, "{grids} grids");
    assert!(leaves > 5000, "{leaves} leaves");
}

#[test]
fn grid_headers_are_read_without_the_tree() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/cloud.vdb");
    let file = VolumeFile::open(&path).unwrap();
    let before = file.bytes_read();
    let h = file.grid_header(0).unwrap().unwrap();
    // The header is 9.6 KB, 9.2 of them OpenVDB's per-leaf delayed-load
    // record, skipped unread; the tree is 4.6 MB.
    assert!(
        file.bytes_read() - before <= 8192,
        "{} bytes",
        file.bytes_read() - before
    );
    let grid = file.read_grid(0).unwrap();
    assert_eq!(h.class, grid.class);
    assert_eq!(h.transform, grid.transform);
    assert_eq!(h.metadata, grid.metadata);
    assert_eq!(h.background, Some(grid.tree.background_components()));
    let nvdb = VolumeFile::open(path.with_extension("").with_file_name("sphere_fog.nvdb")).unwrap();
    assert_eq!(nvdb.format(), Format::NanoVdb);
    assert!(nvdb.grid_header(0).unwrap().is_none());
    assert!(nvdb.stream_grid::<f32>(0).is_err());
}

/// Counts leaves and nothing else.
struct Count;
impl LeafSink<f32> for Count {
    type Error = ();
    fn split_front(&mut self, _: usize) -> Self {
        Count
    }
    fn leaf(&mut self, _: usize, _: &BitMask<8>, _: &[f32; 512]) -> Result<(), ()> {
        Ok(())
    }
}

#[test]
fn mutated_files_stream_to_errors_naming_the_file_never_panics() {
    let files: Vec<PathBuf> = corpus()
        .into_iter()
        .filter(|p| {
            std::fs::metadata(p)
                .map(|m| m.len() < 400_000)
                .unwrap_or(false)
        })
        .collect();
    let dir = std::env::temp_dir().join(format!("cirrus-stream-mut-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = SplitMix64(99);
    let (mut errors, mut loaded) = (0, 0);
    for round in 0..3000 {
        let src = &files[rng.below(files.len())];
        let mut bytes = std::fs::read(src).unwrap();
        // Mutate past the header, where the trees are.
        mutate_past_header(&mut rng, &mut bytes, 4);
        let path = dir.join(format!("m{round}.vdb"));
        std::fs::write(&path, &bytes).unwrap();
        let result = catch_unwind(AssertUnwindSafe(|| -> Result<(), String> {
            let f = VolumeFile::open(&path).map_err(|e| e.to_string())?;
            for i in 0..f.grids().len() {
                if f.grids()[i].value_type != Some(ValueType::Float) {
                    continue;
                }
                let s = f.stream_grid::<f32>(i).map_err(|e| e.to_string())?;
                s.decode_leaves(Count).map_err(|e| match e {
                    DecodeError::File(e) => e.to_string(),
                    DecodeError::Sink(()) => unreachable!(),
                })?;
            }
            Ok(())
        }));
        match result {
            Ok(Ok(())) => loaded += 1,
            Ok(Err(msg)) => {
                assert!(msg.contains(&format!("m{round}.vdb")), "{msg}");
                errors += 1;
            }
            Err(_) => panic!("streaming a mutation of {} panicked", src.display()),
        }
        let _ = std::fs::remove_file(&path);
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        errors > 500 && loaded > 100,
        "{errors} errors, {loaded} loaded"
    );
}
