//! What the workspace's tests share, so each crate's tests draw the same
//! numbers from the same generator and read the same corpus:
//! [`SplitMix64`], a seeded generator (so a test mutates or samples the
//! same bytes on every run); [`corpus`], the files of `data/` that the
//! Debian OpenVDB tools wrote (`tools/make_corpus.py`); and
//! [`mutate_past_header`], the edits the streaming readers' fuzz tests
//! make to those files. A dev-dependency only: nothing here ships.

use std::path::{Path, PathBuf};

/// SplitMix64 (Steele, Lea and Flood 2014): a 64-bit state stepped by the
/// golden-ratio increment and finalised by two multiply-xorshift rounds.
/// Seeded, small and good enough for tests; not for rendering (the
/// renderer has its own streams in `cirrus-render`).
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`0` for `n = 0`), up to the modulo's slight bias.
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }

    /// Uniform in `[0, 1)` with 24 bits.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in `[0, 1)` with 53 bits, for estimators in f64.
    pub fn unit_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The corpus files in `data/` with one of `extensions` and, when
/// `max_bytes` is given, smaller than that, sorted by path.
pub fn corpus(extensions: &[&str], max_bytes: Option<u64>) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("data/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| extensions.contains(&e))
        })
        .filter(|p| max_bytes.is_none_or(|max| std::fs::metadata(p).is_ok_and(|m| m.len() < max)))
        .collect();
    files.sort();
    files
}

/// Up to `max_edits` edits (at least one) past a file's first 60 bytes,
/// where its trees are: flip a bit, overwrite a byte, or truncate there.
pub fn mutate_past_header(rng: &mut SplitMix64, bytes: &mut Vec<u8>, max_edits: usize) {
    for _ in 0..1 + rng.below(max_edits) {
        if bytes.len() <= 61 {
            break;
        }
        let i = 60 + rng.below(bytes.len() - 60);
        match rng.below(3) {
            0 => bytes[i] ^= 1 << rng.below(8),
            1 => bytes[i] = rng.next_u64() as u8,
            _ => bytes.truncate(i),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first outputs for seed 0 are SplitMix64's published ones.
    #[test]
    fn splitmix64_matches_the_reference_sequence() {
        let mut r = SplitMix64(0);
        assert_eq!(r.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.next_u64(), 0x6E78_9E6A_A1B9_65F4);
        assert_eq!(r.next_u64(), 0x06C4_5D18_8009_454F);
        // The next output's top 53 bits, scaled.
        let mut r = SplitMix64(0);
        assert_eq!(
            r.unit_f64(),
            (0xE220_A839_7B1D_CDAF_u64 >> 11) as f64 / 2f64.powi(53)
        );
    }

    #[test]
    fn the_corpus_is_found_and_filtered() {
        let all = corpus(&["vdb", "nvdb"], None);
        let vdb = corpus(&["vdb"], None);
        let small = corpus(&["vdb"], Some(200_000));
        assert!(vdb.len() >= 10, "{}", vdb.len());
        assert!(all.len() > vdb.len());
        assert!(small.len() < vdb.len() && !small.is_empty());
        assert!(small
            .iter()
            .all(|p| std::fs::metadata(p).unwrap().len() < 200_000));
    }
}
