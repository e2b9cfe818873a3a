//! Merging the majorant segments of overlapping instances.
//!
//! Where instances overlap, extinction adds: `sigma_t = sum of sigma_t,i`.
//! A bound of a sum is the sum of the bounds, so over every interval where
//! the set of current per-instance segments does not change, the merged
//! segment's majorant (minorant) is the sum of theirs; an instance outside
//! its segments contributes 0 to both (its density is 0 in its gaps). The
//! merged stream is front to back and disjoint like any field's, so delta,
//! ratio and residual ratio tracking run on it unchanged and stay unbiased.

use smallvec::SmallVec;

use crate::medium::{MajorantSegment, Scaled};

/// One instance's segment stream with its current segment.
struct Track<I> {
    segments: Scaled<I>,
    current: Option<MajorantSegment>,
}

/// The merged stream; see the module doc.
pub struct Merged<I> {
    tracks: SmallVec<[Track<I>; 4]>,
    t: f32,
}

impl<I: Iterator<Item = MajorantSegment>> Merged<I> {
    /// `streams` are the instances' segments in extinction units.
    pub fn new(streams: impl IntoIterator<Item = Scaled<I>>) -> Self {
        let mut tracks = SmallVec::new();
        let mut t = f32::INFINITY;
        for mut segments in streams {
            let current = segments.next();
            if let Some(s) = current {
                t = t.min(s.t0);
                tracks.push(Track { segments, current });
            }
        }
        Self { tracks, t }
    }
}

impl<I: Iterator<Item = MajorantSegment>> Iterator for Merged<I> {
    type Item = MajorantSegment;

    fn next(&mut self) -> Option<MajorantSegment> {
        loop {
            let t = self.t;
            let (mut minorant, mut majorant) = (0.0f32, 0.0f32);
            let mut t_next = f32::INFINITY;
            let mut active = false;
            let mut k = 0;
            while k < self.tracks.len() {
                let track = &mut self.tracks[k];
                // Drop segments that end at or before t.
                while track.current.is_some_and(|s| s.t1 <= t) {
                    track.current = track.segments.next();
                }
                let Some(s) = track.current else {
                    self.tracks.swap_remove(k);
                    continue;
                };
                if s.t0 <= t {
                    minorant += s.minorant;
                    majorant += s.majorant;
                    t_next = t_next.min(s.t1);
                    active = true;
                } else {
                    t_next = t_next.min(s.t0);
                }
                k += 1;
            }
            if self.tracks.is_empty() {
                return None;
            }
            self.t = t_next;
            if active {
                return Some(MajorantSegment {
                    t0: t,
                    t1: t_next,
                    minorant,
                    majorant,
                });
            }
            // A gap in every stream: jump to the next start.
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(t0: f32, t1: f32, minorant: f32, majorant: f32) -> MajorantSegment {
        MajorantSegment {
            t0,
            t1,
            minorant,
            majorant,
        }
    }

    #[test]
    fn overlapping_streams_add_over_each_interval() {
        let a = vec![seg(0.0, 2.0, 1.0, 2.0), seg(3.0, 4.0, 0.0, 1.0)];
        let b = vec![seg(1.0, 3.5, 0.5, 0.5)];
        let merged: Vec<_> = Merged::new([
            Scaled::new(a.into_iter(), 1.0),
            Scaled::new(b.into_iter(), 2.0),
        ])
        .collect();
        assert_eq!(
            merged,
            vec![
                seg(0.0, 1.0, 1.0, 2.0),
                seg(1.0, 2.0, 2.0, 3.0),
                seg(2.0, 3.0, 1.0, 1.0),
                seg(3.0, 3.5, 1.0, 2.0),
                seg(3.5, 4.0, 0.0, 1.0),
            ]
        );
    }

    #[test]
    fn gaps_between_streams_are_skipped() {
        let a = vec![seg(0.0, 1.0, 0.0, 1.0)];
        let b = vec![seg(5.0, 6.0, 0.0, 3.0)];
        let merged: Vec<_> = Merged::new([
            Scaled::new(a.into_iter(), 1.0),
            Scaled::new(b.into_iter(), 1.0),
        ])
        .collect();
        assert_eq!(
            merged,
            vec![seg(0.0, 1.0, 0.0, 1.0), seg(5.0, 6.0, 0.0, 3.0)]
        );
    }
}
