//! What `cirrus render` and `convert` write, and what they say: the
//! format told by the output's extension, several frames refused one
//! output file, progress lines in a log, and the files written named.

mod common;

use common::cirrus;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cirrus-outputs-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn render(args: &[&str]) -> (bool, String, String) {
    let base = ["render", "data/cloud.vdb", "--res", "16x12", "--spp", "1"];
    cirrus(&[&base[..], args].concat())
}

const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
const EXR_MAGIC: &[u8] = &[0x76, 0x2f, 0x31, 0x01];

fn starts_with(path: &Path, magic: &[u8]) -> bool {
    std::fs::read(path).unwrap().starts_with(magic)
}

#[test]
fn the_format_is_told_by_the_extension() {
    let d = scratch("formats");
    // -o NAME.png alone is a PNG, --png alone renders, -o NAME.exr an EXR.
    let png = d.join("a.png");
    let (ok, _, err) = render(&["-o", s(&png)]);
    assert!(ok, "{err}");
    assert!(starts_with(&png, PNG_SIGNATURE));
    assert!(err.contains(&format!("wrote {}", s(&png))), "{err}");
    let only = d.join("only.png");
    let (ok, _, err) = render(&["--png", s(&only)]);
    assert!(ok, "{err}");
    assert!(starts_with(&only, PNG_SIGNATURE));
    let (exr, png2) = (d.join("b.EXR"), d.join("b.png"));
    let (ok, _, err) = render(&["-o", s(&exr), "--png", s(&png2)]);
    assert!(ok, "{err}");
    assert!(starts_with(&exr, EXR_MAGIC) && starts_with(&png2, PNG_SIGNATURE));
    assert!(
        err.contains(&format!("wrote {}, {}", s(&exr), s(&png2))),
        "{err}"
    );
    // A mismatch is refused before rendering, naming the file.
    let at = |name: &str| s(&d.join(name)).to_string();
    for (flags, named, said) in [
        (vec!["-o", "x.tif"], "x.tif", ".exr or .png"),
        (
            vec!["-o", "x.exr", "--png", "y.exr"],
            "y.exr",
            "--png writes PNG",
        ),
        (
            vec!["-o", "x.png", "--png", "y.png"],
            "x.png",
            "give the PNG once",
        ),
        (vec!["-o", "x.exr", "--deep", "d.png"], "d.png", "--deep"),
    ] {
        let flags: Vec<String> = flags
            .iter()
            .map(|f| match f.starts_with('-') {
                true => f.to_string(),
                false => at(f),
            })
            .collect();
        let flags: Vec<&str> = flags.iter().map(|f| f.as_str()).collect();
        let (ok, _, err) = render(&flags);
        assert!(!ok, "{flags:?} accepted");
        assert!(
            err.contains(named) && err.contains(said),
            "{flags:?}: {err}"
        );
    }
    assert!(!d.join("x.tif").exists() && !d.join("x.exr").exists());
    // Without any output the message names both forms.
    let (ok, _, err) = render(&[]);
    assert!(!ok && err.contains("-o OUT.png"), "{err}");
    // merge writes OpenEXR under an .exr name only.
    let (ok, _, err) = cirrus(&["merge", &at("m.png"), s(&exr)]);
    assert!(
        !ok && err.contains("m.png") && err.contains(".exr"),
        "{err}"
    );
    assert!(!d.join("m.png").exists());
    // convert writes bricks under a .cbrk name only.
    let wrong = d.join("c.exr");
    let (ok, _, err) = cirrus(&["convert", "data/cloud.vdb", "-o", s(&wrong)]);
    assert!(
        !ok && err.contains("c.exr") && err.contains(".cbrk"),
        "{err}"
    );
    assert!(!wrong.exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn several_frames_need_a_frame_pattern_in_every_output() {
    let d = scratch("frames");
    let one = d.join("nopattern.exr");
    let (ok, _, err) = render(&["--frames", "1-2", "-o", s(&one)]);
    assert!(!ok, "accepted: {err}");
    assert!(
        err.contains("nopattern.exr") && err.contains("frame pattern"),
        "{err}"
    );
    assert!(!one.exists(), "nothing rendered");
    let (exr, png) = (d.join("f.####.exr"), d.join("one.png"));
    let (ok, _, err) = render(&["--frames", "1-2", "-o", s(&exr), "--png", s(&png)]);
    assert!(!ok && err.contains("one.png"), "{err}");
    // One frame may go to one file.
    let (ok, _, err) = render(&["--frames", "3-3", "-o", s(&one)]);
    assert!(ok, "{err}");
    assert!(one.exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_log_gets_plain_progress_lines() {
    let d = scratch("progress");
    let out = d.join("p.exr");
    // stderr is a pipe here, as in a farm's or batch job's log; interval
    // 0 prints after every tile.
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_cirrus"))
        .args([
            "render",
            "data/cloud.vdb",
            "--res",
            "64x64",
            "--spp",
            "4",
            "-o",
            s(&out),
        ])
        .env("CIRRUS_PROGRESS_INTERVAL", "0")
        .current_dir(common::root())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{err}");
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("cirrus: rendered "))
        .collect();
    assert!(!lines.is_empty(), "no progress lines: {err}");
    assert!(
        lines
            .iter()
            .all(|l| l.contains("% in ") && l.ends_with(" s left")),
        "{lines:?}"
    );
    assert!(!err.contains('\r'), "no carriage returns in a log");
    std::fs::remove_dir_all(&d).unwrap();
}
