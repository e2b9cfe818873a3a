//! The same seed gives a bit-identical image with 1 and 2 threads.

mod common;

use cirrus_render::{
    fitted_tile_size, render, Budget, IntegratorKind, Lights, MajorantMode, Rendered,
};

fn render_with_threads(threads: usize, kind: IntegratorKind, seed: u64) -> Rendered {
    let scene = common::sunlit_cloud();
    let mut settings = common::settings(kind, 8, seed);
    // Tiles smaller than the image so two workers really share it.
    settings.tile_size = 8;
    settings.step_voxels = 2.0;
    common::with_threads(threads, || render(&scene, &settings))
}

#[test]
fn same_seed_same_image_for_any_thread_count() {
    for kind in [
        IntegratorKind::Path,
        IntegratorKind::RayMarch,
        IntegratorKind::RayMarch2Pass,
    ] {
        let one = render_with_threads(1, kind, 42);
        let two = render_with_threads(2, kind, 42);
        let bits = common::image_bits;
        assert_eq!(bits(&one), bits(&two), "{kind:?}: images differ");
        // Work counters are sums of per-tile integers: identical too.
        assert_eq!(
            one.stats.counters.density_lookups, two.stats.counters.density_lookups,
            "{kind:?}"
        );
        assert_eq!(
            one.stats.counters.shadow_rays, two.stats.counters.shadow_rays,
            "{kind:?}"
        );
        // A different seed changes the image.
        let other = render_with_threads(2, kind, 43);
        assert_ne!(bits(&one), bits(&other), "{kind:?}: seed ignored");
    }
}

#[test]
fn time_budget_reports_the_samples_it_reached() {
    let lights = Lights::sun_and_sky(common::sun(0.0), None);
    let scene = common::scene(
        common::medium(common::cloud_field(4), 8.0, 0.9, 0.5),
        8,
        lights,
    );
    let mut settings = common::settings(IntegratorKind::Path, 1, 5);
    settings.budget = Budget::Time(0.3);
    settings.majorant = MajorantMode::Global;
    let out = render(&scene, &settings);
    assert!(out.stats.spp >= 1 && out.image.spp == out.stats.spp);
    assert_eq!(out.stats.counters.paths, 64 * u64::from(out.stats.spp));
    // Passes are sized to fit the budget; allow generous scheduling slack.
    assert!(
        out.stats.wall_seconds < 0.3 + 1.0,
        "took {} s",
        out.stats.wall_seconds
    );
    // A time-budgeted image equals the fixed-spp image with the spp reached:
    // samples are keyed by index, not by pass.
    settings.budget = Budget::Spp(out.stats.spp);
    let fixed = render(&scene, &settings);
    assert_eq!(out.image.rgba, fixed.image.rgba);
    let json = out.stats.to_json();
    for key in [
        "wall_seconds",
        "paths",
        "spp",
        "density_lookups",
        "real_collisions",
        "null_collisions",
        "dda_segments",
        "rays_per_second",
    ] {
        assert!(
            json.contains(&format!("\"{key}\"")),
            "{key} missing from {json}"
        );
    }
}

/// Tiles are units of work only: any tile edge gives the same bits (the
/// render picks the edge by thread count, [`fitted_tile_size`]).
#[test]
fn any_tile_size_gives_the_same_image() {
    let scene = common::sunlit_cloud();
    let mut settings = common::settings(IntegratorKind::Path, 8, 3);
    let threads = rayon::current_num_threads();
    let mut edges = Vec::new();
    let mut images = Vec::new();
    for tile in [16, 5, 1] {
        settings.tile_size = tile;
        // The scene's image is 20x20.
        edges.push(fitted_tile_size(tile, 20, 20, threads));
        images.push(common::image_bits(&render(&scene, &settings)));
    }
    assert!(
        edges[0] != edges[1] && edges[1] != edges[2],
        "edges {edges:?}"
    );
    assert_eq!(images[0], images[1], "edges {edges:?}");
    assert_eq!(images[0], images[2], "edges {edges:?}");
}

/// The tile edge halves until each thread has its share of tiles, and
/// never below 4 unless asked.
#[test]
fn the_tile_edge_fits_the_threads() {
    // 128x128 in 8-pixel tiles: 256 tiles, enough for 16 threads...
    assert_eq!(fitted_tile_size(8, 128, 128, 16), 8);
    // ...not for 17 or 64: 4 pixels (1024 tiles), and no smaller.
    assert_eq!(fitted_tile_size(8, 128, 128, 17), 4);
    assert_eq!(fitted_tile_size(8, 128, 128, 64), 4);
    // A large image keeps the edge asked for.
    assert_eq!(fitted_tile_size(16, 1920, 1080, 64), 16);
    // 160x120 on 2 threads: 300 tiles of 8 pixels, 80 of 16 (enough).
    assert_eq!(fitted_tile_size(16, 160, 120, 2), 16);
    assert_eq!(fitted_tile_size(16, 160, 120, 8), 8);
    // An edge asked below 4 stays; an empty window does not loop.
    assert_eq!(fitted_tile_size(3, 64, 64, 64), 3);
    assert_eq!(fitted_tile_size(8, 0, 0, 4), 4);
}
