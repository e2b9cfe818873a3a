//! The state the request handlers, the render thread and the WebSocket
//! senders share: the view and its version, the pass being rendered (so a
//! change can cancel it), the connected clients, and the latest frame.
//!
//! One mutex guards it all; nothing slow happens while it is held. Two
//! condition variables wake the render thread (`work`) and the frame
//! senders (`frames`).

use std::path::PathBuf;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use cirrus_render::{Image, RenderControl};
use cirrus_scene::Overrides;

use crate::view::{Lighting, View, ViewPatch};

/// What never changes while the server runs.
pub struct Info {
    /// The volume or scene file given on the command line, as given.
    pub input: PathBuf,
    /// `"volume"` or `"scene"`.
    pub kind: &'static str,
    /// The resolution asked for; frames shrink to fit the page.
    pub base_res: (u32, u32),
    pub lighting: Lighting,
    /// Accumulation stops here.
    pub max_spp: u32,
    /// With no page connected, rendering stops this long after the last
    /// change (reads do not count: only a page or a change keeps it going).
    pub idle: Duration,
    /// The only files the server writes.
    pub save_exr: PathBuf,
    pub save_png: PathBuf,
    /// `Err(why)` when Open Image Denoise did not load.
    pub denoiser: Result<String, String>,
}

/// One message for the page: JSON metadata and, for a frame, its PNG.
pub struct Frame {
    pub id: u64,
    pub meta: String,
    pub png: Option<Arc<Vec<u8>>>,
}

/// The last full-resolution accumulation, for Save and Copy command.
pub struct Snapshot {
    /// Linear radiance.
    pub image: Image,
    /// The PNG the page shows.
    pub png: Arc<Vec<u8>>,
    /// What reproduces it with `cirrus render`.
    pub overrides: Overrides,
}

/// The pass on the render thread.
pub struct Running {
    pub control: Arc<RenderControl>,
    /// What it renders (without spp and seed).
    pub key: Overrides,
    /// A quick low-resolution pass: left to finish when the view changes,
    /// so a drag shows frames at the pace passes complete.
    pub preview: bool,
}

pub struct State {
    pub view: View,
    /// Bumped by every accepted change.
    pub version: u64,
    pub running: Option<Running>,
    /// Connected pages (WebSockets).
    pub clients: usize,
    pub last_activity: Instant,
    pub quit: bool,
    /// Exposure or denoising changed: re-encode the frame, no re-render.
    pub redisplay: bool,
    pub frame: Option<Arc<Frame>>,
    pub snapshot: Option<Arc<Snapshot>>,
    /// The metadata of the last frame or error (the page's readout).
    pub status: serde_json::Value,
    next_frame_id: u64,
}

pub struct Shared {
    pub info: Info,
    state: Mutex<State>,
    work: Condvar,
    frames: Condvar,
}

/// Most pages at once: each holds a thread.
const MAX_CLIENTS: usize = 16;

impl Shared {
    pub fn new(info: Info, view: View) -> Self {
        Shared {
            info,
            state: Mutex::new(State {
                view,
                version: 0,
                running: None,
                clients: 0,
                last_activity: Instant::now(),
                quit: false,
                redisplay: false,
                frame: None,
                snapshot: None,
                status: serde_json::json!({"type": "status", "spp": 0}),
                next_frame_id: 1,
            }),
            work: Condvar::new(),
            frames: Condvar::new(),
        }
    }

    /// The state, locked. A thread that panicked while holding the lock
    /// left plain data behind, which stays usable.
    pub fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Applies a patch from the page: a change to what is rendered cancels
    /// the running full-resolution pass. Returns the new view.
    pub fn patch(&self, patch: &ViewPatch) -> Result<View, String> {
        let mut st = self.lock();
        let new = st.view.patched(patch)?;
        let key =
            |v: &View| v.render_overrides(&self.info.lighting, v.resolution(self.info.base_res));
        let new_key = key(&new);
        if let Some(r) = &st.running {
            if !r.preview && r.key != new_key {
                r.control.cancel();
            }
        }
        if new.exposure != st.view.exposure || new.denoise != st.view.denoise {
            st.redisplay = true;
        }
        st.view = new.clone();
        st.version += 1;
        st.last_activity = Instant::now();
        drop(st);
        self.work.notify_all();
        Ok(new)
    }

    /// Waits for a reason to look at the state again (bounded, so idle
    /// time-outs are noticed).
    pub fn wait_work<'a>(&self, guard: MutexGuard<'a, State>) -> MutexGuard<'a, State> {
        self.work
            .wait_timeout(guard, Duration::from_millis(250))
            .map(|(g, _)| g)
            .unwrap_or_else(|e| e.into_inner().0)
    }

    /// Sends a message to every page.
    pub fn publish(&self, meta: serde_json::Value, png: Option<Arc<Vec<u8>>>) {
        let mut st = self.lock();
        let id = st.next_frame_id;
        st.next_frame_id += 1;
        let mut meta = meta;
        meta["id"] = id.into();
        st.frame = Some(Arc::new(Frame {
            id,
            meta: meta.to_string(),
            png,
        }));
        st.status = meta;
        drop(st);
        self.frames.notify_all();
    }

    /// Waits up to `timeout` for a message newer than `after`; `None` on
    /// time-out or shutdown.
    pub fn next_frame(&self, after: u64, timeout: Duration) -> Option<Arc<Frame>> {
        let deadline = Instant::now() + timeout;
        let mut st = self.lock();
        loop {
            if st.quit {
                return None;
            }
            if let Some(f) = st.frame.as_ref().filter(|f| f.id > after) {
                return Some(f.clone());
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return None;
            }
            st = self
                .frames
                .wait_timeout(st, left)
                .map(|(g, _)| g)
                .unwrap_or_else(|e| e.into_inner().0);
        }
    }

    /// Registers a page; `None` when too many are connected. Dropping the
    /// guard unregisters it.
    pub fn join(self: &Arc<Self>) -> Option<ClientGuard> {
        let mut st = self.lock();
        if st.clients >= MAX_CLIENTS || st.quit {
            return None;
        }
        st.clients += 1;
        st.last_activity = Instant::now();
        drop(st);
        self.work.notify_all();
        Some(ClientGuard(self.clone()))
    }

    pub fn is_quitting(&self) -> bool {
        self.lock().quit
    }

    /// Stops the render thread and the senders.
    pub fn quit(&self) {
        let mut st = self.lock();
        st.quit = true;
        if let Some(r) = &st.running {
            r.control.cancel();
        }
        drop(st);
        self.work.notify_all();
        self.frames.notify_all();
    }
}

/// A connected page; counted while it lives.
pub struct ClientGuard(Arc<Shared>);

impl Drop for ClientGuard {
    fn drop(&mut self) {
        let mut st = self.0.lock();
        st.clients = st.clients.saturating_sub(1);
        st.last_activity = Instant::now();
    }
}
