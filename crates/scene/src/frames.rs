//! Frame sequences: ranges like `1-240:2` and paths like `cloud.####.vdb`.
//!
//! A run of `#` is the frame number zero-padded to the run's length (as
//! Houdini and Nuke write it); `%d`, `%4d` and `%04d` are printf's forms.
//! `%%` is a literal `%`; any other `%` is kept as it is. A negative frame
//! keeps its sign in front of the padding, as printf does (`-005`).

use std::path::{Path, PathBuf};

/// More frames than this in one range is a typo, not a shot.
pub const MAX_FRAMES: u64 = 1_000_000;

/// The frames `first`, `first + step`, ... up to and including `last`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    pub first: i64,
    pub last: i64,
    pub step: u64,
}

impl FrameRange {
    /// `A`, `A-B` or `A-B:S` (`B >= A`, `S >= 1`; A and B may be negative).
    pub fn parse(s: &str) -> Result<FrameRange, String> {
        let bad = || format!("frames {s:?}: expected A, A-B or A-B:STEP");
        let (range, step) = match s.trim().split_once(':') {
            Some((r, st)) => (r, st.trim().parse::<u64>().map_err(|_| bad())?),
            None => (s.trim(), 1),
        };
        // The separator is the first '-' after the first character, so
        // that "-5--2" is -5 to -2.
        let split = range
            .char_indices()
            .skip(1)
            .find(|&(_, c)| c == '-')
            .map(|(i, _)| i);
        let (first, last) = match split {
            Some(i) => (&range[..i], &range[i + 1..]),
            None => (range, range),
        };
        let first: i64 = first.trim().parse().map_err(|_| bad())?;
        let last: i64 = last.trim().parse().map_err(|_| bad())?;
        if step == 0 || last < first {
            return Err(format!(
                "frames {s:?}: the range must not be empty and the step at least 1"
            ));
        }
        let r = FrameRange { first, last, step };
        if r.count() > MAX_FRAMES {
            return Err(format!(
                "frames {s:?}: {} frames is over the limit of {MAX_FRAMES}",
                r.count()
            ));
        }
        Ok(r)
    }

    pub fn count(&self) -> u64 {
        (self.last.abs_diff(self.first)) / self.step + 1
    }

    pub fn frames(&self) -> impl Iterator<Item = i64> {
        let r = *self;
        (0..r.count()).map(move |k| r.first + (k * r.step) as i64)
    }
}

/// Whether `s` holds a frame pattern.
pub fn has_pattern(s: &str) -> bool {
    s.contains('#') || substitute_str(s, 0) != s.replace("%%", "%")
}

/// `path` with every frame pattern replaced by `frame`.
pub fn substitute(path: &Path, frame: i64) -> PathBuf {
    PathBuf::from(substitute_str(&path.to_string_lossy(), frame))
}

fn padded(frame: i64, width: usize) -> String {
    if frame < 0 {
        format!("-{:0w$}", frame.unsigned_abs(), w = width.saturating_sub(1))
    } else {
        format!("{frame:0width$}")
    }
}

fn substitute_str(s: &str, frame: i64) -> String {
    let mut out = String::with_capacity(s.len() + 8);
    let chars: Vec<char> = s.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        match chars[i] {
            '#' => {
                let run = chars[i..].iter().take_while(|&&c| c == '#').count();
                out.push_str(&padded(frame, run));
                i += run;
            }
            '%' if chars.get(i + 1) == Some(&'%') => {
                out.push('%');
                i += 2;
            }
            '%' => {
                // %d, %Nd, %0Nd.
                let digits: String = chars[i + 1..]
                    .iter()
                    .take_while(|c| c.is_ascii_digit())
                    .collect();
                if chars.get(i + 1 + digits.len()) == Some(&'d') && digits.len() <= 2 {
                    let width = digits.parse::<usize>().unwrap_or(0);
                    if digits.starts_with('0') {
                        out.push_str(&padded(frame, width));
                    } else {
                        out.push_str(&format!("{frame:>width$}"));
                    }
                    i += digits.len() + 2;
                } else {
                    out.push('%');
                    i += 1;
                }
            }
            c => {
                out.push(c);
                i += 1;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_and_refuse() {
        let r = FrameRange::parse("1-240:2").unwrap();
        assert_eq!((r.first, r.last, r.step, r.count()), (1, 240, 2, 120));
        assert_eq!(r.frames().last(), Some(239));
        assert_eq!(
            FrameRange::parse("7").unwrap().frames().collect::<Vec<_>>(),
            [7]
        );
        let n = FrameRange::parse("-5--2").unwrap();
        assert_eq!(n.frames().collect::<Vec<_>>(), [-5, -4, -3, -2]);
        assert!(FrameRange::parse("5-1").is_err());
        assert!(FrameRange::parse("1-5:0").is_err());
        assert!(FrameRange::parse("a-b").is_err());
        assert!(FrameRange::parse("0-5000000")
            .unwrap_err()
            .contains("limit"));
    }

    #[test]
    fn patterns_substitute() {
        let p = |s: &str, f| substitute(Path::new(s), f).to_string_lossy().into_owned();
        assert_eq!(p("cloud.####.vdb", 12), "cloud.0012.vdb");
        assert_eq!(p("cloud.#.vdb", 12), "cloud.12.vdb");
        assert_eq!(p("out.%04d.exr", 7), "out.0007.exr");
        assert_eq!(p("out.%d.exr", 7), "out.7.exr");
        assert_eq!(p("out.%3d.exr", 7), "out.  7.exr");
        assert_eq!(p("f.####.vdb", -5), "f.-005.vdb");
        assert_eq!(p("100%.exr", 3), "100%.exr");
        assert_eq!(p("a%%b.%02d", 3), "a%b.03");
        assert!(has_pattern("a.####.vdb") && has_pattern("a.%04d.vdb") && has_pattern("%d"));
        assert!(!has_pattern("100%.exr") && !has_pattern("plain.vdb") && !has_pattern("a%%b"));
    }
}
