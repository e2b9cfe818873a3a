//! Bad input: truncated, empty, random and randomly mutated files must all
//! give an error naming the file (or, for harmless mutations, load), never
//! a panic. An abort (an allocation the file cannot justify) would end the
//! test process, so it fails too.

use cirrus_testkit::SplitMix64;
use cirrus_vdb::VolumeFile;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

/// Mutations per run: at least 10,000 across the corpus.
const MUTATIONS: usize = 12_000;

/// Small files keep 12,000 loads fast; they cover every codec and layout.
fn corpus_files() -> Vec<PathBuf> {
    cirrus_testkit::corpus(&["vdb", "nvdb"], Some(400_000))
}

/// Opens and reads every grid; returns whether it loaded. Panics propagate.
fn load(path: &Path) -> Result<usize, String> {
    let f = VolumeFile::open(path).map_err(|e| e.to_string())?;
    for i in 0..f.grids().len() {
        f.read_grid(i).map_err(|e| e.to_string())?;
    }
    Ok(f.grids().len())
}

fn mutate(rng: &mut SplitMix64, bytes: &mut Vec<u8>) {
    match rng.below(6) {
        0 => {
            let i = rng.below(bytes.len());
            bytes[i] ^= 1 << rng.below(8);
        }
        1 => {
            for _ in 0..1 + rng.below(16) {
                let i = rng.below(bytes.len());
                bytes[i] = rng.next_u64() as u8;
            }
        }
        2 if bytes.len() >= 8 => {
            // A size or offset field gone wild.
            let i = rng.below(bytes.len().saturating_sub(8));
            let v = [u64::MAX, 1 << 40, 1 << 31, rng.next_u64(), 0][rng.below(5)];
            bytes[i..i + 8].copy_from_slice(&v.to_le_bytes());
        }
        3 => bytes.truncate(rng.below(bytes.len())),
        4 => {
            let i = rng.below(bytes.len());
            let n = 1 + rng.below(64);
            bytes.drain(i..(i + n).min(bytes.len()));
        }
        _ => {
            let i = rng.below(bytes.len());
            let fill: Vec<u8> = (0..1 + rng.below(64))
                .map(|_| rng.next_u64() as u8)
                .collect();
            bytes.splice(i..i, fill);
        }
    }
}

#[test]
fn mutated_corpus_files_error_cleanly_and_never_panic() {
    let files = corpus_files();
    assert!(
        files.len() >= 10,
        "expected the corpus in data/, found {} files",
        files.len()
    );
    let dir = std::env::temp_dir().join(format!("cirrus-mutations-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let target = dir.join("mutant.vdb");
    let mut rng = SplitMix64(0xC1_22_05);
    let (mut loaded, mut refused, mut panicked) = (0, 0, Vec::new());
    for k in 0..MUTATIONS {
        let src = &files[k % files.len()];
        let mut bytes = std::fs::read(src).unwrap();
        for _ in 0..1 + rng.below(3) {
            if !bytes.is_empty() {
                mutate(&mut rng, &mut bytes);
            }
        }
        std::fs::write(&target, &bytes).unwrap();
        match catch_unwind(AssertUnwindSafe(|| load(&target))) {
            Ok(Ok(_)) => loaded += 1,
            Ok(Err(msg)) => {
                assert!(
                    msg.contains("mutant.vdb"),
                    "error does not name the file: {msg}"
                );
                refused += 1
            }
            Err(_) => panicked.push(format!("mutation {k} of {}", src.display())),
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    eprintln!(
        "{MUTATIONS} mutations: {loaded} loaded, {refused} refused with an error, {} panicked",
        panicked.len()
    );
    assert!(panicked.is_empty(), "panics:\n{}", panicked.join("\n"));
    assert!(
        refused > MUTATIONS / 4,
        "only {refused} mutants were refused: the mutations are too gentle to test anything"
    );
}

#[test]
fn empty_random_and_truncated_files_are_clear_errors() {
    let dir = std::env::temp_dir().join(format!("cirrus-badfiles-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("bad.vdb");
    std::fs::write(&p, b"").unwrap();
    let e = VolumeFile::open(&p)
        .err()
        .expect("empty file must fail")
        .to_string();
    assert!(e.contains("bad.vdb") && e.contains("ends early"), "{e}");
    let mut rng = SplitMix64(42);
    let random: Vec<u8> = (0..4096).map(|_| rng.next_u64() as u8).collect();
    std::fs::write(&p, &random).unwrap();
    let e = VolumeFile::open(&p)
        .err()
        .expect("random bytes must fail")
        .to_string();
    assert!(e.contains("not an OpenVDB or NanoVDB file"), "{e}");
    let missing = dir.join("missing.vdb");
    let e = VolumeFile::open(&missing)
        .err()
        .expect("missing file must fail")
        .to_string();
    assert!(e.contains("missing.vdb"), "{e}");
    // Every prefix of a real file up to its first kilobyte, then coarser.
    for src in corpus_files().iter().take(6) {
        let bytes = std::fs::read(src).unwrap();
        let cuts: Vec<usize> = (0..bytes.len().min(1024))
            .chain((1024..bytes.len()).step_by(997))
            .collect();
        for cut in cuts {
            std::fs::write(&p, &bytes[..cut]).unwrap();
            match catch_unwind(AssertUnwindSafe(|| load(&p))) {
                Ok(Ok(_)) => panic!(
                    "{} truncated to {cut} of {} bytes loaded",
                    src.display(),
                    bytes.len()
                ),
                Ok(Err(_)) => {}
                Err(_) => panic!("{} truncated to {cut} bytes panicked", src.display()),
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
