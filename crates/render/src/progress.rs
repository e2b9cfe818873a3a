//! The progress of a render: a bar with ETA on a terminal's stderr, or
//! where stderr is not a terminal (a farm's or a batch job's log) a plain
//! line every few seconds, and the count a [`RenderControl`] watches.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::control::RenderControl;
use crate::scene::{Budget, RenderSettings};

/// Seconds between plain progress lines where stderr is not a terminal,
/// unless `$CIRRUS_PROGRESS_INTERVAL` gives another (0: after every tile).
pub const PLAIN_PROGRESS_SECONDS: f64 = 5.0;

/// A progress bar with ETA on a terminal's stderr, plain lines on any
/// other, or nothing when progress is off. Updated once per tile, never
/// per sample.
pub(crate) struct Progress {
    bar: Option<ProgressBar>,
    plain: Option<PlainLines>,
    control: Option<Arc<RenderControl>>,
    /// With a time budget the bar measures milliseconds, not samples.
    timed: Option<(Instant, u64)>,
}

impl Progress {
    pub(crate) fn new(settings: &RenderSettings, width: u32, height: u32) -> Self {
        let (len, timed) = match settings.budget {
            Budget::Spp(n) => {
                let samples = u64::from(width) * u64::from(height) * u64::from(n.max(1));
                (samples, None)
            }
            Budget::Time(s) => {
                let ms = (s * 1000.0).max(1.0) as u64;
                (ms, Some((Instant::now(), ms)))
            }
        };
        let control = settings.control.clone();
        if let Some(c) = &control {
            c.start(len);
        }
        if !settings.progress || !std::io::stderr().is_terminal() {
            return Self {
                bar: None,
                plain: settings.progress.then(|| PlainLines::new(len)),
                control,
                timed,
            };
        }
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
        let style = ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] [{wide_bar}] {percent:>3}% ETA {eta} {msg}",
        )
        .expect("valid template");
        bar.set_style(style);
        Self {
            bar: Some(bar),
            plain: None,
            control,
            timed,
        }
    }

    pub(crate) fn cancelled(&self) -> bool {
        self.control.as_ref().is_some_and(|c| c.is_cancelled())
    }

    pub(crate) fn tile_done(&self, samples: u64) {
        let elapsed_ms = |(t0, ms): (Instant, u64)| (t0.elapsed().as_millis() as u64).min(ms);
        if let Some(c) = &self.control {
            match self.timed {
                None => c.add(samples),
                Some(t) => c.set(elapsed_ms(t)),
            }
        }
        if let Some(plain) = &self.plain {
            match self.timed {
                None => plain.add(samples),
                Some(t) => plain.set(elapsed_ms(t)),
            }
        }
        let Some(bar) = &self.bar else { return };
        match self.timed {
            None => bar.inc(samples),
            Some(t) => bar.set_position(elapsed_ms(t)),
        }
    }

    pub(crate) fn set_spp(&self, spp: u32) {
        if let Some(bar) = &self.bar {
            bar.set_message(format!("{spp} spp"));
        }
    }

    pub(crate) fn finish(&self) {
        if let (Some(c), Some((_, ms))) = (&self.control, self.timed) {
            c.set(ms);
        }
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// Progress as a plain line (`cirrus: rendered 40% in 12.0 s, about 18 s
/// left`) at most every interval, for logs: no bar, no carriage returns.
struct PlainLines {
    len: u64,
    done: AtomicU64,
    start: Instant,
    interval: Duration,
    /// When the last line was printed; one thread prints at a time.
    last: Mutex<Instant>,
}

impl PlainLines {
    fn new(len: u64) -> Self {
        let seconds = std::env::var("CIRRUS_PROGRESS_INTERVAL")
            .ok()
            .and_then(|v| v.trim().parse::<f64>().ok())
            .filter(|s| s.is_finite() && *s >= 0.0)
            .unwrap_or(PLAIN_PROGRESS_SECONDS);
        let start = Instant::now();
        Self {
            len: len.max(1),
            done: AtomicU64::new(0),
            start,
            interval: Duration::from_secs_f64(seconds),
            last: Mutex::new(start),
        }
    }

    fn add(&self, n: u64) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        self.report(done);
    }

    fn set(&self, done: u64) {
        self.done.fetch_max(done, Ordering::Relaxed);
        self.report(done);
    }

    fn report(&self, done: u64) {
        let Ok(mut last) = self.last.try_lock() else {
            return;
        };
        if last.elapsed() < self.interval || done >= self.len {
            return;
        }
        *last = Instant::now();
        let fraction = done as f64 / self.len as f64;
        let elapsed = self.start.elapsed().as_secs_f64();
        let left = elapsed * (1.0 - fraction) / fraction.max(1e-9);
        eprintln!(
            "cirrus: rendered {:.0}% in {elapsed:.1} s, about {left:.0} s left",
            100.0 * fraction
        );
    }
}
