//! Every file of the corpus against the manifest that Debian's OpenVDB
//! tools wrote for it (`tools/make_corpus.py`): counts, bounds, transforms,
//! value ranges and sampled values must agree exactly (NanoVDB quantised
//! grids within the manifest's stated tolerance).
//!
//! The committed corpus is `data/`; CI also regenerates one with the Debian
//! tools and points `CIRRUS_CORPUS` at it, so the checks do not lean on
//! committed bytes alone.

use cirrus_vdb::{Coord, VolumeFile};
use serde_json::Value as Json;
use std::path::{Path, PathBuf};

fn corpus_dirs() -> Vec<PathBuf> {
    let mut dirs = vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")];
    if let Ok(extra) = std::env::var("CIRRUS_CORPUS") {
        dirs.push(PathBuf::from(extra));
    }
    dirs
}

/// A manifest number: a JSON number or "nan", "inf", "-inf".
fn number(j: &Json) -> Option<f64> {
    match j {
        Json::Number(n) => n.as_f64(),
        Json::String(s) => match s.as_str() {
            "nan" => Some(f64::NAN),
            "inf" => Some(f64::INFINITY),
            "-inf" => Some(f64::NEG_INFINITY),
            _ => None,
        },
        Json::Bool(b) => Some(*b as u8 as f64),
        _ => None,
    }
}

/// The components of a scalar or vector manifest value.
fn components(j: &Json) -> Vec<f64> {
    match j {
        Json::Array(a) => a.iter().filter_map(number).collect(),
        other => number(other).into_iter().collect(),
    }
}

fn same(a: f64, b: f64, tol: f64) -> bool {
    (a.is_nan() && b.is_nan()) || a == b || (a - b).abs() <= tol
}

/// For grids of f32 values: the manifest's decimal rounds to the same f32.
fn same_f32(ours: f64, theirs: f64, tol: f64) -> bool {
    same(ours, theirs as f32 as f64, tol)
}

struct Checker {
    failures: Vec<String>,
    checks: usize,
}

impl Checker {
    fn check(&mut self, ok: bool, what: impl FnOnce() -> String) {
        self.checks += 1;
        if !ok {
            self.failures.push(what());
        }
    }
}

fn check_file(c: &mut Checker, dir: &Path, entry: &Json) {
    let name = entry["file"]
        .as_str()
        .expect("manifest entry without a file");
    let path = dir.join(name);
    let opened = VolumeFile::open(&path).and_then(|f| {
        let grids: Vec<_> = (0..f.grids().len())
            .map(|i| f.read_grid(i))
            .collect::<Result<_, _>>()?;
        Ok((f, grids))
    });
    if let Some(expected) = entry.get("expect_error").and_then(|e| e.as_str()) {
        match opened {
            Ok(_) => c.check(false, || {
                format!("{name}: loaded, expected an error containing {expected:?}")
            }),
            Err(e) => {
                let msg = e.to_string();
                c.check(msg.contains(expected) && msg.contains(name), || {
                    format!("{name}: error {msg:?} lacks {expected:?} or the file name")
                });
            }
        }
        return;
    }
    let (file, grids) = match opened {
        Ok(x) => x,
        Err(e) => return c.check(false, || format!("{name}: {e}")),
    };
    if let Some(v) = entry.get("file_version").and_then(|v| v.as_u64()) {
        c.check(file.file_version() == Some(v as u32), || {
            format!("{name}: file version {:?} != {v}", file.file_version())
        });
    }
    let expected = entry["grids"].as_array().expect("grids");
    c.check(expected.len() == grids.len(), || {
        format!(
            "{name}: {} grids, manifest has {}",
            grids.len(),
            expected.len()
        )
    });
    let tol_default = entry.get("value_tolerance").and_then(number).unwrap_or(0.0);
    for (g, m) in grids.iter().zip(expected) {
        let at = format!("{name}:{}", g.name);
        let tol = m
            .get("value_tolerance")
            .and_then(number)
            .unwrap_or(tol_default);
        let tree = &g.tree;
        c.check(m["name"] == g.name.as_str(), || {
            format!("{at}: name != {}", m["name"])
        });
        if let Some(vt) = m.get("value_type").and_then(|v| v.as_str()) {
            c.check(vt == tree.value_type().name(), || {
                format!("{at}: value type {} != {vt}", tree.value_type().name())
            });
        }
        if let Some(cl) = m.get("class").and_then(|v| v.as_str()) {
            c.check(cl == g.class.name(), || {
                format!("{at}: class {} != {cl}", g.class.name())
            });
        }
        if let Some(h) = m.get("half_float").and_then(|v| v.as_bool()) {
            c.check(h == g.half_float, || {
                format!("{at}: half {} != {h}", g.half_float)
            });
        }
        if let Some(n) = m.get("active_voxels").and_then(|v| v.as_u64()) {
            c.check(n == tree.active_voxel_count(), || {
                format!("{at}: active voxels {} != {n}", tree.active_voxel_count())
            });
        }
        if let Some(n) = m.get("leaf_count").and_then(|v| v.as_u64()) {
            c.check(n == tree.leaf_count() as u64, || {
                format!("{at}: leaves {} != {n}", tree.leaf_count())
            });
        }
        if let Some(t) = m.get("active_tile_count").and_then(|v| v.as_array()) {
            let tc = tree.active_tile_counts();
            let ours = [tc.lower, tc.upper, tc.root];
            let theirs: Vec<u64> = t.iter().filter_map(|x| x.as_u64()).collect();
            c.check(theirs == ours, || {
                format!("{at}: tiles {ours:?} != {theirs:?}")
            });
        }
        if let Some(b) = m.get("index_bbox") {
            let ours = tree
                .active_bbox()
                .map(|b| [b.min.to_array(), b.max.to_array()]);
            let theirs: Option<[[i32; 3]; 2]> = serde_json::from_value(b.clone()).ok();
            c.check(ours == theirs, || {
                format!("{at}: bbox {ours:?} != {theirs:?}")
            });
        }
        if let Some(vs) = m.get("voxel_size") {
            let ours = g.transform.voxel_size().to_array();
            let theirs = components(vs);
            c.check(
                theirs.len() == 3
                    && (0..3).all(|i| same(ours[i], theirs[i], 1e-9 * theirs[i].abs())),
                || format!("{at}: voxel size {ours:?} != {theirs:?}"),
            );
        }
        if let Some(t) = m.get("transform").and_then(|v| v.as_str()) {
            c.check(t == g.transform.kind.name(), || {
                format!("{at}: transform {} != {t}", g.transform.kind.name())
            });
        }
        for s in m
            .get("index_to_world")
            .and_then(|v| v.as_array())
            .into_iter()
            .flatten()
        {
            let ijk = components(&s["ijk"]);
            let world = components(&s["world"]);
            let ours = g
                .transform
                .index_to_world(glam::DVec3::new(ijk[0], ijk[1], ijk[2]))
                .to_array();
            let scale = world.iter().fold(1.0f64, |a, &w| a.max(w.abs()));
            c.check(
                (0..3).all(|i| same(ours[i], world[i], 1e-12 * scale)),
                || format!("{at}: index {ijk:?} -> {ours:?}, manifest {world:?}"),
            );
        }
        if let Some(bg) = m.get("background") {
            let (ours, n) = tree.background_components();
            let theirs = components(bg);
            c.check(
                theirs.len() == n && (0..n).all(|i| same(ours[i], theirs[i], 0.0)),
                || format!("{at}: background {:?} != {theirs:?}", &ours[..n]),
            );
        }
        let range = tree.value_range();
        // OpenVDB orders vectors lexicographically for evalMinMax; the
        // manifest gives the per-component range separately.
        for (key, pick) in [("min", 0), ("max", 1)] {
            let vector_key = format!("{key}_components");
            let Some(v) = m
                .get(&vector_key)
                .or_else(|| m.get(key))
                .filter(|v| !v.is_null())
            else {
                continue;
            };
            let theirs = components(v);
            let ours = range.map(|r| if pick == 0 { r.min } else { r.max });
            let ok = ours.is_some_and(|o| {
                theirs
                    .iter()
                    .enumerate()
                    .all(|(i, &t)| same_f32(o[i], t, tol))
            });
            c.check(ok, || format!("{at}: {key} {ours:?} != {theirs:?}"));
        }
        for s in m
            .get("samples")
            .and_then(|v| v.as_array())
            .into_iter()
            .flatten()
        {
            let ijk = components(&s["ijk"]);
            let coord = Coord::new(ijk[0] as i32, ijk[1] as i32, ijk[2] as i32);
            let (ours, n, active) = tree.probe_components(coord);
            let theirs = components(&s["value"]);
            c.check(
                theirs.len() == n && (0..n).all(|i| same_f32(ours[i], theirs[i], tol)),
                || format!("{at}: value at {coord:?} {:?} != {theirs:?}", &ours[..n]),
            );
            if let Some(a) = s.get("active").and_then(|a| a.as_bool()) {
                c.check(a == active, || {
                    format!("{at}: active at {coord:?} {active} != {a}")
                });
            }
        }
    }
}

#[test]
fn every_corpus_file_agrees_with_the_debian_tools() {
    let mut c = Checker {
        failures: Vec::new(),
        checks: 0,
    };
    let mut files = 0;
    for dir in corpus_dirs() {
        let manifest = dir.join("manifest.json");
        let text = std::fs::read_to_string(&manifest)
            .unwrap_or_else(|e| panic!("{}: {e}", manifest.display()));
        let m: Json = serde_json::from_str(&text).expect("manifest is JSON");
        for entry in m["files"].as_array().expect("files") {
            check_file(&mut c, &dir, entry);
            files += 1;
        }
    }
    eprintln!("{files} corpus files, {} checks", c.checks);
    assert!(
        files >= 20,
        "the corpus should hold at least 20 files, found {files}"
    );
    assert!(
        c.failures.is_empty(),
        "{} of {} checks failed:\n{}",
        c.failures.len(),
        c.checks,
        c.failures.join("\n")
    );
}
