//! Files packaged inside a `.usdz` (the resolver names them
//! `PACKAGE.usdz[INNER]`): cirrus's readers take paths, so a packaged VDB or
//! sky map is copied out once into the temporary directory, under a folder
//! keyed by the package's path, size and modification time.

use std::hash::{Hash, Hasher};
use std::io::Read;
use std::path::{Path, PathBuf};

/// `PACKAGE.usdz[INNER]` split into the package and the inner path.
pub fn split(resolved: &str) -> Option<(&str, &str)> {
    let inner_start = resolved.find(".usdz[")? + ".usdz".len();
    let inner = resolved[inner_start + 1..].strip_suffix(']')?;
    Some((&resolved[..inner_start], inner))
}

/// The file a resolved path names: itself, or a packaged file copied out.
pub fn extracted(resolved: &str) -> Result<PathBuf, String> {
    let Some((package, inner)) = split(resolved) else {
        return Ok(PathBuf::from(resolved));
    };
    let meta = std::fs::metadata(package).map_err(|e| format!("{package}: {e}"))?;
    let mut key = std::collections::hash_map::DefaultHasher::new();
    (package, meta.len(), meta.modified().ok()).hash(&mut key);
    let dir = std::env::temp_dir()
        .join("cirrus-usdz")
        .join(format!("{:016x}", key.finish()));
    let name = Path::new(inner)
        .file_name()
        .ok_or_else(|| format!("{resolved}: no file name"))?;
    let out = dir.join(name);
    if out.exists() {
        return Ok(out);
    }
    let file = std::fs::File::open(package).map_err(|e| format!("{package}: {e}"))?;
    let mut zip = zip::ZipArchive::new(file).map_err(|e| format!("{package}: {e}"))?;
    let mut entry = zip
        .by_name(inner)
        .map_err(|e| format!("{package}: {inner}: {e}"))?;
    let mut bytes = Vec::new();
    entry
        .read_to_end(&mut bytes)
        .map_err(|e| format!("{package}: {inner}: {e}"))?;
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    // Written whole under a temporary name, then renamed: a reader in
    // another process never sees half a file.
    let partial = dir.join(format!(
        ".{}.{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    std::fs::write(&partial, &bytes).map_err(|e| format!("{}: {e}", partial.display()))?;
    std::fs::rename(&partial, &out).map_err(|e| format!("{}: {e}", out.display()))?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packaged_paths_split_and_plain_ones_pass() {
        assert_eq!(
            split("/a/shot.usdz[vdb/cloud.vdb]"),
            Some(("/a/shot.usdz", "vdb/cloud.vdb"))
        );
        assert_eq!(split("/a/cloud.vdb"), None);
        assert_eq!(
            extracted("/a/cloud.vdb").unwrap(),
            PathBuf::from("/a/cloud.vdb")
        );
    }
}
