//! Motion blur flags through the `cirrus` binary: `--shutter` (negative
//! times included), `--velocity`, and the errors of bad values.

mod common;

use common::cirrus;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cirrus-motion-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn render(out: &Path, extra: &[&str]) -> (bool, String) {
    let mut args = vec![
        "render",
        "data/multi_grid.vdb",
        "--res",
        "24x16",
        "--spp",
        "2",
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (ok, _, err) = cirrus(&args);
    (ok, err)
}

#[test]
fn shutter_flags_blur_and_a_closed_shutter_changes_nothing() {
    let d = scratch("flags");
    let (still, closed, open) = (
        d.join("still.exr"),
        d.join("closed.exr"),
        d.join("open.exr"),
    );
    assert!(render(&still, &[]).0);
    let (ok, err) = render(&closed, &["--shutter", "0,0", "--velocity", "velocity"]);
    assert!(ok, "{err}");
    let flags = [
        "--shutter",
        "-0.5,0.5",
        "--velocity",
        "velocity",
        "--velocity-unit",
        "voxels",
        "--velocity-scale",
        "6",
    ];
    let (ok, err) = render(&open, &flags);
    assert!(ok, "{err}");
    let read = |p: &PathBuf| std::fs::read(p).unwrap();
    assert_eq!(
        read(&closed),
        read(&still),
        "a closed shutter is no motion blur"
    );
    assert_ne!(read(&open), read(&still), "an open shutter blurs");
}

#[test]
fn bad_motion_values_are_errors_that_say_why() {
    let out = scratch("bad").join("x.exr");
    let (ok, err) = render(&out, &["--shutter", "0.5,-0.5"]);
    assert!(!ok && err.contains("open must not be after close"), "{err}");
    let (ok, err) = render(&out, &["--shutter", "0,0.5", "--velocity", "density"]);
    assert!(
        !ok && err.contains("multi_grid.vdb") && err.contains("vec3"),
        "{err}"
    );
    let (ok, err) = render(&out, &["--shutter", "0,0.5", "--velocity", "wind"]);
    assert!(!ok && err.contains("wind"), "{err}");
}
