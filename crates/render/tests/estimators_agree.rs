//! The three shadow-ray estimators, and local versus global majorants,
//! estimate the same image.

mod common;

use cirrus_render::{render, IntegratorKind, Lights, MajorantMode, TransmittanceEstimator};
use glam::Vec3;

#[test]
fn transmittance_estimators_and_majorant_modes_converge_to_the_same_image() {
    // A sun with a 3 degree disc (so its MIS path runs) plus a sky.
    let lights = Lights::sun_and_sky(common::sun(3.0), common::env(Vec3::new(0.2, 0.3, 0.45)));
    let scene = common::scene(
        common::medium(common::cloud_field(4), 8.0, 0.9, 0.5),
        20,
        lights,
    );
    let run = |estimator, majorant, seed| {
        let mut s = common::settings(IntegratorKind::Path, 64, seed);
        s.transmittance = estimator;
        s.majorant = majorant;
        let out = render(&scene, &s);
        assert_eq!(
            out.stats.counters.nonfinite_samples + out.stats.counters.collision_cap_hits,
            0
        );
        out.image
    };
    // Different seeds: the images are independent, so the variance of a
    // difference is the sum of the variances.
    let ratio = run(TransmittanceEstimator::Ratio, MajorantMode::Hierarchy, 1);
    let residual = run(TransmittanceEstimator::Residual, MajorantMode::Hierarchy, 2);
    let track = run(
        TransmittanceEstimator::TrackLength,
        MajorantMode::Hierarchy,
        3,
    );
    let global = run(TransmittanceEstimator::Ratio, MajorantMode::Global, 4);
    // Four pooled comparisons, each with a false-failure rate near 1e-4:
    // about 4e-4 together.
    for (label, other) in [
        ("residual", &residual),
        ("track-length", &track),
        ("global", &global),
    ] {
        common::assert_pooled_agreement(
            &format!("ratio vs {label}"),
            &common::differences(&ratio, other, 1),
        );
    }
    common::assert_pooled_agreement(
        "residual vs track-length",
        &common::differences(&residual, &track, 1),
    );
}
