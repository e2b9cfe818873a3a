//! First-image latency of `cirrus preview` after a change (a benchmark,
//! not a test): the time from sending a camera change over HTTP to
//! receiving the first frame of the new view over the WebSocket, and to
//! the first full-resolution frame.
//!
//! `cargo run --release -p cirrus-preview --example latency -- [FILE] [--res WxH] [--changes N]`
//! (defaults: data/cloud.vdb, 256x256, 20 changes per mode).

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

use cirrus_preview::{start, Config};
use serde_json::{json, Value};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut file = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cloud.vdb").to_string();
    let (mut res, mut changes) = ((256, 256), 20);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--res" => res = cirrus_scene::parse::resolution(&args.next().ok_or("--res WxH")?)?,
            "--changes" => changes = args.next().ok_or("--changes N")?.parse()?,
            _ => file = a,
        }
    }
    let mut config = Config::new(&file);
    config.port = 0;
    config.res = Some(res);
    config.max_spp = 64;
    let preview = start(config)?;
    let addr = preview.addr();
    let (mut ws, _) = tungstenite::connect(format!("ws://{addr}/ws"))?;
    let state: Value = serde_json::from_str(&request(addr, "GET", "/state", "")?)?;
    let camera = state["view"]["camera"].clone();
    // Warm up: let the engine measure its rates.
    until(&mut ws, |m| m["spp"].as_u64() >= Some(4))?;
    println!(
        "{file} at {}x{}, {} threads, {changes} camera changes per mode",
        res.0,
        res.1,
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    for (mode, interactive) in [
        ("still (auto: path)", false),
        ("dragging (auto: raymarch)", true),
    ] {
        let (mut first, mut full) = (Vec::new(), Vec::new());
        for i in 0..changes {
            let angle = (i as f64 + 1.0) * 0.05;
            let body = json!({"camera": orbit(&camera, angle), "interactive": interactive});
            let t0 = Instant::now();
            let reply: Value =
                serde_json::from_str(&request(addr, "POST", "/view", &body.to_string())?)?;
            let version = reply["version"].as_u64().ok_or("no version")?;
            let m = until(&mut ws, |m| m["version"].as_u64() >= Some(version))?;
            first.push((t0.elapsed(), m["width"].as_u64().unwrap_or(0)));
            until(&mut ws, |m| {
                m["version"].as_u64() >= Some(version) && m["preview"] == false
            })?;
            full.push(t0.elapsed());
            std::thread::sleep(Duration::from_millis(200));
        }
        let mut f: Vec<Duration> = first.iter().map(|x| x.0).collect();
        let widths: Vec<u64> = first.iter().map(|x| x.1).collect();
        println!("{mode}:");
        println!(
            "  first frame      {}  (width {}..{})",
            summary(&mut f),
            widths.iter().min().unwrap_or(&0),
            widths.iter().max().unwrap_or(&0)
        );
        println!("  first full frame {}", summary(&mut full));
    }
    preview.shutdown();
    Ok(())
}

/// min / median / p90 / max in milliseconds.
fn summary(d: &mut [Duration]) -> String {
    d.sort();
    let ms = |i: usize| d[i.min(d.len() - 1)].as_secs_f64() * 1e3;
    format!(
        "min {:6.1} ms  median {:6.1} ms  p90 {:6.1} ms  max {:6.1} ms",
        ms(0),
        ms(d.len() / 2),
        ms(d.len() * 9 / 10),
        ms(d.len() - 1)
    )
}

/// The camera turned by `angle` radians about +Y around its target.
fn orbit(camera: &Value, angle: f64) -> Value {
    let v = |k: &str, i: usize| camera[k][i].as_f64().unwrap_or(0.0);
    let (dx, dz) = (v("from", 0) - v("to", 0), v("from", 2) - v("to", 2));
    let (s, c) = angle.sin_cos();
    let mut cam = camera.clone();
    cam["from"][0] = json!(v("to", 0) + c * dx + s * dz);
    cam["from"][2] = json!(v("to", 2) - s * dx + c * dz);
    cam
}

type Socket = tungstenite::WebSocket<tungstenite::stream::MaybeTlsStream<TcpStream>>;

/// Reads frames until one's metadata satisfies `done` (and its PNG came).
fn until(
    ws: &mut Socket,
    done: impl Fn(&Value) -> bool,
) -> Result<Value, Box<dyn std::error::Error>> {
    let mut meta = Value::Null;
    loop {
        match ws.read()? {
            tungstenite::Message::Text(t) => meta = serde_json::from_str(t.as_str())?,
            tungstenite::Message::Binary(_) if done(&meta) => return Ok(meta),
            _ => {}
        }
    }
}

fn request(addr: SocketAddr, method: &str, path: &str, body: &str) -> std::io::Result<String> {
    let mut s = TcpStream::connect(addr)?;
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\
         Content-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    )?;
    let mut out = String::new();
    s.read_to_string(&mut out)?;
    Ok(out
        .split_once("\r\n\r\n")
        .map_or("", |(_, b)| b)
        .to_string())
}
