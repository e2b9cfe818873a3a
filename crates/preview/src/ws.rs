//! The WebSocket a page receives frames on: for each frame a text message
//! (its JSON metadata) and, unless it is an error, a binary one (the PNG).
//!
//! The sender only ever takes the latest frame, so a slow page skips
//! frames instead of queueing them. The page sends nothing on it (changes
//! go through `POST /view`); a ping every few seconds finds a page that
//! went away, whose thread then ends and stops counting as a client.

use std::sync::Arc;
use std::time::Duration;

use tiny_http::{Request, Response};
use tungstenite::protocol::Role;
use tungstenite::{Message, WebSocket};

use crate::reply::{error, header, with_headers};
use crate::shared::{ClientGuard, Shared};

/// Silence after which a ping checks the page is still there.
const PING_AFTER: Duration = Duration::from_secs(3);

/// Completes the handshake and starts the page's sender thread.
pub fn accept(req: Request, shared: Arc<Shared>) {
    let upgrade = header(&req, "Upgrade").is_some_and(|u| u.eq_ignore_ascii_case("websocket"));
    let version = header(&req, "Sec-WebSocket-Version").is_some_and(|v| v.trim() == "13");
    let key = header(&req, "Sec-WebSocket-Key").filter(|k| !k.trim().is_empty());
    let (true, true, Some(key)) = (upgrade, version, key) else {
        let _ = req.respond(error(400, "expected a WebSocket (version 13) handshake"));
        return;
    };
    let Some(client) = shared.join() else {
        let _ = req.respond(error(503, "too many pages connected"));
        return;
    };
    let accept = tungstenite::handshake::derive_accept_key(key.trim().as_bytes());
    let reply = with_headers(
        Response::empty(101),
        &[("Sec-WebSocket-Accept", accept.as_str())],
    );
    let stream = req.upgrade("websocket", reply);
    let spawned = std::thread::Builder::new()
        .name("cirrus-preview-ws".into())
        .spawn(move || {
            send_frames(
                WebSocket::from_raw_socket(stream, Role::Server, None),
                &shared,
                client,
            )
        });
    // Without a thread the stream and guard drop here: the page is refused.
    drop(spawned);
}

fn send_frames<S: std::io::Read + std::io::Write>(
    mut ws: WebSocket<S>,
    shared: &Shared,
    _client: ClientGuard,
) {
    let mut last = 0;
    loop {
        let sent = match shared.next_frame(last, PING_AFTER) {
            Some(frame) => {
                last = frame.id;
                ws.send(Message::text(frame.meta.clone()))
                    .and_then(|_| match &frame.png {
                        Some(png) => ws.send(Message::binary(png.as_ref().clone())),
                        None => Ok(()),
                    })
            }
            None if shared.is_quitting() => {
                let _ = ws.close(None);
                let _ = ws.flush();
                return;
            }
            None => ws.send(Message::Ping(Vec::new().into())),
        };
        if sent.is_err() {
            return;
        }
    }
}
