//! A render stops soon after it is cancelled, even when one pass holds a
//! pixel's whole (huge) sample budget.

mod common;

use std::sync::Arc;
use std::time::{Duration, Instant};

use cirrus_render::{render, IntegratorKind, Lights, RenderControl};
use glam::Vec3;

#[test]
fn a_cancelled_render_stops_within_a_few_samples_per_pixel() {
    let lights = Lights::sun_and_sky(common::sun(0.0), common::env(Vec3::new(0.3, 0.4, 0.6)));
    let scene = common::scene(
        common::medium(common::cloud_field(4), 12.0, 0.9, 0.5),
        32,
        lights,
    );
    let control = Arc::new(RenderControl::new());
    let mut settings = common::settings(IntegratorKind::Path, 10_000_000, 1);
    settings.control = Some(control.clone());
    let canceller = {
        let control = control.clone();
        std::thread::spawn(move || {
            // Cancel once the render has begun.
            while control.progress().1 == 0 {
                std::thread::sleep(Duration::from_millis(5));
            }
            std::thread::sleep(Duration::from_millis(100));
            control.cancel();
            Instant::now()
        })
    };
    let out = render(&scene, &settings);
    let stopped = Instant::now();
    let cancelled_at = canceller.join().unwrap();
    assert!(control.is_cancelled());
    // A hang guard, not a speed check: the whole budget is 10^7 samples a
    // pixel (hours); stopping takes at most CANCEL_CHECK samples a thread.
    let latency = stopped.saturating_duration_since(cancelled_at);
    assert!(
        latency < Duration::from_secs(20),
        "stopped {latency:?} after the cancel"
    );
    // Far fewer paths than the budget were traced.
    assert!(out.stats.counters.paths < 32 * 32 * 10_000);
}
