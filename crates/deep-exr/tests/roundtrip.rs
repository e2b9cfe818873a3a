//! A deep image written through OpenEXRCore reads back value for value,
//! and files this crate cannot read are refused with the file named.

use cirrus_deep_exr::{read, write, DeepImage};

fn sample_image() -> DeepImage {
    let mut img = DeepImage::new((5, 4), (1, 2), (3, 2), &["R", "A", "Z"]);
    // Channels are sorted: A, R, Z.
    let pixels: Vec<Vec<Vec<f32>>> = vec![
        vec![],
        vec![vec![0.5, 0.25, 1.0]],
        vec![vec![0.1, 0.2, 2.0], vec![0.3, 0.4, 3.5]],
        vec![vec![1.0, 0.0, 7.0]],
        vec![],
        vec![
            vec![0.0, 9.0, 1e10],
            vec![0.2, 0.1, 4.0],
            vec![0.7, 0.6, 5.0],
        ],
    ];
    for p in &pixels {
        img.push_pixel(p);
    }
    img
}

#[test]
fn deep_pixels_read_back_exactly() {
    let dir = std::env::temp_dir().join(format!("cirrus-deep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("roundtrip.exr");
    let img = sample_image();
    assert_eq!(img.channels, ["A", "R", "Z"]);
    write(&path, &img).unwrap();
    let back = read(&path).unwrap();
    assert_eq!(back, img);
    assert_eq!(back.counts, [0, 1, 2, 1, 0, 3]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_flat_or_missing_file_is_refused_by_name() {
    let e = read(std::path::Path::new("/nonexistent/none.exr")).unwrap_err();
    assert!(e.to_string().contains("none.exr"), "{e}");
    let flat = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/sky.exr");
    let e = read(std::path::Path::new(flat)).unwrap_err().to_string();
    assert!(e.contains("sky.exr") && e.contains("deep"), "{e}");
}
