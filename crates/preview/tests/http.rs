//! The preview server over real HTTP: a server per test on port 0 in this
//! process, requests written on a `TcpStream`, frames read with a
//! WebSocket client.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use cirrus_preview::{start, Config, Preview};
use serde_json::Value;

/// A fresh directory holding a copy of the corpus cloud.
fn workdir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cirrus-preview-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let cloud = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/cloud.vdb");
    std::fs::copy(cloud, dir.join("cloud.vdb")).unwrap();
    dir
}

fn serve(input: PathBuf) -> Preview {
    let mut c = Config::new(input);
    c.port = 0;
    c.res = Some((32, 24));
    c.max_spp = 8;
    start(c).unwrap()
}

struct Reply {
    status: u16,
    body: String,
}

impl Reply {
    fn json(&self) -> Value {
        serde_json::from_str(&self.body).unwrap_or_else(|e| panic!("{e}: {}", self.body))
    }
}

/// One request on its own connection; `headers` may replace Host.
fn request(
    addr: SocketAddr,
    method: &str,
    path: &str,
    headers: &[(&str, &str)],
    body: &[u8],
) -> Reply {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    let mut head = format!("{method} {path} HTTP/1.1\r\nConnection: close\r\n");
    if !headers.iter().any(|(k, _)| k.eq_ignore_ascii_case("host")) {
        head += &format!("Host: {addr}\r\n");
    }
    if !headers
        .iter()
        .any(|(k, _)| k.eq_ignore_ascii_case("transfer-encoding"))
    {
        head += &format!("Content-Length: {}\r\n", body.len());
    }
    for (k, v) in headers {
        head += &format!("{k}: {v}\r\n");
    }
    head += "\r\n";
    s.write_all(head.as_bytes()).unwrap();
    // The server may answer (and close) before reading an oversized body.
    let _ = s.write_all(body);
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    let text = String::from_utf8_lossy(&raw).into_owned();
    let status = text
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("no status line in {text:?}"));
    let body = text
        .split_once("\r\n\r\n")
        .map_or("", |(_, b)| b)
        .to_string();
    Reply { status, body }
}

fn get(addr: SocketAddr, path: &str) -> Reply {
    request(addr, "GET", path, &[], b"")
}

fn post(addr: SocketAddr, path: &str, body: &str) -> Reply {
    request(
        addr,
        "POST",
        path,
        &[("Content-Type", "application/json")],
        body.as_bytes(),
    )
}

type Socket = tungstenite::WebSocket<tungstenite::stream::MaybeTlsStream<TcpStream>>;

fn connect(addr: SocketAddr) -> Socket {
    let (ws, _) = tungstenite::connect(format!("ws://{addr}/ws")).unwrap();
    ws
}

/// Reads frames until one satisfies `done`; returns its metadata and PNG.
fn frame_until(ws: &mut Socket, done: impl Fn(&Value) -> bool) -> (Value, Vec<u8>) {
    let deadline = Instant::now() + Duration::from_secs(120);
    let mut meta = Value::Null;
    while Instant::now() < deadline {
        match ws.read().unwrap() {
            tungstenite::Message::Text(t) => {
                meta = serde_json::from_str(t.as_str()).unwrap();
                assert_ne!(meta["type"], "error", "{meta}");
            }
            tungstenite::Message::Binary(png) if done(&meta) => return (meta, png.to_vec()),
            _ => {}
        }
    }
    panic!("no such frame in time; last {meta}");
}

fn png_size(png: &[u8]) -> (u32, u32) {
    let reader = png::Decoder::new(std::io::Cursor::new(png))
        .read_info()
        .unwrap();
    let info = reader.info();
    (info.width, info.height)
}

#[test]
fn state_changes_apply_and_restart_accumulation() {
    let dir = workdir("state");
    let p = serve(dir.join("cloud.vdb"));
    let addr = p.addr();
    let page = get(addr, "/");
    assert_eq!(page.status, 200);
    assert!(page.body.contains("cirrus preview"));
    let s = get(addr, "/state").json();
    assert_eq!(s["info"]["res"], serde_json::json!([32, 24]));
    let mut ws = connect(addr);
    let (m, png) = frame_until(&mut ws, |m| m["spp"] == 8);
    assert_eq!(
        (m["width"].clone(), m["height"].clone()),
        (32.into(), 24.into())
    );
    assert_eq!(png_size(&png), (32, 24));

    let r = post(
        addr,
        "/view",
        r#"{"albedo": 0.5, "sun": {"elevation": 60}, "g": -0.2}"#,
    );
    assert_eq!(r.status, 200, "{}", r.body);
    let version = r.json()["version"].as_u64().unwrap();
    let v = get(addr, "/state").json()["view"].clone();
    assert_eq!(v["albedo"], 0.5);
    assert_eq!(v["sun"]["elevation"], 60.0);
    assert!((v["g"].as_f64().unwrap() + 0.2).abs() < 1e-6);
    // The accumulation restarts from the new view and climbs again.
    let (m, _) = frame_until(&mut ws, |m| m["version"].as_u64() >= Some(version));
    assert!(m["spp"].as_u64().unwrap() <= 2, "{m}");
    frame_until(&mut ws, |m| {
        m["version"].as_u64() >= Some(version) && m["spp"] == 8
    });
    let c = get(addr, "/command").json();
    let c = c["command"].as_str().unwrap();
    assert!(
        c.contains("--albedo 0.5") && c.contains("--g=-0.2") && c.contains("--spp 8"),
        "{c}"
    );

    // The viewport caps the frame size, keeping the aspect.
    let r = post(addr, "/view", r#"{"viewport": [16, 100]}"#);
    assert_eq!(r.status, 200);
    let (m, png) = frame_until(&mut ws, |m| {
        m["target"] == serde_json::json!([16, 12]) && m["preview"] == false
    });
    assert_eq!(png_size(&png), (16, 12), "{m}");
    p.shutdown();
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn malformed_and_oversized_requests_get_4xx_and_change_nothing() {
    let dir = workdir("malformed");
    let p = serve(dir.join("cloud.vdb"));
    let addr = p.addr();
    let before = get(addr, "/state").json()["view"].clone();
    for body in [
        "",
        "{",
        "[1, 2]",
        r#"{"albedo": "high"}"#,
        r#"{"albedo": 2}"#,
        r#"{"g": 1e40}"#,
        r#"{"camera": {"from": [0, 0, 0], "to": [0, 0, 0], "up": [0, 1, 0], "fov": 40}}"#,
        r#"{"camera": {"from": [1, 2], "to": [0, 0, 0], "up": [0, 1, 0], "fov": 40}}"#,
        r#"{"viewport": [0, 0]}"#,
        r#"{"integrator": "magic"}"#,
        r#"{"device": "tpu"}"#,
        r#"{"device": 1}"#,
        r#"{"sun": {"elevation": 1000}}"#,
        "\u{0}\u{1}binary",
    ] {
        let r = post(addr, "/view", body);
        assert_eq!(r.status, 400, "{body:?}: {}", r.body);
        assert!(r.json()["error"].is_string());
    }
    let big = format!(r#"{{"albedo": 0.5, "pad": "{}"}}"#, "x".repeat(100 * 1024));
    assert_eq!(post(addr, "/view", &big).status, 413);
    // Without a length the limit still holds (chunked body).
    let mut chunked = Vec::new();
    for _ in 0..80 {
        chunked.extend_from_slice(format!("{:x}\r\n{}\r\n", 1024, " ".repeat(1024)).as_bytes());
    }
    chunked.extend_from_slice(b"0\r\n\r\n");
    let r = request(
        addr,
        "POST",
        "/view",
        &[
            ("Content-Type", "application/json"),
            ("Transfer-Encoding", "chunked"),
        ],
        &chunked,
    );
    assert_eq!(r.status, 413);
    let r = request(
        addr,
        "POST",
        "/view",
        &[("Content-Type", "text/plain")],
        b"{}",
    );
    assert_eq!(r.status, 415);
    assert_eq!(get(addr, "/view").status, 405);
    assert_eq!(request(addr, "DELETE", "/state", &[], b"").status, 405);
    assert_eq!(get(addr, "/ws").status, 400, "a plain GET is no handshake");
    assert_eq!(get(addr, "/nothing").status, 404);
    // Nothing above changed the view, and the server still answers.
    assert_eq!(get(addr, "/state").json()["view"], before);
    p.shutdown();
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn path_like_input_is_refused() {
    let dir = workdir("paths");
    let p = serve(dir.join("cloud.vdb"));
    let addr = p.addr();
    for path in [
        "/../../etc/passwd",
        "/cloud.vdb",
        "/data/cloud.vdb",
        "/%2e%2e/%2e%2e/etc/passwd",
        "/state/../cloud.vdb",
        "//etc/passwd",
    ] {
        assert_eq!(get(addr, path).status, 404, "{path}");
    }
    for body in [
        r#"{"file": "/etc/passwd"}"#,
        r#"{"env_map": "/etc/passwd"}"#,
        r#"{"output": "/tmp/x.exr"}"#,
        r#"{"camera": {"from": [1, 1, 1], "to": [0, 0, 0], "up": [0, 1, 0], "fov": 40, "file": "x"}}"#,
    ] {
        assert_eq!(post(addr, "/view", body).status, 400, "{body}");
    }
    assert_eq!(post(addr, "/save?path=/tmp/evil.exr", "").status, 400);
    assert_eq!(
        post(addr, "/save", r#"{"path": "/tmp/evil.exr"}"#).status,
        400
    );
    assert_eq!(post(addr, "/save", r#"{"exr": "evil.exr"}"#).status, 400);
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["cloud.vdb"]);
    p.shutdown();
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn other_sites_and_foreign_hosts_are_refused() {
    let dir = workdir("origin");
    let p = serve(dir.join("cloud.vdb"));
    let addr = p.addr();
    let evil = [
        ("Content-Type", "application/json"),
        ("Origin", "http://evil.example"),
    ];
    assert_eq!(
        request(addr, "POST", "/view", &evil, br#"{"albedo": 0.1}"#).status,
        403
    );
    assert_eq!(request(addr, "POST", "/save", &evil, b"{}").status, 403);
    let rebound = [("Host", "evil.example")];
    assert_eq!(request(addr, "GET", "/state", &rebound, b"").status, 403);
    let own = format!("http://{addr}");
    let ok = [
        ("Content-Type", "application/json"),
        ("Origin", own.as_str()),
    ];
    assert_eq!(
        request(addr, "POST", "/view", &ok, br#"{"albedo": 0.1}"#).status,
        200
    );
    p.shutdown();
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn save_writes_only_the_fixed_files() {
    let dir = workdir("save");
    let p = serve(dir.join("cloud.vdb"));
    let addr = p.addr();
    let early = post(addr, "/save", "{}");
    assert!(early.status == 409 || early.status == 200, "{}", early.body);
    let mut ws = connect(addr);
    frame_until(&mut ws, |m| m["spp"] == 8);
    let r = post(addr, "/save", "{}");
    assert_eq!(r.status, 200, "{}", r.body);
    assert_eq!(r.json()["spp"], 8);
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["cloud.preview.exr", "cloud.preview.png", "cloud.vdb"]
    );
    let exr = exr::prelude::read_first_rgba_layer_from_file(
        dir.join("cloud.preview.exr"),
        |res, _| vec![[0f32; 4]; res.width() * res.height()],
        |px, pos, (r, g, b, a): (f32, f32, f32, f32)| px[pos.y() * 32 + pos.x()] = [r, g, b, a],
    )
    .unwrap();
    let px = &exr.layer_data.channel_data.pixels;
    assert_eq!(px.len(), 32 * 24);
    assert!(px.iter().flatten().all(|v| v.is_finite()));
    assert!(
        px.iter().any(|p| p[3] > 0.1),
        "the cloud covers some pixels"
    );
    let png = std::fs::read(dir.join("cloud.preview.png")).unwrap();
    assert_eq!(png_size(&png), (32, 24));
    p.shutdown();
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_scene_file_previews_through_the_scene_library() {
    let dir = workdir("scene");
    std::fs::write(
        dir.join("two.toml"),
        r#"
        [camera]
        res = "64x48"
        from = [500.0, 200.0, 500.0]
        to = [150.0, 80.0, 100.0]
        [[volume]]
        file = "cloud.vdb"
        [[volume]]
        file = "cloud.vdb"
        transform = { translate = [200.0, 0.0, 0.0], scale = 0.5 }
        "#,
    )
    .unwrap();
    let p = serve(dir.join("two.toml"));
    let addr = p.addr();
    assert_eq!(get(addr, "/state").json()["info"]["kind"], "scene");
    let mut ws = connect(addr);
    let (m, png) = frame_until(&mut ws, |m| m["spp"].as_u64() >= Some(2));
    assert_eq!(png_size(&png), (32, 24), "{m}");
    let c = get(addr, "/command").json();
    assert!(c["command"].as_str().unwrap().contains("two.toml"), "{c}");
    p.shutdown();
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn rendering_stops_when_idle_without_a_page_and_resumes_with_one() {
    let dir = workdir("idle");
    let mut c = Config::new(dir.join("cloud.vdb"));
    c.port = 0;
    c.res = Some((16, 12));
    c.max_spp = 1_000_000;
    c.idle = Duration::from_millis(300);
    let p = start(c).unwrap();
    let addr = p.addr();
    let spp = |addr| {
        get(addr, "/state").json()["status"]["spp"]
            .as_u64()
            .unwrap_or(0)
    };
    std::thread::sleep(Duration::from_millis(1500));
    let stopped = spp(addr);
    std::thread::sleep(Duration::from_millis(800));
    assert_eq!(spp(addr), stopped, "still rendering with nobody watching");
    let mut ws = connect(addr);
    frame_until(&mut ws, |m| m["spp"].as_u64() > Some(stopped));
    p.shutdown();
    let _ = std::fs::remove_dir_all(dir);
}

/// The mean of every pixel's RGB in the accumulation `/save` wrote.
fn saved_mean(dir: &Path, w: usize, h: usize) -> f64 {
    let exr = exr::prelude::read_first_rgba_layer_from_file(
        dir.join("cloud.preview.exr"),
        |res, _| vec![[0f32; 4]; res.width() * res.height()],
        move |px, pos, (r, g, b, a): (f32, f32, f32, f32)| px[pos.y() * w + pos.x()] = [r, g, b, a],
    )
    .unwrap();
    let px = &exr.layer_data.channel_data.pixels;
    assert_eq!(px.len(), w * h);
    assert!(px.iter().flatten().all(|v| v.is_finite()));
    px.iter()
        .map(|p| f64::from(p[0] + p[1] + p[2]) / 3.0)
        .sum::<f64>()
        / (w * h) as f64
}

/// Whether `message` says there is no Vulkan adapter; then CI (which
/// installs lavapipe) fails, and elsewhere the install hint must be named.
fn no_adapter(message: &str) -> bool {
    let none = message.contains("no Vulkan adapter");
    if none {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI has no Vulkan adapter: {message}"
        );
        assert!(message.contains("mesa-vulkan-drivers"), "{message}");
        eprintln!("SKIPPED: {message}");
    }
    none
}

/// Reads messages until an error frame; returns its message.
fn error_frame(ws: &mut Socket) -> String {
    let deadline = Instant::now() + Duration::from_secs(120);
    while Instant::now() < deadline {
        if let tungstenite::Message::Text(t) = ws.read().unwrap() {
            let meta: Value = serde_json::from_str(t.as_str()).unwrap();
            if meta["type"] == "error" {
                return meta["message"].as_str().unwrap().to_string();
            }
        }
    }
    panic!("no error frame in time");
}

/// The page switches a CPU preview to the GPU (opened then, once): its
/// passes accumulate as the CPU's do, to the same image within the noise;
/// the command line says the device; what the GPU does not render is an
/// error frame naming it, and a CPU view renders again after it.
#[test]
fn the_page_moves_passes_to_the_gpu_and_they_accumulate() {
    let dir = workdir("gpu");
    let mut c = Config::new(dir.join("cloud.vdb"));
    c.port = 0;
    c.res = Some((32, 24));
    c.max_spp = 16;
    let p = start(c).unwrap();
    let addr = p.addr();
    assert_eq!(get(addr, "/state").json()["view"]["device"], "cpu");
    let mut ws = connect(addr);
    let (m, _) = frame_until(&mut ws, |m| m["spp"] == 16);
    assert_eq!(m["device"], "cpu", "{m}");
    assert_eq!(post(addr, "/save", "{}").status, 200);
    let cpu = saved_mean(&dir, 32, 24);

    let r = post(addr, "/view", r#"{"device": "gpu"}"#);
    assert_eq!(r.status, 200, "{}", r.body);
    assert_eq!(r.json()["view"]["device"], "gpu");
    let version = r.json()["version"].as_u64().unwrap();
    // Frames of the CPU view may still arrive first; the GPU's follow.
    let m = loop {
        let tungstenite::Message::Text(t) = ws.read().unwrap() else {
            continue;
        };
        let meta: Value = serde_json::from_str(t.as_str()).unwrap();
        if meta["type"] == "error" {
            let message = meta["message"].as_str().unwrap();
            assert!(no_adapter(message), "{message}");
            p.shutdown();
            return;
        }
        if meta["version"].as_u64() >= Some(version) && meta["spp"] == 16 {
            break meta;
        }
    };
    let device = m["device"].as_str().unwrap();
    assert!(device.starts_with("gpu: "), "{m}");
    assert!(
        m["passes"].as_u64() > Some(1),
        "one pass is no accumulation: {m}"
    );
    assert_eq!(post(addr, "/save", "{}").status, 200);
    let gpu = saved_mean(&dir, 32, 24);
    eprintln!("image mean: cpu {cpu}, gpu {gpu}");
    // 32x24 pixels at 16 spp: the image means of the two devices'
    // estimators (same expectation) lie well within 5% of each other.
    assert!(cpu > 0.01, "the cloud is lit: {cpu}");
    assert!(
        (gpu - cpu).abs() < 0.05 * cpu,
        "gpu {gpu} against cpu {cpu}"
    );
    let c = get(addr, "/command").json();
    assert!(
        c["command"].as_str().unwrap().contains("--device gpu"),
        "{c}"
    );

    // The GPU has no ray marcher: refused by name, on the page.
    let r = post(addr, "/view", r#"{"integrator": "raymarch"}"#);
    assert_eq!(r.status, 200, "{}", r.body);
    let message = error_frame(&mut ws);
    assert!(message.contains("the raymarch integrator"), "{message}");
    assert_eq!(post(addr, "/view", r#"{"device": "cpu"}"#).status, 200);
    frame_until(&mut ws, |m| {
        m["device"] == "cpu" && m["integrator"] == "raymarch"
    });
    p.shutdown();
    let _ = std::fs::remove_dir_all(dir);
}
