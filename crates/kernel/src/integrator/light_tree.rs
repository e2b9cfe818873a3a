//! A light tree (Conty Estevez and Kulla 2018, as Cycles' light tree and
//! pbrt-v4's `BVHLightSampler`): a binary tree over the lights in the
//! scene, each node holding its lights' [`LightBounds`]. A pick walks from
//! the root, at each node taking a child by its importance for what is
//! lit (a point, or a ray segment for a volume's equi-angular sample):
//! with a least and a greatest importance for each child (a point's
//! distance to the box's far corner and to its near side), the mean of
//! the shares each gives, as Cycles does, so a vertex finds the lights that
//! matter in `log n` steps whatever their number; the probability of a
//! given light is the product of the choices on the way to its leaf, which
//! the tree recomputes by walking the leaf's recorded trail (for MIS).
//!
//! Built once per render, splitting the lights at the median of their
//! centres along the widest axis of those centres: a balanced tree whose
//! depth is `ceil(log2 n)` (pbrt-v4 splits by a surface-area-orientation
//! cost; the median is simpler and, for lights spread through a volume,
//! close to it). A node's importance is a bound, never zero where one of
//! its lights brings light, so no light is starved.

use glam::Vec3;

use crate::light::{LightBounds, Lights};

/// One node: its bounds and either a light or its second child (the
/// first follows it).
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: LightBounds,
    kind: NodeKind,
}

#[derive(Clone, Copy, Debug)]
enum NodeKind {
    /// Light index in the scene's [`Lights`].
    Leaf(u32),
    /// Index of the second child.
    Interior(u32),
}

/// The way from the root to a light's leaf: bit `k` set where the walk
/// takes the second child at depth `k`.
#[derive(Clone, Copy, Debug)]
struct Trail {
    bits: u64,
    depth: u8,
}

/// The tree over some of a scene's lights.
#[derive(Clone, Debug)]
pub(crate) struct LightTree {
    nodes: Vec<Node>,
    /// Per light of the scene, its trail where the tree holds it.
    trails: Vec<Option<Trail>>,
}

/// The largest `f32` below one: a rescaled number stays in `[0, 1)`.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

impl LightTree {
    /// The tree over the lights of `lights` at the indices `members` that
    /// have bounds (lights at infinity have none and are left out);
    /// `None` where none has.
    pub fn new(lights: &Lights, members: &[usize]) -> Option<Self> {
        let mut leaves: Vec<(Vec3, u32, LightBounds)> = members
            .iter()
            .filter_map(|&i| {
                let b = lights.get(i).bounds()?;
                (b.phi > 0.0 && b.phi.is_finite()).then(|| (b.centre(), i as u32, b))
            })
            .collect();
        if leaves.is_empty() {
            return None;
        }
        let mut tree = Self {
            nodes: Vec::with_capacity(2 * leaves.len()),
            trails: vec![None; lights.len()],
        };
        tree.build(&mut leaves, 0, 0);
        Some(tree)
    }

    /// How many lights it holds.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.trails.iter().filter(|t| t.is_some()).count()
    }

    /// Whether it holds light `i`.
    #[inline]
    pub fn holds(&self, i: usize) -> bool {
        self.trails.get(i).is_some_and(Option::is_some)
    }

    /// The bounds of every light it holds.
    #[inline]
    pub fn root(&self) -> &LightBounds {
        &self.nodes[0].bounds
    }

    /// Appends the subtree over `leaves`, reached by `bits` at `depth`,
    /// and returns its bounds.
    fn build(
        &mut self,
        leaves: &mut [(Vec3, u32, LightBounds)],
        bits: u64,
        depth: u8,
    ) -> LightBounds {
        let at = self.nodes.len();
        if let [(_, light, bounds)] = *leaves {
            self.nodes.push(Node {
                bounds,
                kind: NodeKind::Leaf(light),
            });
            self.trails[light as usize] = Some(Trail { bits, depth });
            return bounds;
        }
        // A placeholder, filled once both children are built.
        self.nodes.push(Node {
            bounds: leaves[0].2,
            kind: NodeKind::Interior(0),
        });
        let (lo, hi) = leaves
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), l| {
                (lo.min(l.0), hi.max(l.0))
            });
        let axis = (hi - lo).max_position();
        let mid = leaves.len() / 2;
        leaves.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]));
        let (first, second) = leaves.split_at_mut(mid);
        let a = self.build(first, bits, depth + 1);
        let right = self.nodes.len() as u32;
        let b = self.build(second, bits | (1 << depth), depth + 1);
        let bounds = a.union(&b);
        self.nodes[at] = Node {
            bounds,
            kind: NodeKind::Interior(right),
        };
        bounds
    }

    /// A light picked with `u` (uniform in `[0, 1)`) by `importance` of
    /// each node, and its probability; `None` where no light brings
    /// anything.
    #[inline]
    pub fn pick(
        &self,
        importance: impl Fn(&LightBounds) -> (f32, f32),
        u: f32,
    ) -> Option<(usize, f32)> {
        let (mut node, mut pmf, mut u) = (0usize, 1.0f32, u);
        loop {
            match self.nodes[node].kind {
                NodeKind::Leaf(light) => return Some((light as usize, pmf)),
                NodeKind::Interior(second) => {
                    let second = second as usize;
                    let p = first_child_probability(
                        importance(&self.nodes[node + 1].bounds),
                        importance(&self.nodes[second].bounds),
                    )?;
                    if u < p {
                        u = (u / p).min(ONE_MINUS_EPSILON);
                        pmf *= p;
                        node += 1;
                    } else {
                        u = ((u - p) / (1.0 - p)).min(ONE_MINUS_EPSILON);
                        pmf *= 1.0 - p;
                        node = second;
                    }
                }
            }
        }
    }

    /// The probability that [`Self::pick`] with `importance` picks light
    /// `i` (0 for a light it does not hold).
    #[inline]
    pub fn probability(&self, importance: impl Fn(&LightBounds) -> (f32, f32), i: usize) -> f32 {
        let Some(Some(trail)) = self.trails.get(i) else {
            return 0.0;
        };
        let (mut node, mut pmf) = (0usize, 1.0f32);
        for k in 0..trail.depth {
            let NodeKind::Interior(second) = self.nodes[node].kind else {
                unreachable!("a trail ends at its leaf");
            };
            let second = second as usize;
            let Some(p) = first_child_probability(
                importance(&self.nodes[node + 1].bounds),
                importance(&self.nodes[second].bounds),
            ) else {
                return 0.0;
            };
            if trail.bits >> k & 1 == 0 {
                pmf *= p;
                node += 1;
            } else {
                pmf *= 1.0 - p;
                node = second;
            }
        }
        pmf
    }
}

/// The probability of taking the first of two children whose least and
/// greatest importances are `a` and `b`: the mean of the shares by each
/// (one alone where the other says nothing); `None` where neither child
/// brings anything.
#[inline]
fn first_child_probability(a: (f32, f32), b: (f32, f32)) -> Option<f32> {
    match (share(a.0, b.0), share(a.1, b.1)) {
        (Some(least), Some(most)) => Some(0.5 * (least + most)),
        (one, other) => one.or(other),
    }
}

/// The share of importance `a` against `b`; `None` where neither is
/// positive. An infinite importance takes its child.
#[inline]
fn share(a: f32, b: f32) -> Option<f32> {
    let clean = |x: f32| if x > 0.0 { x } else { 0.0 };
    let (a, b) = (clean(a), clean(b));
    match (a.is_infinite(), b.is_infinite()) {
        (true, true) => Some(0.5),
        (true, false) => Some(1.0),
        (false, true) => Some(0.0),
        _ if a + b > 0.0 => Some(a / (a + b)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{AreaLight, AreaShape, Light, SphereLight, Sun};

    /// Embers and a few panels through a box, a sun beside them (which
    /// the tree leaves out).
    fn scene(n: usize) -> Lights {
        let mut rng = cirrus_testkit::SplitMix64(n as u64);
        let mut v = |s: f32| Vec3::new(rng.unit(), rng.unit(), rng.unit()) * s;
        let mut lights: Vec<Light> = (0..n)
            .map(|k| {
                let (p, i) = (v(100.0), 1.0 + 9.0 * v(1.0).x);
                if k % 7 == 3 {
                    let normal = v(2.0) - Vec3::ONE;
                    let a = AreaLight::new(
                        AreaShape::Rect,
                        p,
                        Vec3::X,
                        Vec3::Z,
                        normal,
                        Vec3::splat(i),
                    );
                    a.into()
                } else {
                    SphereLight::new(p, 0.2 * (k % 3) as f32, Vec3::splat(i)).into()
                }
            })
            .collect();
        lights.push(Sun::new(Vec3::NEG_Y, Vec3::ONE, 0.0).into());
        Lights::new(lights)
    }

    /// Every light that sends light toward a point has a probability
    /// there, the probabilities sum to one less the chance that the pick
    /// finds nothing (a cluster whose bound saw light where none of its
    /// lights sends any: flat lights facing away), and each light is
    /// picked as often as its probability says (a chi-square bound over
    /// 400k picks); the probability the pick reports is the traversal's.
    #[test]
    fn the_picks_frequencies_are_its_probabilities() {
        let lights = scene(60);
        let members: Vec<usize> = (0..lights.len()).collect();
        let tree = LightTree::new(&lights, &members).unwrap();
        assert_eq!(tree.len(), 60, "the sun is left out");
        for p in [
            Vec3::splat(50.0),
            Vec3::new(-30.0, 120.0, 40.0),
            Vec3::new(10.0, 5.0, 90.0),
        ] {
            let imp = |b: &LightBounds| b.importance_range(p);
            let pmf: Vec<f32> = (0..lights.len())
                .map(|i| tree.probability(imp, i))
                .collect();
            for (i, &q) in pmf.iter().enumerate().take(60) {
                let own = lights.get(i).bounds().unwrap().importance(p);
                assert!(
                    own == 0.0 || q > 0.0,
                    "light {i} at {p}: {own} but never picked"
                );
            }
            let sum: f32 = pmf.iter().sum();
            assert!(sum <= 1.0 + 1e-5 && sum > 0.95, "at {p}: {sum}");
            assert_eq!(pmf[60], 0.0);
            let n = 400_000;
            let mut counts = vec![0u32; lights.len()];
            let mut none = 0u32;
            for k in 0..n {
                let u = (k as f32 + 0.5) / n as f32;
                let Some((i, q)) = tree.pick(imp, u) else {
                    none += 1;
                    continue;
                };
                assert_eq!(q.to_bits(), pmf[i].to_bits(), "light {i}");
                counts[i] += 1;
            }
            let lost = none as f32 / n as f32;
            assert!(
                (lost - (1.0 - sum)).abs() < 1e-4,
                "at {p}: {lost} vs {}",
                1.0 - sum
            );
            // Stratified numbers: far tighter than a chi-square's bound,
            // which holds too.
            let chi2: f64 = counts
                .iter()
                .zip(&pmf)
                .filter(|(_, &q)| q > 0.0)
                .map(|(&c, &q)| {
                    let e = q as f64 * n as f64;
                    (c as f64 - e).powi(2) / e
                })
                .sum();
            // 60 cells: the 99.9th percentile of chi-square with 59
            // degrees of freedom is about 99.
            assert!(chi2 < 99.0, "at {p}: chi-square {chi2}");
        }
    }

    /// Along a segment, the same: probabilities summing to one, each the
    /// pick's frequency; and a lamp near the segment outweighs one far off.
    #[test]
    fn the_segment_pick_follows_its_probabilities() {
        let lights = scene(40);
        let members: Vec<usize> = (0..lights.len()).collect();
        let tree = LightTree::new(&lights, &members).unwrap();
        let (o, d) = (Vec3::new(-10.0, 50.0, 50.0), Vec3::X);
        let imp = |b: &LightBounds| b.segment_importance_range(o, d, 0.0, 120.0);
        let pmf: Vec<f32> = (0..lights.len())
            .map(|i| tree.probability(imp, i))
            .collect();
        assert!(
            (pmf.iter().sum::<f32>() - 1.0).abs() < 1e-5,
            "no light faces away from a segment"
        );
        let n = 200_000;
        let mut counts = vec![0u32; lights.len()];
        for k in 0..n {
            let (i, q) = tree.pick(imp, (k as f32 + 0.5) / n as f32).unwrap();
            assert_eq!(q.to_bits(), tree.probability(imp, i).to_bits());
            counts[i] += 1;
        }
        for (i, (&c, &q)) in counts.iter().zip(&pmf).enumerate() {
            let f = c as f32 / n as f32;
            assert!(
                (f - q).abs() < 3.0 / n as f32 + 1e-5,
                "light {i}: {f} vs {q}"
            );
        }
    }

    /// Ten thousand lights build a tree of depth 14 whose probabilities
    /// still sum to one, less what flat lights facing away lose.
    #[test]
    fn ten_thousand_lights_make_a_balanced_tree() {
        let lights = scene(10_000);
        let members: Vec<usize> = (0..lights.len()).collect();
        let tree = LightTree::new(&lights, &members).unwrap();
        let depth = tree.trails.iter().flatten().map(|t| t.depth).max().unwrap();
        assert_eq!(depth, 14);
        let p = Vec3::new(20.0, 70.0, 30.0);
        let imp = |b: &LightBounds| b.importance_range(p);
        let sum: f64 = (0..lights.len())
            .map(|i| tree.probability(imp, i) as f64)
            .sum();
        assert!(sum <= 1.0 + 1e-4 && sum > 0.99, "{sum}");
    }
}
