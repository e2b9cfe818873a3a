//! Lookups and walks on a memory-mapped .cbrk: the micro-benchmark behind
//! `Section`'s cached slice. `cargo run --release -p cirrus-bricks
//! --example mapped_lookups -- FILE.cbrk` (make one with `cirrus convert`).

fn main() {
    let path = std::env::args()
        .nth(1)
        .expect("usage: mapped_lookups FILE.cbrk");
    let v = cirrus_bricks::read_cbrk(std::path::Path::new(&path)).unwrap();
    let rays = cirrus_bench::measure::random_rays(&v, 20000, 1);
    let pts: Vec<glam::Vec3> = rays
        .iter()
        .flat_map(|r| (0..16).map(move |k| r.origin + r.dir * (r.t_max * (k as f32 + 0.5) / 16.0)))
        .collect();
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t = std::time::Instant::now();
        let s: f32 = pts.iter().map(|&p| v.trilinear(p)).sum();
        let n: usize = rays
            .iter()
            .map(|r| v.segments(r.origin, r.dir, 0.0, r.t_max).count())
            .sum();
        std::hint::black_box((s, n));
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!(
        "{} lookups and {} ray walks: best of 5 {:.4} s",
        pts.len(),
        rays.len(),
        best
    );
}
