//! Properties of the Owen-scrambled Sobol points and of the sample streams
//! built on them: stratification (elementary intervals), scrambling that
//! keeps it, values in [0, 1), uniformity over seeds (unbiasedness), and
//! the random sampler's bit-compatibility with the plain `Rng`.

use cirrus_kernel::sampling::{Draw, SampleStream, SamplerKind, SOBOL_VERTICES};
use cirrus_kernel::sobol::{owen_scramble, sobol, OwenSobol, SobolIndex};
use cirrus_kernel::Rng;

fn set(seed: u64) -> OwenSobol {
    let h = cirrus_kernel::sampling::mix64(seed);
    OwenSobol {
        shuffle: h as u32,
        scramble: [(h >> 32) as u32, cirrus_kernel::sampling::mix64(h) as u32],
    }
}

/// Whether `points` (32-bit fractions, `2^m` of them) put exactly one point
/// in every elementary interval `[i 2^-a, (i+1) 2^-a) x [j 2^-b, (j+1) 2^-b)`
/// with `a + b = m`: a (0, m, 2)-net in base 2, every shape checked.
fn is_net(points: &[[u32; 2]], m: u32) -> Result<(), String> {
    assert_eq!(points.len(), 1 << m);
    for a in 0..=m {
        let b = m - a;
        let mut seen = vec![false; 1 << m];
        for p in points {
            let i = if a == 0 { 0 } else { p[0] >> (32 - a) };
            let j = if b == 0 { 0 } else { p[1] >> (32 - b) };
            let cell = ((i << b) | j) as usize;
            if seen[cell] {
                return Err(format!("shape 2^-{a} x 2^-{b}: two points in cell {cell}"));
            }
            seen[cell] = true;
        }
    }
    Ok(())
}

#[test]
fn unscrambled_sobol_blocks_are_nets() {
    for m in 0..=10 {
        for block in 0..4u32 {
            let pts: Vec<[u32; 2]> = (0..1u32 << m)
                .map(|i| {
                    let index = (block << m) + i;
                    [sobol(0, index), sobol(1, index)]
                })
                .collect();
            is_net(&pts, m).unwrap_or_else(|e| panic!("m = {m}, block {block}: {e}"));
        }
    }
}

#[test]
fn shuffled_scrambled_prefixes_and_blocks_are_nets() {
    for seed in 0..20u64 {
        let s = set(seed);
        for m in 0..=10 {
            // The first 2^m points (what a pixel with 2^m samples uses) and
            // the next aligned block (its next 2^m samples).
            for block in 0..2u32 {
                let pts: Vec<[u32; 2]> = (0..1u32 << m)
                    .map(|i| s.point_bits((block << m) + i))
                    .collect();
                is_net(&pts, m)
                    .unwrap_or_else(|e| panic!("seed {seed}, m = {m}, block {block}: {e}"));
            }
        }
    }
}

#[test]
fn one_dimensional_draws_are_stratified() {
    for seed in 0..20u64 {
        let s = set(seed);
        for m in 0..=12 {
            let mut seen = vec![false; 1 << m];
            for i in 0..1u32 << m {
                let u = s.get_1d(SobolIndex::new(i));
                let cell = (u * (1u32 << m) as f32) as usize;
                assert!(!seen[cell], "seed {seed}, m = {m}: cell {cell} twice");
                seen[cell] = true;
            }
        }
    }
}

#[test]
fn values_lie_in_the_unit_interval() {
    // Indices and seeds at the edges, and the largest fraction there is.
    for seed in [0u64, 1, u64::MAX, 0x1234_5678_9abc_def0] {
        let s = set(seed);
        for i in [0u32, 1, 2, 255, 256, 65535, 1 << 31, u32::MAX - 1, u32::MAX] {
            let (x, y) = s.get_2d(SobolIndex::new(i));
            let u = s.get_1d(SobolIndex::new(i));
            for v in [x, y, u] {
                assert!((0.0..1.0).contains(&v), "seed {seed}, index {i}: {v}");
            }
        }
    }
    assert!(cirrus_kernel::sobol::to_unit(u32::MAX) < 1.0);
    // Over many streams too.
    for pixel in 0..2000u64 {
        let mut d = SampleStream::new(SamplerKind::Sobol, 9, pixel, (pixel * 7919) as u32);
        for v in 0..SOBOL_VERTICES + 1 {
            let (a, b) = d.get_2d(Draw::Phase, v);
            let c = d.get_1d(Draw::Roulette, v);
            assert!([a, b, c].iter().all(|x| (0.0..1.0).contains(x)));
        }
    }
}

/// A scrambled point is uniform over scramble seeds (what makes estimates
/// unbiased): a fixed index's first coordinate over 16384 seeds, in 64 bins,
/// by chi-square (63 degrees of freedom; the bound 120 is exceeded with
/// probability about 1e-5).
#[test]
fn a_scrambled_point_is_uniform_over_seeds() {
    for index in [0u32, 1, 5, 1000] {
        for dim in 0..2 {
            let mut bins = [0u32; 64];
            let n = 16384;
            for seed in 0..n as u64 {
                let p = set(seed).point_bits(index)[dim];
                bins[(p >> 26) as usize] += 1;
            }
            let e = n as f64 / 64.0;
            let chi2: f64 = bins.iter().map(|&o| (o as f64 - e).powi(2) / e).sum();
            assert!(chi2 < 120.0, "index {index} dim {dim}: chi2 {chi2}");
        }
    }
}

#[test]
fn the_scramble_is_a_bijection_that_keeps_leading_digits_nested() {
    // Owen's property: the first k output digits depend only on the first
    // k input digits. Two fractions sharing their first 8 digits keep
    // sharing 8 digits after the scramble.
    for seed in [3u32, 77, 0xfeed_f00d] {
        for x in [0u32, 0x8000_0000, 0x1234_5678, 0xffff_0000] {
            let y = x ^ 0x0000_ffff; // differs below digit 16
            assert_eq!(
                owen_scramble(x, seed) >> 16,
                owen_scramble(y, seed) >> 16,
                "seed {seed}, x {x:#x}"
            );
        }
        let mut outs: Vec<u32> = (0..4096u32).map(|i| owen_scramble(i << 20, seed)).collect();
        outs.sort_unstable();
        outs.dedup();
        assert_eq!(outs.len(), 4096, "seed {seed}: not injective");
    }
}

#[test]
fn random_streams_are_the_plain_rng() {
    for (seed, pixel, sample) in [(0u64, 0u64, 0u32), (5, 1234, 77), (u64::MAX, 9, 1 << 20)] {
        let mut r = Rng::new(seed, pixel, u64::from(sample));
        let mut d = SampleStream::new(SamplerKind::Random, seed, pixel, sample);
        let (a, b) = d.get_2d(Draw::PixelJitter, 0);
        assert_eq!((a, b), (r.uniform(), r.uniform()));
        assert_eq!(d.get_1d(Draw::FreeFlight, 0), r.uniform());
        let (a, b) = d.get_2d(Draw::Phase, 3);
        assert_eq!((a, b), (r.uniform(), r.uniform()));
        let led = d.leading(Draw::LightShadow(0), 0, |rng| rng.uniform());
        assert_eq!(led, r.uniform());
        assert_eq!(d.rng().uniform(), r.uniform());
    }
}

#[test]
fn a_led_tracker_draws_the_sobol_number_first_then_the_stream() {
    let mut d = SampleStream::new(SamplerKind::Sobol, 4, 10, 3);
    let mut plain = d.clone();
    let first = plain.get_1d(Draw::FreeFlight, 2);
    let mut rest = plain.rng().clone();
    let (a, b) = d.leading(Draw::FreeFlight, 2, |rng| (rng.uniform(), rng.uniform()));
    assert_eq!((a, b), (first, rest.uniform()));
    // A number the tracker left undrawn is dropped.
    d.leading(Draw::FreeFlight, 2, |_| ());
    assert_eq!(d.rng().uniform(), rest.uniform());
    // Past the vertex budget the draw is the stream's.
    let mut e = SampleStream::new(SamplerKind::Sobol, 4, 10, 3);
    let mut r = e.rng().clone();
    assert_eq!(e.get_1d(Draw::FreeFlight, SOBOL_VERTICES), r.uniform());
}

/// Different draws of one sample are independent point sets: over a
/// pixel's 4096 samples the correlation of two draws is near 0 (|r| below
/// 4 / sqrt(n) = 0.0625).
#[test]
fn draws_are_decorrelated() {
    let n = 4096u32;
    let pairs = [
        (Draw::FreeFlight, 0, Draw::Phase, 0),
        (Draw::Phase, 0, Draw::Phase, 1),
        (Draw::PixelJitter, 0, Draw::LightDirection(0), 0),
        (Draw::LightShadow(0), 0, Draw::LightShadow(1), 0),
    ];
    for (da, va, db, vb) in pairs {
        let (mut sa, mut sb, mut sab, mut saa, mut sbb) = (0f64, 0f64, 0f64, 0f64, 0f64);
        for s in 0..n {
            let mut d = SampleStream::new(SamplerKind::Sobol, 1, 42, s);
            let a = d.get_2d(da, va).0 as f64;
            let b = d.get_2d(db, vb).0 as f64;
            sa += a;
            sb += b;
            sab += a * b;
            saa += a * a;
            sbb += b * b;
        }
        let nf = n as f64;
        let cov = sab / nf - sa * sb / (nf * nf);
        let r = cov / ((saa / nf - (sa / nf).powi(2)) * (sbb / nf - (sb / nf).powi(2))).sqrt();
        assert!(r.abs() < 0.0625, "{da:?}@{va} vs {db:?}@{vb}: r = {r}");
    }
}
