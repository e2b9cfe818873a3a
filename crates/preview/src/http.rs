//! The HTTP routes (tiny_http, one thread; each WebSocket gets its own).
//!
//! | route | does |
//! |---|---|
//! | `GET /` | the page (one embedded file) |
//! | `GET /state` | view, input, limits, denoiser, last frame's readout |
//! | `POST /view` | a JSON [`ViewPatch`]; answers the new view |
//! | `POST /save` | writes the two fixed files next to the input |
//! | `GET /command` | the `cirrus render` line reproducing the frame |
//! | `GET /ws` | WebSocket: frame metadata (text) then PNG (binary) |
//!
//! Safety: bodies over 64 KiB get 413; malformed JSON, unknown fields and
//! out-of-range values 400; anything else 404 (or 405 for a known route).
//! On a loopback address the Host must be loopback (no DNS rebinding);
//! POSTs must be JSON and same-origin, so another site cannot post to it.
//! No request names a path: Save writes only `Info::save_exr` and
//! `Info::save_png`.

use std::io::Read;
use std::sync::Arc;

use serde_json::json;
use tiny_http::{Method, Request, Response};

use crate::command::render_command;
use crate::reply::{error, header, json_reply, with_headers, Reply};
use crate::shared::Shared;
use crate::view::ViewPatch;

/// The largest request body accepted.
pub const MAX_BODY: usize = 64 * 1024;

const PAGE: &str = include_str!("../page/index.html");

/// Serves requests until the server is unblocked.
pub fn serve(server: Arc<tiny_http::Server>, shared: Arc<Shared>, hosts: Option<Vec<String>>) {
    for request in server.incoming_requests() {
        if shared.is_quitting() {
            let _ = request.respond(json_reply(503, json!({"error": "shutting down"})));
            break;
        }
        handle(request, &shared, hosts.as_deref());
    }
}

fn handle(mut req: Request, shared: &Arc<Shared>, hosts: Option<&[String]>) {
    let url = req.url().to_string();
    let (path, query) = url.split_once('?').unwrap_or((url.as_str(), ""));
    let host = header(&req, "Host").unwrap_or_default();
    if let Some(hosts) = hosts {
        if !hosts.iter().any(|h| h.eq_ignore_ascii_case(&host)) {
            let _ = req.respond(error(403, "unexpected Host header"));
            return;
        }
    }
    // Browsers send Origin on cross-origin requests and on every
    // WebSocket; only this server's own page may post or connect.
    let foreign = header(&req, "Origin").is_some_and(|o| o != format!("http://{host}"));
    let method = req.method().clone();
    let reply = match (&method, path) {
        (Method::Get, "/" | "/index.html") => page(),
        (Method::Get, "/state") => state(shared),
        (Method::Get, "/command") => command(shared),
        (Method::Get, "/ws") if foreign => error(403, "cross-origin WebSocket refused"),
        (Method::Get, "/ws") => return crate::ws::accept(req, shared.clone()),
        (Method::Post, "/view" | "/save") if foreign => error(403, "cross-origin request refused"),
        (Method::Post, "/view") => match body(&mut req) {
            Ok(b) => view(shared, &b),
            Err(r) => r,
        },
        (Method::Post, "/save") => match body(&mut req) {
            Ok(b) => save(shared, query, &b),
            Err(r) => r,
        },
        (_, "/" | "/index.html" | "/state" | "/command" | "/ws" | "/view" | "/save") => {
            error(405, "method not allowed")
        }
        _ => error(404, "not found"),
    };
    let _ = req.respond(reply);
}

fn page() -> Reply {
    with_headers(
        Response::from_data(PAGE.as_bytes().to_vec()),
        &[
            ("Content-Type", "text/html; charset=utf-8"),
            ("Cache-Control", "no-store"),
            // Everything is inline or from this server: no CDN can reach in.
            (
                "Content-Security-Policy",
                "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; \
                 img-src 'self' blob: data:; connect-src 'self'; base-uri 'none'; form-action 'none'",
            ),
        ],
    )
}

fn state(shared: &Shared) -> Reply {
    let info = &shared.info;
    let st = shared.lock();
    let (denoise_available, denoise_message) = match &info.denoiser {
        Ok(m) => (true, m.clone()),
        Err(m) => (false, m.clone()),
    };
    let file_name = |p: &std::path::Path| {
        p.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    json_reply(
        200,
        json!({
            "view": st.view,
            "version": st.version,
            "status": st.status,
            "info": {
                "input": info.input.display().to_string(),
                "kind": info.kind,
                "res": [info.base_res.0, info.base_res.1],
                "max_spp": info.max_spp,
                "denoise_available": denoise_available,
                "denoise_message": denoise_message,
                "save": [file_name(&info.save_exr), file_name(&info.save_png)],
            },
        }),
    )
}

fn view(shared: &Shared, body: &[u8]) -> Reply {
    let patch: ViewPatch = match serde_json::from_slice(body) {
        Ok(p) => p,
        Err(e) => return error(400, &format!("bad view: {e}")),
    };
    match shared.patch(&patch) {
        Ok(v) => json_reply(200, json!({"view": v, "version": shared.lock().version})),
        Err(e) => error(400, &e),
    }
}

fn command(shared: &Shared) -> Reply {
    let Some(snap) = shared.lock().snapshot.clone() else {
        return error(409, "nothing rendered yet");
    };
    let c = render_command(&shared.info.input, &snap.overrides);
    json_reply(200, json!({"command": c, "spp": snap.overrides.spp}))
}

/// Save takes no arguments: where it writes is fixed at start-up.
fn save(shared: &Shared, query: &str, body: &[u8]) -> Reply {
    let body = String::from_utf8_lossy(body);
    let body = body.trim();
    if !query.is_empty() || !(body.is_empty() || body == "{}") {
        return error(
            400,
            "save takes no arguments: it writes the fixed files of /state",
        );
    }
    let Some(snap) = shared.lock().snapshot.clone() else {
        return error(409, "nothing rendered yet");
    };
    let info = &shared.info;
    let written = cirrus_render::image_io::write_exr(&info.save_exr, &snap.image)
        .and_then(|_| cirrus_scene::write_whole(&info.save_png, &snap.png));
    match written {
        Ok(()) => json_reply(
            200,
            json!({
                "exr": info.save_exr.display().to_string(),
                "png": info.save_png.display().to_string(),
                "spp": snap.image.spp,
            }),
        ),
        Err(e) => error(500, &format!("save failed: {e}")),
    }
}

/// The request body, at most [`MAX_BODY`] bytes, of a JSON request.
fn body(req: &mut Request) -> Result<Vec<u8>, Reply> {
    let json = header(req, "Content-Type")
        .is_some_and(|t| t.to_ascii_lowercase().starts_with("application/json"));
    if !json {
        return Err(error(415, "send application/json"));
    }
    if req.body_length().is_some_and(|n| n > MAX_BODY) {
        return Err(too_large());
    }
    let mut buf = Vec::new();
    if let Err(e) = req
        .as_reader()
        .take(MAX_BODY as u64 + 1)
        .read_to_end(&mut buf)
    {
        return Err(error(400, &format!("unreadable body: {e}")));
    }
    if buf.len() > MAX_BODY {
        return Err(too_large());
    }
    Ok(buf)
}

fn too_large() -> Reply {
    with_headers(
        error(413, "request body over 64 KiB"),
        &[("Connection", "close")],
    )
}
