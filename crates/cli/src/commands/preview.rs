//! `cirrus preview FILE|SCENE.toml|STAGE.usd [--port P] [--bind ADDR] [--device D]`: serves a
//! live progressive render to the browser (`cirrus-preview`) and prints
//! its URL.

use super::CliResult;
use std::net::IpAddr;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct PreviewArgs {
    /// A .vdb, .nvdb or .cbrk volume, a scene file (.toml) or a USD stage
    /// (.usd, .usda, .usdc, .usdz); without a camera the view is framed on
    /// the volumes.
    pub file: PathBuf,
    /// Port to listen on (0: any free port).
    #[arg(long, default_value_t = 8470)]
    pub port: u16,
    /// Address to listen on. Anyone who can reach it can steer the render
    /// and save next to the input: keep it on loopback unless you mean it.
    #[arg(long, default_value = "127.0.0.1")]
    pub bind: IpAddr,
    /// Resolution (WxH) instead of the scene's; frames shrink to the page.
    #[arg(long, value_parser = cirrus_scene::parse::resolution)]
    pub res: Option<(u32, u32)>,
    /// Stop accumulating at this many samples per pixel.
    #[arg(long, default_value_t = 4096)]
    pub max_spp: u32,
    /// Where passes render, as `cirrus render --device` (default: the
    /// scene file's `[render] device`, else cpu); the page can change it.
    /// The GPU path-traces the quick passes while you drag (it has no ray
    /// marcher).
    #[arg(long, value_enum)]
    pub device: Option<cirrus_scene::Device>,
}

pub fn run(args: &PreviewArgs) -> CliResult {
    let mut config = cirrus_preview::Config::new(&args.file);
    config.port = args.port;
    config.bind = args.bind;
    config.res = args.res;
    config.max_spp = args.max_spp;
    config.device = args.device;
    if !args.bind.is_loopback() {
        eprintln!(
            "cirrus preview: listening on {}: anyone who can reach it can steer the render",
            args.bind
        );
    }
    let preview = cirrus_preview::start(config)?;
    // Scripts (and the browser test) read the URL from the first line.
    println!("cirrus preview: {} (Ctrl-C stops)", preview.url());
    preview.wait();
    Ok(())
}
