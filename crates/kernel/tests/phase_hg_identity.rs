//! `Phase::hg` must reproduce the `HenyeyGreenstein` it replaced bit for
//! bit (same arithmetic, same random numbers per sample), so that every
//! existing HG image is unchanged.

use cirrus_kernel::sampling::uniform_sphere;
use cirrus_kernel::Phase;
use cirrus_kernel::Rng;
use glam::Vec3;

/// The Henyey-Greenstein code this crate had before `Phase`, verbatim, as
/// the reference for bit identity.
mod old_hg {
    use cirrus_kernel::sampling::from_local;
    use glam::Vec3;
    use std::f32::consts::PI;

    const ISOTROPIC_G: f32 = 1e-3;
    pub const MAX_ABS_G: f32 = 0.9999;

    pub struct HenyeyGreenstein {
        g: f32,
    }

    impl HenyeyGreenstein {
        pub fn new(g: f32) -> Self {
            let g = if g.is_nan() || g.abs() < ISOTROPIC_G {
                0.0
            } else {
                g.clamp(-MAX_ABS_G, MAX_ABS_G)
            };
            Self { g }
        }
        pub fn g(&self) -> f32 {
            self.g
        }
        pub fn eval_cos(&self, mu: f32) -> f32 {
            let g = self.g;
            let mu = mu.clamp(-1.0, 1.0);
            let denom = if g >= 0.0 {
                (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - mu)
            } else {
                (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + mu)
            };
            (1.0 - g) * (1.0 + g) / (4.0 * PI * denom * denom.sqrt())
        }
        pub fn eval(&self, dir_in: Vec3, dir_out: Vec3) -> f32 {
            self.eval_cos(dir_in.dot(dir_out))
        }
        pub fn sample_cos(&self, u: f32) -> f32 {
            let g = self.g;
            if g == 0.0 {
                return 1.0 - 2.0 * u;
            }
            let s = (1.0 - g) * (1.0 + g) / (1.0 - g + 2.0 * g * u);
            ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
        }
        pub fn sample(&self, dir_in: Vec3, u1: f32, u2: f32) -> (Vec3, f32) {
            let mu = self.sample_cos(u1);
            let sin = (1.0 - mu * mu).max(0.0).sqrt();
            let phi = 2.0 * PI * u2;
            let dir = from_local(dir_in, sin * phi.cos(), sin * phi.sin(), mu);
            (dir, self.eval_cos(mu))
        }
    }
}

#[test]
fn hg_is_bit_identical_to_the_previous_implementation() {
    let gs = [
        -1.0,
        -0.9999,
        -0.9,
        -0.5,
        -1e-3,
        -1e-4,
        0.0,
        1e-4,
        1e-3,
        0.3,
        0.6,
        0.85,
        0.9,
        0.99,
        0.9999,
        1.0,
        f32::NAN,
    ];
    let mut rng = Rng::new(17, 0, 0);
    let dirs: Vec<Vec3> = (0..16)
        .map(|_| uniform_sphere(rng.uniform(), rng.uniform()))
        .collect();
    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
    for g in gs {
        let (old, new) = (old_hg::HenyeyGreenstein::new(g), Phase::hg(g));
        assert_eq!(old.g().to_bits(), new.mean_cosine().to_bits(), "g {g}");
        for i in 0..=2000 {
            let mu = -1.0 + i as f32 / 1000.0;
            assert_eq!(
                old.eval_cos(mu).to_bits(),
                new.eval_cos(mu).to_bits(),
                "g {g} mu {mu}"
            );
            let u = i as f32 / 2001.0;
            assert_eq!(
                old.sample_cos(u).to_bits(),
                new.sample_cos(u).to_bits(),
                "g {g} u {u}"
            );
        }
        for &a in &dirs {
            for &b in &dirs {
                assert_eq!(old.eval(a, b).to_bits(), new.eval(a, b).to_bits());
            }
            for _ in 0..200 {
                let (u1, u2) = (rng.uniform(), rng.uniform());
                let ((d0, p0), (d1, p1)) = (old.sample(a, u1, u2), new.sample(a, u1, u2));
                assert_eq!(bits(d0), bits(d1), "g {g}");
                assert_eq!(p0.to_bits(), p1.to_bits(), "g {g}");
            }
        }
    }
    assert_eq!(old_hg::MAX_ABS_G, cirrus_kernel::phase::MAX_ABS_G);
}
