//! Where to look for `libOpenImageDenoise.so.2`, in order.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// File names of the library tried inside a directory, best first.
pub const LIBRARY_NAMES: [&str; 2] = ["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];

/// The name handed to the dynamic loader last, searched on its usual path
/// (`LD_LIBRARY_PATH`, `ld.so.cache`, ...).
pub const SYSTEM_NAME: &str = "libOpenImageDenoise.so.2";

/// The places to look for the library, in the order they are tried.
///
/// [`SearchPath::from_env`] fills it from the environment; tests and callers
/// that must not depend on the environment build it by hand.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SearchPath {
    /// `$CIRRUS_OIDN`: the library file, or a directory holding it. When set,
    /// it is the only place tried: an explicit choice that does not load is
    /// reported, never replaced silently by another copy of the library.
    pub cirrus_oidn: Option<PathBuf>,
    /// `$OIDN_DIR`: an OIDN install prefix; its `lib` directory is searched.
    pub oidn_dir: Option<PathBuf>,
    /// A Python interpreter whose `pyoidn` package (the PyPI wheel, which
    /// bundles the library) is searched; `from_env` uses `python3` on PATH.
    pub python: Option<OsString>,
    /// The running program: a `venv` in its directory or one or two above
    /// holding `pyoidn` is searched, which is where `tools/oidn.sh` (run
    /// by `tools/render_default.sh`) installs it for `target/release/cirrus`
    /// (`target/venv`), so the denoiser keeps working after that script.
    pub executable: Option<PathBuf>,
    /// Finally ask the dynamic loader for [`SYSTEM_NAME`].
    pub system: bool,
}

impl SearchPath {
    /// The search path given by `$CIRRUS_OIDN`, `$OIDN_DIR`, `python3` on
    /// PATH and the system loader. Empty variables count as unset.
    pub fn from_env() -> SearchPath {
        let var = |name: &str| {
            std::env::var_os(name)
                .filter(|v| !v.is_empty())
                .map(PathBuf::from)
        };
        SearchPath {
            cirrus_oidn: var("CIRRUS_OIDN"),
            oidn_dir: var("OIDN_DIR"),
            python: Some(OsString::from("python3")),
            executable: std::env::current_exe().ok(),
            system: true,
        }
    }

    /// The candidates to hand to the loader, in order: absolute paths of
    /// files that exist, then (if `system`) the bare [`SYSTEM_NAME`].
    /// An explicit [`cirrus_oidn`](Self::cirrus_oidn) is returned alone,
    /// whether or not it exists, so that the error can name it.
    pub fn candidates(&self) -> Vec<PathBuf> {
        if let Some(p) = &self.cirrus_oidn {
            return if p.is_dir() {
                vec![file_in(p).unwrap_or_else(|| p.join(LIBRARY_NAMES[0]))]
            } else {
                vec![p.clone()]
            };
        }
        let mut out = Vec::new();
        if let Some(prefix) = &self.oidn_dir {
            out.extend(file_in(&prefix.join("lib")));
        }
        if let Some(exe) = &self.executable {
            for pkg in venv_pyoidn_dirs(exe) {
                for dir in pyoidn_lib_dirs(&pkg) {
                    out.extend(file_in(&dir));
                }
            }
        }
        if let Some(python) = &self.python {
            if let Some(pkg) = pyoidn_dir(python) {
                for dir in pyoidn_lib_dirs(&pkg) {
                    out.extend(file_in(&dir));
                }
            }
        }
        if self.system {
            out.push(PathBuf::from(SYSTEM_NAME));
        }
        let mut seen = std::collections::HashSet::new();
        out.retain(|p| seen.insert(p.clone()));
        out
    }
}

/// The `pyoidn` packages of the virtual environments named `venv` in the
/// directories holding `exe`, up to three levels up
/// (`VENV/lib/pythonX.Y/site-packages/pyoidn`).
pub fn venv_pyoidn_dirs(exe: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for dir in exe.ancestors().skip(1).take(3) {
        let Ok(entries) = std::fs::read_dir(dir.join("venv").join("lib")) else {
            continue;
        };
        let mut pythons: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
        pythons.sort();
        for python in pythons {
            let pkg = python.join("site-packages").join("pyoidn");
            if pkg.is_dir() {
                out.push(pkg);
            }
        }
    }
    out
}

/// The first of [`LIBRARY_NAMES`] that exists as a file in `dir`.
fn file_in(dir: &Path) -> Option<PathBuf> {
    LIBRARY_NAMES
        .iter()
        .map(|n| dir.join(n))
        .find(|p| p.is_file())
}

/// The directories of an installed `pyoidn` package that may hold the
/// library. The 2.5.1.0 wheel keeps it in `pyoidn/oidn/lib`; the others
/// cover the usual wheel layouts (`auditwheel` puts bundled libraries in a
/// `pyoidn.libs` sibling).
pub fn pyoidn_lib_dirs(pkg: &Path) -> Vec<PathBuf> {
    let mut dirs = vec![
        pkg.join("oidn").join("lib"),
        pkg.to_path_buf(),
        pkg.join("lib"),
        pkg.join(".libs"),
    ];
    if let Some(parent) = pkg.parent() {
        dirs.push(parent.join("pyoidn.libs"));
    }
    dirs
}

/// The directory of the `pyoidn` package that `python` imports, if any.
///
/// The package is located with `importlib.util.find_spec`, which does not
/// run its `__init__` (that would import numpy and cffi for nothing).
pub fn pyoidn_dir(python: &std::ffi::OsStr) -> Option<PathBuf> {
    const SCRIPT: &str = "import importlib.util as u\n\
s = u.find_spec('pyoidn')\n\
print(list(s.submodule_search_locations)[0] if s and s.submodule_search_locations else '')";
    let out = Command::new(python)
        .args(["-c", SCRIPT])
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let line = String::from_utf8(out.stdout).ok()?;
    let line = line.trim();
    (!line.is_empty()).then(|| PathBuf::from(line))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_venv_beside_the_binary_is_searched() {
        let root = std::env::temp_dir().join(format!("cirrus-venv-search-{}", std::process::id()));
        let lib = root.join("venv/lib/python3.11/site-packages/pyoidn/oidn/lib");
        std::fs::create_dir_all(&lib).unwrap();
        std::fs::create_dir_all(root.join("release")).unwrap();
        std::fs::write(lib.join(LIBRARY_NAMES[0]), b"").unwrap();
        let search = SearchPath {
            executable: Some(root.join("release/cirrus")),
            ..SearchPath::default()
        };
        assert_eq!(search.candidates(), vec![lib.join(LIBRARY_NAMES[0])]);
        // Not from a binary elsewhere.
        let elsewhere = SearchPath {
            executable: Some(PathBuf::from("/nonexistent/bin/cirrus")),
            ..SearchPath::default()
        };
        assert!(elsewhere.candidates().is_empty());
        std::fs::remove_dir_all(&root).unwrap();
    }
}
