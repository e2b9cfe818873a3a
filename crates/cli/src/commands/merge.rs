//! `cirrus merge OUT.exr TILE.exr...`: crop tiles into one image (flat
//! tiles, or deep tiles written by `--deep`).

use super::CliResult;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct MergeArgs {
    /// The full-size EXR to write.
    pub output: PathBuf,
    /// Tiles written by `cirrus render --crop` of the same image; together
    /// they must cover it exactly once.
    #[arg(required = true)]
    pub tiles: Vec<PathBuf>,
}

/// Copies every channel of every tile into place, and denoises the whole
/// image where the tiles were rendered with `--denoise`; the result is bit
/// for bit the full render when the tiles were rendered with its seed.
pub fn run(args: &MergeArgs) -> CliResult {
    if !cirrus_scene::has_extension(&args.output, "exr") {
        return Err(format!(
            "{}: merge writes OpenEXR; name the output .exr",
            args.output.display()
        )
        .into());
    }
    let tiles: Vec<&std::path::Path> = args.tiles.iter().map(|p| p.as_path()).collect();
    if cirrus_deep_exr::is_deep_file(tiles[0])? {
        cirrus_deep_exr::merge(&args.output, &tiles)?;
    } else {
        let denoised = cirrus_scene::merge_tiles(&args.output, &tiles)?;
        eprintln!(
            "{}: merged {} tiles{}",
            args.output.display(),
            args.tiles.len(),
            if denoised { ", denoised" } else { "" }
        );
        return Ok(());
    }
    eprintln!(
        "{}: merged {} tiles",
        args.output.display(),
        args.tiles.len()
    );
    Ok(())
}
