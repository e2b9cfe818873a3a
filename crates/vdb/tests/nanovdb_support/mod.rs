//! Helpers shared by the NanoVDB tests: fixture paths and scratch files.
#![allow(dead_code)]

use cirrus_vdb::{Grid, Result, VolumeFile};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

pub fn expected(grid: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(fixture("expected.json")).unwrap();
    let all: serde_json::Value = serde_json::from_str(&text).unwrap();
    all[grid].clone()
}

/// A scratch file holding `bytes`, removed on drop.
pub struct Scratch(PathBuf);
impl Scratch {
    pub fn new(tag: &str, bytes: &[u8]) -> Scratch {
        static COUNT: AtomicUsize = AtomicUsize::new(0);
        let n = COUNT.fetch_add(1, Ordering::Relaxed);
        let name = format!("cirrus-nvdb-{}-{n}-{tag}.nvdb", std::process::id());
        let p = std::env::temp_dir().join(name);
        std::fs::write(&p, bytes).unwrap();
        Scratch(p)
    }
    pub fn path(&self) -> &Path {
        &self.0
    }
}
impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

pub fn open_and_read_all(path: &Path) -> Result<Vec<Grid>> {
    let file = VolumeFile::open(path)?;
    (0..file.grids().len()).map(|i| file.read_grid(i)).collect()
}

pub fn read(name: &str) -> Vec<u8> {
    std::fs::read(fixture(name)).unwrap()
}
