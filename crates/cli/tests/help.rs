//! What a user reads: `--help` speaks of the flags, not of the code, and
//! the README's `render` synopsis names every flag `render` takes.

mod common;

use common::{cirrus, root};

const COMMANDS: [&[&str]; 10] = [
    &["--help"],
    &["render", "--help"],
    &["info", "--help"],
    &["convert", "--help"],
    &["merge", "--help"],
    &["preview", "--help"],
    &["bench", "traverse", "--help"],
    &["bench", "error", "--help"],
    &["bench", "stress", "--help"],
    &["bench", "interleave", "--help"],
];

#[test]
fn help_speaks_of_flags_not_code() {
    for args in COMMANDS {
        let (ok, out, err) = cirrus(args);
        assert!(ok, "{args:?}: {err}");
        for code in ["[`", "`]", "cirrus_", ".rs`", "::"] {
            let line = out.lines().find(|l| l.contains(code));
            assert!(line.is_none(), "{args:?} shows {code:?}: {line:?}");
        }
    }
    let (_, out, _) = cirrus(&["preview", "--help"]);
    assert!(out.contains("USD stage"), "{out}");
}

/// The long flags of `cirrus render --help`, in order.
fn render_flags() -> Vec<String> {
    let (_, out, _) = cirrus(&["render", "--help"]);
    out.lines()
        .filter_map(|l| {
            let l = l.trim_start();
            let l = l.strip_prefix("-o, ").unwrap_or(l);
            l.strip_prefix("--")
                .map(|f| f.split([' ', '<', ',']).next().unwrap().to_string())
        })
        .filter(|f| !matches!(f.as_str(), "help" | "version"))
        .collect()
}

#[test]
fn the_readme_synopsis_names_every_render_flag() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let start = readme
        .find("```\ncirrus render FILE")
        .expect("the synopsis");
    let end = start + 4 + readme[start + 4..].find("```").unwrap();
    let synopsis = &readme[start..end];
    let flags = render_flags();
    assert!(flags.len() > 50, "{flags:?}");
    let missing: Vec<&String> = flags
        .iter()
        // `-o` is `--output`'s short form.
        .filter(|f| {
            !(synopsis.contains(&format!("--{f}")) || *f == "output" && synopsis.contains("-o "))
        })
        .collect();
    assert!(
        missing.is_empty(),
        "the README's synopsis lacks {missing:?}"
    );
}
