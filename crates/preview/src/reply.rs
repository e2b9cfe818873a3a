//! HTTP replies shared by the routes and the WebSocket upgrade: JSON
//! bodies, errors, and headers added without panicking.

use std::io::{Cursor, Read};

use serde_json::json;
use tiny_http::{Header, Request, Response};

/// A reply with its body in memory.
pub type Reply = Response<Cursor<Vec<u8>>>;

/// The value of request header `name` (any case), if present.
pub fn header(req: &Request, name: &str) -> Option<String> {
    req.headers()
        .iter()
        .find(|h| h.field.as_str().as_str().eq_ignore_ascii_case(name))
        .map(|h| h.value.as_str().to_string())
}

/// `reply` with the given headers; one that does not parse (never, for
/// the constants used here) is left out rather than panicking.
pub fn with_headers<R: Read>(mut reply: Response<R>, headers: &[(&str, &str)]) -> Response<R> {
    for (name, value) in headers {
        if let Ok(h) = Header::from_bytes(name.as_bytes(), value.as_bytes()) {
            reply.add_header(h);
        }
    }
    reply
}

/// `value` as a JSON body with status `code`, never cached.
pub fn json_reply(code: u16, value: serde_json::Value) -> Reply {
    with_headers(
        Response::from_data(value.to_string().into_bytes()).with_status_code(code),
        &[
            ("Content-Type", "application/json"),
            ("Cache-Control", "no-store"),
            ("X-Content-Type-Options", "nosniff"),
        ],
    )
}

/// `{"error": message}` with status `code`.
pub fn error(code: u16, message: &str) -> Reply {
    json_reply(code, json!({"error": message}))
}
