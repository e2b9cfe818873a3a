//! NanoVDB file layouts newer than the 32.4.2 fixtures ("NanoVDB2" segments,
//! "NanoVDB1" grids, raw grid-buffer files), concatenated files, and corrupt
//! files: clear errors, never panics.

mod nanovdb_support;

use cirrus_vdb::*;
use nanovdb_support::*;

// ---------------------------------------------------------------------------
// Newer layouts: NanoVDB 32.6+ (OpenVDB 11+) "NanoVDB2" segments, "NanoVDB1"
// grid buffers and raw grid-buffer files, built here from 32.4.2 files.

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
