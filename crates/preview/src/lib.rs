//! `cirrus preview`: a live, progressive render of a volume or scene file
//! in the browser.
//!
//! How the parts fit:
//!
//! - [`source`] opens the input once (a lone volume is read and prepared
//!   once; a scene file is re-rendered through the scene library) and
//!   renders one pass for a set of `cirrus render` overrides.
//! - [`view`] is what the page controls (camera, sun, sky, medium,
//!   exposure, integrator, device) and turns it into those overrides; equal
//!   overrides key one accumulation.
//! - `engine` is the render thread: a quick low-resolution pass after each
//!   change, then full-resolution passes with distinct seeds, averaged by
//!   [`accumulate`] weighted by their samples, cancelled when the view
//!   changes, paused when no page is connected.
//! - `frame` tone-maps (the renderer's own curve), optionally denoises and
//!   encodes the PNG frames; `shared` holds the state the threads share.
//! - `http` serves the embedded page and a small JSON API (tiny_http);
//!   `ws` streams frames over a WebSocket (tungstenite). No request names
//!   a file: Save writes `<stem>.preview.exr` and `.png` next to the input.
//! - [`command`] prints the `cirrus render` line reproducing a frame.
//!
//! ```no_run
//! let preview = cirrus_preview::start(cirrus_preview::Config::new("data/cloud.vdb"))?;
//! println!("{}", preview.url());
//! preview.wait();
//! # Ok::<(), cirrus_scene::Error>(())
//! ```

pub mod accumulate;
pub mod command;
mod engine;
mod frame;
mod http;
mod reply;
mod shared;
pub mod source;
pub mod view;
mod ws;

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use cirrus_scene::{Device, Error, Result};

pub use http::MAX_BODY;

use shared::{Info, Shared};
use source::Source;

/// How to run a preview.
#[derive(Clone, Debug)]
pub struct Config {
    /// A volume (`.vdb`, `.nvdb`, `.cbrk`), a scene file (`.toml`) or a USD
    /// stage (`.usd`, `.usda`, `.usdc`, `.usdz`).
    pub input: PathBuf,
    /// Loopback by default: the page controls the renderer and writes files.
    pub bind: IpAddr,
    /// 0 picks a free port.
    pub port: u16,
    /// Replaces the scene's resolution; frames shrink to fit the page.
    pub res: Option<(u32, u32)>,
    /// Accumulation stops at this many samples per pixel.
    pub max_spp: u32,
    /// With no page connected, rendering stops this long after the last
    /// change.
    pub idle: Duration,
    /// Where passes render; `None` takes the scene's `[render] device`
    /// (the CPU unless it says otherwise). The page can change it.
    pub device: Option<Device>,
}

impl Config {
    pub fn new(input: impl Into<PathBuf>) -> Self {
        Config {
            input: input.into(),
            bind: IpAddr::V4(Ipv4Addr::LOCALHOST),
            port: 8470,
            res: None,
            max_spp: 4096,
            idle: Duration::from_secs(10),
            device: None,
        }
    }
}

/// A running preview server.
pub struct Preview {
    shared: Arc<Shared>,
    server: Arc<tiny_http::Server>,
    addr: SocketAddr,
    threads: Vec<JoinHandle<()>>,
}

/// Opens the input, binds the address and starts the render and HTTP
/// threads.
pub fn start(config: Config) -> Result<Preview> {
    if config.max_spp == 0 {
        return Err(Error::input("max spp must be at least 1"));
    }
    let source = Source::open(&config.input, config.res, config.device)?;
    let denoiser =
        frame::denoiser().map(|d| format!("{} {:?}", d.library().display(), d.version()));
    let info = Info {
        input: config.input.clone(),
        kind: source.kind,
        base_res: source.base_res,
        lighting: source.lighting.clone(),
        max_spp: config.max_spp,
        idle: config.idle,
        save_exr: save_path(&config.input, "exr"),
        save_png: save_path(&config.input, "png"),
        denoiser,
    };
    let aovs = info.denoiser.is_ok();
    let shared = Arc::new(Shared::new(info, source.view.clone()));
    let bind = SocketAddr::new(config.bind, config.port);
    let server = tiny_http::Server::http(bind)
        .map_err(|e| Error::file(format!("cannot listen on {bind}: {e}")))?;
    let addr = server
        .server_addr()
        .to_ip()
        .ok_or_else(|| Error::file("the server has no IP address"))?;
    let server = Arc::new(server);
    // On loopback only loopback names may be the Host (DNS rebinding).
    let hosts = config.bind.is_loopback().then(|| {
        let p = addr.port();
        vec![
            format!("127.0.0.1:{p}"),
            format!("localhost:{p}"),
            format!("[::1]:{p}"),
        ]
    });
    let mut threads = Vec::new();
    let (s, mut renderer) = (shared.clone(), source.renderer);
    renderer.aovs = aovs;
    threads.push(spawn("cirrus-preview-render", move || {
        engine::run(&mut renderer, &s)
    })?);
    let (s, srv) = (shared.clone(), server.clone());
    threads.push(spawn("cirrus-preview-http", move || {
        http::serve(srv, s, hosts)
    })?);
    Ok(Preview {
        shared,
        server,
        addr,
        threads,
    })
}

fn spawn(name: &str, f: impl FnOnce() + Send + 'static) -> Result<JoinHandle<()>> {
    std::thread::Builder::new()
        .name(name.into())
        .spawn(f)
        .map_err(|e| Error::file(format!("cannot start a thread: {e}")))
}

/// `<dir>/<stem>.preview.<ext>` beside the input.
pub fn save_path(input: &Path, ext: &str) -> PathBuf {
    let stem = input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "cirrus".into());
    input.with_file_name(format!("{stem}.preview.{ext}"))
}

impl Preview {
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// `http://ADDR:PORT/`.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// Blocks while the server runs (until [`Preview::shutdown`] from
    /// another handle, or the process ends).
    pub fn wait(mut self) {
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }

    /// Stops rendering and serving and joins the threads.
    pub fn shutdown(mut self) {
        self.stop();
    }

    fn stop(&mut self) {
        self.shared.quit();
        self.server.unblock();
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

impl Drop for Preview {
    fn drop(&mut self) {
        if !self.threads.is_empty() {
            self.stop();
        }
    }
}
