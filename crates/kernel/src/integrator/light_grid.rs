//! Pass one of Kajiya and Von Herzen (1984): the direct light at every point
//! of a lattice over the field, stored sparsely in bricks.

use glam::{Vec3, Vec4, Vec4Swizzles};
use rayon::prelude::*;

use super::march::{marched_transmittance, ShadowEnd, MIN_STEP_VOXELS};

use super::light_choice::PerLight;
use crate::counters::Counters;
use crate::light::{Lights, Whence};
use crate::medium::Media;
use crate::phase::Phase;
use crate::sampling::{from_local, Rng};

/// Lattice points per brick edge: the points a brick computes.
const BRICK: usize = 8;
const BRICK_POINTS: usize = BRICK * BRICK * BRICK;
/// Lattice points per stored brick edge: its own and the first of the next
/// brick's (copied), so that every interpolation stencil lies in one stored
/// brick. Stencils crossing a brick's face were three in ten and cost
/// three times a stencil inside one (eight brick lookups), a twentieth of
/// a thick cloud's path; the copies cost `(9/8)^3 = 1.42x` the memory.
const STORED: usize = BRICK + 1;
/// Keeps the light grid's random streams apart from the camera samples'.
const GRID_DOMAIN: u64 = 0x4c49_4748_5447_5244;

/// The light choice's grid spacing in voxels...
const CHOICE_CELL_VOXELS: f32 = 8.0;
/// ...unless that puts fewer points than this along the longest axis...
const CHOICE_MIN_POINTS: f32 = 16.0;
/// ...or more than this.
const CHOICE_MAX_POINTS: f32 = 64.0;
/// The light choice's grid has its own fixed seed: its values only decide
/// probabilities, and a grid that is the same for every render seed keeps
/// the majorant probe, which traces through it, choosing by the scene
/// alone.
const CHOICE_SEED: u64 = 0x5348_4144_4f57_5321;

/// Resolution and quality of the two-pass light grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightGridSettings {
    /// Lattice spacing in voxels.
    pub cell_voxels: f32,
    /// Marched directions per lattice point for the environment term.
    pub env_directions: u32,
}

impl Default for LightGridSettings {
    fn default() -> Self {
        Self {
            cell_voxels: 4.0,
            env_directions: 8,
        }
    }
}

/// Sparse lattice of direct light over the field's bounds.
///
/// Stored per lattice point: one four-value slot per light, in
/// the lights' order. A distant light's slot holds its transmittance
/// toward its centre (the rest zero); a dome's the first two
/// spherical-harmonic bands of its transmittance `T(p, w)`, as `a = mean
/// of T` and `b = mean of T w` over the sphere. (Four values for a
/// distant light too, so that every slot is one vector interpolated in
/// one go: the lookup is on every vertex's path.)
///
/// Kajiya and Von Herzen expanded the light field in spherical harmonics;
/// bands 0 and 1 are enough here because by Funk-Hecke a phase function's
/// band-1 coefficient is its mean cosine `<mu>` (`g` for HG, whose
/// coefficients are `g^l`), so the in-scattered environment light toward a
/// ray travelling along `d` is `L_env * (a + 3 <mu> b . d)`: exact for an
/// isotropic phase function, missing only band 2 and higher otherwise.
///
/// Built at a chosen spacing; bricks of 8^3 lattice points are stored only
/// when the density is non-zero at a lattice point or cell centre in or
/// around them. Lookups elsewhere return no light, so features smaller than a
/// cell can be missed: the price of the baseline.
pub struct LightGrid {
    lo: Vec3,
    cell: f32,
    points: [usize; 3],
    /// The highest stencil corner along each axis: `points - 2`, at least 0.
    max_base: Vec3,
    bricks: [usize; 3],
    /// Per light the grid was built for, in order, whether its light
    /// comes from every direction (a dome: four slots, its transmittance's
    /// mean and first moment) rather than along one (one slot).
    everywhere: Vec<bool>,
    /// Slots per lattice point: one per light.
    width: usize,
    /// Per brick, its [`STORED`]^3 entries (x fastest) of `width` slots
    /// each, or `None` where it and the bricks it copies from are empty.
    brick_data: Vec<Option<Box<[Vec4]>>>,
}

impl LightGrid {
    /// Pass one: marches shadow rays from every lattice point of the
    /// non-empty bricks (in parallel; each point has its own random stream,
    /// so the grid is the same for any thread count). A distant light with a disc is
    /// treated as a point at its centre here.
    pub fn build<M: Media>(
        medium: &M,
        lights: &Lights,
        step_voxels: f32,
        settings: &LightGridSettings,
        seed: u64,
        c: &mut Counters,
    ) -> Self {
        let lights = lights.clone().pruned();
        let voxel = medium.voxel_size();
        let cell = settings.cell_voxels.max(MIN_STEP_VOXELS) * voxel;
        let step = step_voxels.max(MIN_STEP_VOXELS) * voxel;
        let bounds = medium.bounds();
        let lo = bounds.min;
        let extent = bounds.size().max(Vec3::ZERO);
        let points = [0, 1, 2].map(|a| (extent[a] / cell).ceil() as usize + 1);
        let bricks = points.map(|n| n.div_ceil(BRICK));
        let everywhere: Vec<bool> = lights
            .iter()
            .map(|l| l.whence(Vec3::ZERO) == Whence::Everywhere)
            .collect();
        let width = everywhere.len();
        let mut grid = Self {
            lo,
            cell,
            points,
            max_base: Vec3::from_array(points.map(|n| n.saturating_sub(2) as f32)),
            bricks,
            everywhere,
            width,
            brick_data: Vec::new(),
        };
        let n_bricks = bricks.iter().product::<usize>();
        let env_dirs = settings.env_directions.max(1);
        let built: Vec<(Option<Box<[Vec4]>>, Counters)> = (0..n_bricks)
            .into_par_iter()
            .map(|b| {
                let mut bc = Counters::default();
                let origin = grid.brick_origin(b);
                let data = grid.brick_occupied(medium, origin, &mut bc).then(|| {
                    let mut out = vec![Vec4::ZERO; BRICK_POINTS * width];
                    for (local, entry) in out.chunks_exact_mut(width.max(1)).enumerate() {
                        let ijk = [
                            local % BRICK,
                            (local / BRICK) % BRICK,
                            local / (BRICK * BRICK),
                        ];
                        let q = [0, 1, 2].map(|a| origin[a] + ijk[a]);
                        if q.iter().zip(&points).any(|(i, n)| i >= n) {
                            continue;
                        }
                        let index = q[0] + points[0] * (q[1] + points[1] * q[2]);
                        let mut rng = Rng::new(seed ^ GRID_DOMAIN, index as u64, 0);
                        grid.light_at(medium, &lights, q, step, env_dirs, &mut rng, &mut bc, entry);
                    }
                    out.into_boxed_slice()
                });
                (data, bc)
            })
            .collect();
        let computed: Vec<_> = built
            .into_iter()
            .map(|(data, bc)| {
                *c += bc;
                data
            })
            .collect();
        grid.brick_data = grid.stored(&computed);
        grid
    }

    /// The stored bricks from the computed ones: each brick's points and
    /// the first of its neighbours' beyond its upper faces (the lattice's
    /// last point repeated past its end, zero in empty bricks); `None`
    /// where every brick it copies from is empty.
    fn stored(&self, computed: &[Option<Box<[Vec4]>>]) -> Vec<Option<Box<[Vec4]>>> {
        let w = self.width;
        let clamped = |origin: [usize; 3], ijk: [usize; 3]| {
            [0, 1, 2].map(|a| (origin[a] + ijk[a]).min(self.points[a] - 1))
        };
        (0..computed.len())
            .map(|b| {
                let origin = self.brick_origin(b);
                // The bricks it copies from hold its corners.
                let copies = (0..8).any(|c| {
                    let corner = [0, 1, 2].map(|a| BRICK * ((c >> a) & 1));
                    computed[self.place(clamped(origin, corner), BRICK).0].is_some()
                });
                if !copies {
                    return None;
                }
                let mut out = vec![Vec4::ZERO; STORED * STORED * STORED * w];
                for (local, entry) in out.chunks_exact_mut(w.max(1)).enumerate() {
                    let ijk = [
                        local % STORED,
                        (local / STORED) % STORED,
                        local / (STORED * STORED),
                    ];
                    let (from, o) = self.place(clamped(origin, ijk), BRICK);
                    if let Some(values) = &computed[from] {
                        entry.copy_from_slice(&values[o * w..(o + 1) * w]);
                    }
                }
                Some(out.into_boxed_slice())
            })
            .collect()
    }

    /// The brick holding lattice point `q` and the point's entry in it,
    /// for bricks of `edge` entries a side (x fastest): [`BRICK`] as
    /// computed, [`STORED`] as stored.
    #[inline]
    fn place(&self, q: [usize; 3], edge: usize) -> (usize, usize) {
        let [i, j, k] = q;
        let b = i / BRICK + self.bricks[0] * (j / BRICK + self.bricks[1] * (k / BRICK));
        (b, i % BRICK + edge * (j % BRICK + edge * (k % BRICK)))
    }

    /// The coarse grid the path tracer's light choice weighs lights by
    /// (`light_choice.rs`): lattice points 8 voxels apart, at least 16
    /// along the longest axis of a small volume and at most 64 along that
    /// of a large one (its cost bounded at any size), marched at half that
    /// spacing, four sky directions per point. Coarse is enough: its
    /// values only decide probabilities.
    pub fn for_light_choice<M: Media>(medium: &M, lights: &Lights) -> Self {
        let voxel = medium.voxel_size();
        let voxels_across = medium.bounds().size().max_element() / voxel;
        let cell_voxels = CHOICE_CELL_VOXELS
            .min(voxels_across / CHOICE_MIN_POINTS)
            .max(voxels_across / CHOICE_MAX_POINTS);
        let settings = LightGridSettings {
            cell_voxels,
            env_directions: 4,
        };
        let mut uncounted = Counters::default();
        Self::build(
            medium,
            lights,
            0.5 * cell_voxels,
            &settings,
            CHOICE_SEED,
            &mut uncounted,
        )
    }

    /// Lattice points along each axis.
    pub fn lattice(&self) -> [usize; 3] {
        self.points
    }

    /// Number of bricks holding light (for reporting sparsity); each
    /// costs 9^3 entries of 16 bytes per light.
    pub fn stored_bricks(&self) -> usize {
        self.brick_data.iter().filter(|b| b.is_some()).count()
    }

    /// Number of bricks covering the lattice, stored or not.
    pub fn total_bricks(&self) -> usize {
        self.brick_data.len()
    }

    fn brick_origin(&self, b: usize) -> [usize; 3] {
        let [bx, by, _] = self.bricks;
        [b % bx, (b / bx) % by, b / (bx * by)].map(|i| i * BRICK)
    }

    /// Whether any density lies near the brick: sampled at the lattice
    /// points one beyond the brick on every side and at the cell centres
    /// between them.
    fn brick_occupied<M: Media>(&self, medium: &M, origin: [usize; 3], c: &mut Counters) -> bool {
        let start = Vec3::new(origin[0] as f32, origin[1] as f32, origin[2] as f32) - 1.0;
        let n = 2 * (BRICK + 2) - 1; // points and centres at half-cell spacing
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let q = start + 0.5 * Vec3::new(i as f32, j as f32, k as f32);
                    c.density_lookups += 1;
                    if medium.extinction::<f32>(self.lo + self.cell * q, 0.0) > 0.0 {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Fills `entry` with what lattice point `q` sees of each light.
    #[allow(clippy::too_many_arguments)]
    fn light_at<M: Media>(
        &self,
        medium: &M,
        lights: &Lights,
        q: [usize; 3],
        step: f32,
        env_dirs: u32,
        rng: &mut Rng,
        c: &mut Counters,
        entry: &mut [Vec4],
    ) {
        let p = self.lo + self.cell * Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32);
        let shadow = |dir: Vec3, distance: f32, rng: &mut Rng, c: &mut Counters| {
            let end = ShadowEnd::Cutoff;
            marched_transmittance::<M, f32>(medium, p, dir, distance, step, end, rng, c)
        };
        for (slot, light) in entry.iter_mut().zip(lights.iter()) {
            match light.whence(p) {
                Whence::Toward { dir, distance } => slot.x = shadow(dir, distance, rng, c),
                Whence::Everywhere => {
                    // Directions stratified in cos(theta), random in phi.
                    let (mut a, mut b) = (0.0, Vec3::ZERO);
                    for s in 0..env_dirs {
                        let z = 1.0 - 2.0 * (s as f32 + rng.uniform()) / env_dirs as f32;
                        let r = (1.0 - z * z).max(0.0).sqrt();
                        let phi = std::f32::consts::TAU * rng.uniform();
                        let w = from_local(Vec3::Z, r * phi.cos(), r * phi.sin(), z);
                        let tr = shadow(w, f32::INFINITY, rng, c);
                        a += tr;
                        b += tr * w;
                    }
                    let inv = 1.0 / env_dirs as f32;
                    let b = b * inv;
                    *slot = Vec4::new(a * inv, b.x, b.y, b.z);
                }
            }
        }
    }

    /// The stored values of lattice point `(i, j, k)` in the brick that
    /// computed it, `None` in an empty brick.
    #[cfg(test)]
    fn entry(&self, i: usize, j: usize, k: usize) -> Option<&[Vec4]> {
        let (bi, o) = self.place([i, j, k], STORED);
        let brick = self.brick_data[bi].as_ref()?;
        Some(&brick[o * self.width..(o + 1) * self.width])
    }

    /// The lattice stencil at `p` (clamped to the lattice): its lowest
    /// corner and the fractions across it.
    #[inline]
    fn stencil(&self, p: Vec3) -> ([usize; 3], [f32; 3]) {
        // In vector lanes, converted to u32 (one instruction each, where a
        // float to usize takes a dozen): the lookup is on every vertex.
        let x = (p - self.lo) / self.cell;
        let xb = x.floor().clamp(Vec3::ZERO, self.max_base);
        let f = (x - xb).clamp(Vec3::ZERO, Vec3::ONE);
        (xb.as_uvec3().to_array().map(|b| b as usize), f.to_array())
    }

    /// Trilinear interpolation of the stored entries at `p` (clamped to
    /// the lattice), collected.
    #[cfg(test)]
    fn lookup(&self, p: Vec3) -> Vec<Vec4> {
        let mut e = Vec::new();
        self.lookup_each(p, |slot| e.push(slot));
        e
    }

    /// Trilinear interpolation of the stored entries at `p` (clamped to
    /// the lattice), each slot handed to `each` in turn.
    #[inline]
    fn lookup_each(&self, p: Vec3, mut each: impl FnMut(Vec4)) {
        let (base, f) = self.stencil(p);
        let w = self.width;
        let (bi, o) = self.place(base, STORED);
        let Some(brick) = &self.brick_data[bi] else {
            return (0..w).for_each(|_| each(Vec4::ZERO));
        };
        // x fastest in a brick: y one row of STORED on, z one slice.
        const Y: usize = STORED;
        const Z: usize = STORED * STORED;
        let corners = &brick[o * w..(o + Z + Y + 2) * w];
        // Each corner's slots as a slice of exactly `w`, so the loop below
        // indexes them without bounds checks.
        let at = |d: usize| &corners[d * w..d * w + w];
        let [c0, c1, c2, c3] = [at(0), at(1), at(Y), at(Y + 1)];
        let [c4, c5, c6, c7] = [at(Z), at(Z + 1), at(Z + Y), at(Z + Y + 1)];
        let lerp = |a: Vec4, b: Vec4, t: f32| a + (b - a) * t;
        for n in 0..w {
            let z0 = lerp(lerp(c0[n], c1[n], f[0]), lerp(c2[n], c3[n], f[0]), f[1]);
            let z1 = lerp(lerp(c4[n], c5[n], f[0]), lerp(c6[n], c7[n], f[0]), f[1]);
            each(lerp(z0, z1, f[2]));
        }
    }

    /// What `p` sees of each light the grid was built for (the lights
    /// with no light dropped, [`Lights::pruned`]) toward a ray travelling
    /// along `dir`: a distant light's transmittance, a dome's two bands
    /// with the phase function's mean cosine (see [`LightGrid`]).
    /// At most [`MAX_PICKED_LIGHTS`](super::light_choice::MAX_PICKED_LIGHTS) lights: the light choice's.
    pub(crate) fn seen(&self, phase: &Phase, p: Vec3, dir: Vec3) -> PerLight {
        let mut seen = PerLight::zeros(self.everywhere.len());
        let mean_cosine = phase.mean_cosine();
        let mut i = 0;
        self.lookup_each(p, |slot| {
            if let (Some(seen), Some(&everywhere)) = (seen.get_mut(i), self.everywhere.get(i)) {
                *seen = Self::seen_in(everywhere, slot, mean_cosine, dir);
            }
            i += 1;
        });
        seen
    }

    /// The fraction of a light seen through a slot by a phase function of
    /// mean cosine `mean_cosine`: one transmittance for a light along one
    /// direction, two bands for one from `everywhere`.
    #[inline]
    fn seen_in(everywhere: bool, slot: Vec4, mean_cosine: f32, dir: Vec3) -> f32 {
        if everywhere {
            (slot.x + 3.0 * mean_cosine * slot.yzw().dot(dir)).max(0.0)
        } else {
            slot.x
        }
    }

    /// Phase-weighted direct light at `p` toward a ray travelling along
    /// `dir` (pass two's in-scattering term).
    /// A map environment lights with its mean radiance here: the grid
    /// stores only the sky's transmittance (a biased baseline).
    pub(crate) fn in_scatter(
        &self,
        phase: &Phase,
        lights: &Lights,
        p: Vec3,
        dir: Vec3,
    ) -> super::LightParts {
        let mut s = super::LightParts::default();
        let mut i = 0;
        self.lookup_each(p, |slot| {
            let light = lights.get(i);
            let everywhere = self.everywhere.get(i).copied().unwrap_or(false);
            let seen = Self::seen_in(everywhere, slot, phase.mean_cosine(), dir);
            let l = light.in_scattered(phase, p, dir, seen);
            s.add(lights.group(i), l);
            i += 1;
        });
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{Environment, Sun};
    use crate::medium::{GridField, Medium};
    use crate::sampling::Rng;

    /// The stencil at `base` blended corner by corner with fractions `f`,
    /// each corner found in its own brick and weighed by its trilinear
    /// weight: the reference the interpolation is checked against.
    fn blend(grid: &LightGrid, base: [usize; 3], f: [f32; 3]) -> Vec<Vec4> {
        let mut out = vec![Vec4::ZERO; grid.width];
        for corner in 0..8 {
            let d = [corner & 1, (corner >> 1) & 1, corner >> 2];
            let mut w = 1.0;
            let mut q = [0usize; 3];
            for a in 0..3 {
                w *= if d[a] == 1 { f[a] } else { 1.0 - f[a] };
                q[a] = (base[a] + d[a]).min(grid.points[a] - 1);
            }
            if let Some(e) = grid.entry(q[0], q[1], q[2]) {
                for (o, v) in out.iter_mut().zip(e) {
                    *o += w * v;
                }
            }
        }
        out
    }

    /// A lumpy cloud of 40^3 voxels: its light-choice grid has 17 points
    /// along each axis (16 cells, the fewest), three bricks, so stencils
    /// fall inside bricks and across their faces.
    fn lumpy_grid() -> LightGrid {
        let field = GridField::from_fn([40; 3], Vec3::ZERO, 0.1, 4, |i, j, k| {
            let r = Vec3::new(i as f32, j as f32, k as f32) / 40.0 - 0.5;
            (1.0 - 3.0 * r.length()).max(0.0) * (1.0 + (7.0 * r.x).sin() * (5.0 * r.z).cos())
        });
        let cloud = crate::volumes::Volumes::from(Medium::new(field, 20.0, Vec3::splat(0.9), 0.5));
        let lights = Lights::sun_and_sky(
            Some(Sun::new(Vec3::new(0.3, -1.0, 0.2), Vec3::splat(3.0), 0.0)),
            Some(Environment::new(Vec3::splat(0.2))),
        );
        LightGrid::for_light_choice(&cloud, &lights)
    }

    /// The one-brick lookup (with the copied points) gives what blending
    /// each corner from the brick that computed it gives, to rounding,
    /// inside the lattice, on brick faces and clamped outside it; and the
    /// grid holds light that varies (the comparison would pass over a
    /// constant grid whatever the offsets).
    #[test]
    fn a_lookup_blends_the_corners_of_the_bricks_that_computed_them() {
        let grid = lumpy_grid();
        assert_eq!(grid.lattice(), [17, 17, 17]);
        let mut rng = Rng::new(3, 0, 0);
        let (mut lo, mut hi) = (f32::MAX, f32::MIN);
        for n in 0..20_000 {
            let u = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
            let mut p = Vec3::splat(-0.4) + 4.8 * u;
            if n % 4 == 0 {
                // On a lattice plane between two bricks.
                p.y = grid.lo.y + grid.cell * (BRICK as f32 - 1.0 + rng.uniform());
            }
            let (base, f) = grid.stencil(p);
            let fast = grid.lookup(p);
            let blended = blend(&grid, base, f);
            for (a, b) in fast.iter().zip(&blended) {
                assert!(
                    (*a - *b).abs().max_element() <= 1e-5,
                    "at {p}: {fast:?} against {blended:?}"
                );
            }
            lo = lo.min(fast[0].x);
            hi = hi.max(fast[0].x);
        }
        assert!(lo < 0.05 && hi > 0.9, "sun transmittance from {lo} to {hi}");
    }
}
