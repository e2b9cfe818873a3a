//! Frame sequences through the binary: resume, overwrite, a broken frame
//! reported by name, and a scene file's own range.

mod common;

use common::{cirrus, root};
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cirrus-frames-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn render(d: &Path, extra: &[&str]) -> (bool, String) {
    let pattern = d.join("seq.####.vdb");
    let out = d.join("out.####.exr");
    let mut args = vec![
        "render",
        s(&pattern),
        "--frames",
        "1-5",
        "--res",
        "12x8",
        "--spp",
        "1",
        "-o",
        s(&out),
    ];
    args.extend_from_slice(extra);
    let (ok, _, err) = cirrus(&args);
    (ok, err)
}

#[test]
fn a_sequence_resumes_and_reports_a_broken_frame_by_name() {
    let d = scratch("seq");
    let cloud = root().join("data/cloud.vdb");
    for f in 1..=5 {
        std::fs::copy(&cloud, d.join(format!("seq.{f:04}.vdb"))).unwrap();
    }
    std::fs::write(d.join("seq.0003.vdb"), b"not a volume").unwrap();
    let exists = |f: u32| d.join(format!("out.{f:04}.exr")).exists();

    let (ok, err) = render(&d, &[]);
    assert!(!ok, "a failed frame fails the run");
    assert!(
        err.contains("frame 3") && err.contains("seq.0003.vdb"),
        "{err}"
    );
    assert!(
        err.contains("5 frames: 4 rendered, 0 skipped, 1 failed"),
        "{err}"
    );
    assert_eq!(
        (1..=5).map(exists).collect::<Vec<_>>(),
        [true, true, false, true, true]
    );

    // Repaired, the rerun renders frame 3 alone.
    std::fs::copy(&cloud, d.join("seq.0003.vdb")).unwrap();
    let (ok, err) = render(&d, &[]);
    assert!(ok, "{err}");
    assert!(
        err.contains("5 frames: 1 rendered, 4 skipped, 0 failed"),
        "{err}"
    );
    assert!(exists(3));

    // A removed output is rendered again; --overwrite renders every frame.
    std::fs::remove_file(d.join("out.0002.exr")).unwrap();
    let (ok, err) = render(&d, &[]);
    assert!(ok && err.contains("1 rendered, 4 skipped"), "{err}");
    let (ok, err) = render(&d, &["--overwrite"]);
    assert!(ok && err.contains("5 rendered, 0 skipped"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn a_scene_files_frame_range_and_patterns() {
    let d = scratch("scene");
    let cloud = root().join("data/cloud.vdb");
    for f in [4, 6] {
        std::fs::copy(&cloud, d.join(format!("c{f}.vdb"))).unwrap();
    }
    let scene = d.join("shot.toml");
    std::fs::write(
        &scene,
        format!(
            "[output]\nexr = \"{}\"\n[render]\nspp = 1\nframes = \"4-6:2\"\n[camera]\nres = \"8x8\"\n[[volume]]\nfile = \"c%d.vdb\"\n",
            s(&d.join("out.%02d.exr"))
        ),
    )
    .unwrap();
    let (ok, _, err) = cirrus(&["render", s(&scene)]);
    assert!(ok, "{err}");
    assert!(err.contains("2 frames: 2 rendered"), "{err}");
    assert!(d.join("out.04.exr").exists() && d.join("out.06.exr").exists());
    assert!(!d.join("out.05.exr").exists());
    let (ok, _, err) = cirrus(&["render", s(&scene)]);
    assert!(
        ok && err.contains("2 frames: 0 rendered, 2 skipped"),
        "{err}"
    );
    let (ok, _, err) = cirrus(&["render", s(&d.join("c%d.vdb")), "-o", "x.exr"]);
    assert!(!ok && err.contains("needs --frames"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}
