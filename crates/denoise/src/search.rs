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
