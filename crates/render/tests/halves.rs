//! The two halves of each pixel's samples (kept for a denoiser's error
//! estimate) change nothing of the image, are its samples split by parity,
//! and are the same bits in a crop and on any thread count.

mod common;

use cirrus_render::{render, IntegratorKind, Rendered};

fn render_halves(halves: bool, threads: usize, crop: bool) -> Rendered {
    let scene = common::sunlit_cloud();
    let mut s = common::settings(IntegratorKind::Path, 9, 5);
    s.tile_size = 8;
    s.halves = halves;
    if crop {
        s.crop = Some(common::CROP);
    }
    common::with_threads(threads, || render(&scene, &s))
}

#[test]
fn keeping_the_halves_changes_no_pixel_and_they_make_up_the_image() {
    let plain = render_halves(false, 2, false);
    let kept = render_halves(true, 2, false);
    assert!(plain.halves.is_none());
    assert_eq!(common::image_bits(&plain), common::image_bits(&kept));
    let h = kept.halves.as_ref().unwrap();
    let mut worst = 0.0f32;
    for (i, p) in kept.image.rgba.iter().enumerate() {
        // 9 samples: 5 even-numbered (0, 2, ..., 8) and 4 odd.
        assert_eq!(h.samples[i], [5, 4], "pixel {i}");
        for ((a, b), p) in h.a[i].iter().zip(&h.b[i]).zip(p) {
            let joined = (5.0 * a + 4.0 * b) / 9.0;
            worst = worst.max((joined - p).abs() / p.abs().max(1e-3));
        }
    }
    // Two running means against one: equal to float rounding.
    assert!(worst < 1e-5, "largest relative gap {worst:e}");
    // And they are two different estimates, not one image twice.
    assert!(h.a.iter().zip(&h.b).any(|(a, b)| a != b));
}

#[test]
fn the_halves_are_the_same_bits_in_a_crop_and_on_any_thread_count() {
    let full = render_halves(true, 2, false);
    let one = render_halves(true, 1, false);
    assert_eq!(full.halves, one.halves);
    let part = render_halves(true, 3, true);
    let (f, p) = (full.halves.unwrap(), part.halves.unwrap());
    let c = common::CROP;
    let (w, fw) = ((c.x1 - c.x0) as usize, full.image.width as usize);
    for (i, (a, b)) in p.a.iter().zip(&p.b).enumerate() {
        let j = (i / w + c.y0 as usize) * fw + i % w + c.x0 as usize;
        assert_eq!(
            a.map(f32::to_bits),
            f.a[j].map(f32::to_bits),
            "crop pixel {i}"
        );
        assert_eq!(
            b.map(f32::to_bits),
            f.b[j].map(f32::to_bits),
            "crop pixel {i}"
        );
        assert_eq!(p.samples[i], f.samples[j]);
    }
}
