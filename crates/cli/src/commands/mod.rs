pub mod bench;
pub mod bench_error;
pub mod bench_plot;
pub mod bench_stress;
pub mod convert;
pub mod info;
pub mod merge;
pub mod render;
pub mod scene_cull;
pub mod scene_file;
pub mod scene_load;
pub mod scene_render;

/// The error every subcommand returns: printed once by `main`.
pub type CliResult = Result<(), Box<dyn std::error::Error>>;

/// Writes a file whole or not at all: a temporary beside it, then a rename.
pub fn write_whole(path: &std::path::Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("out");
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = std::fs::write(&tmp, bytes).and_then(|_| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", path.display())))
}
