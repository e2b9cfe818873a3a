//! The ranges of a description's values, checked before anything is read:
//! a value out of range is an error naming the setting (its flag and its
//! scene-file key), never a value clamped or a render that quietly fails.
//! The `[[light]]` tables check their own values (`lights.rs`); a
//! volume's albedo, density scale and phase parameters are checked where
//! its medium is made (`plan.rs`).

use crate::description::{SceneDescription, VolumeSpec};
use crate::error::{Error, Result};

/// Checks the camera, the `[sun]` and `[environment]` shorthands, the
/// sampling settings and each volume's phase asymmetry.
pub fn check(desc: &SceneDescription) -> Result<()> {
    camera(desc)?;
    sun_and_sky(desc)?;
    sampling(desc)?;
    for v in &desc.volumes {
        volume(v).map_err(|e| e.within(v.file.display()))?;
    }
    Ok(())
}

fn bad(setting: &str, want: &str, got: impl std::fmt::Display) -> Error {
    Error::input(format!("{setting} must be {want}, got {got}"))
}

fn rgb(v: [f32; 3]) -> String {
    format!("{},{},{}", v[0], v[1], v[2])
}

fn finite(v: &[f32]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn camera(desc: &SceneDescription) -> Result<()> {
    let c = &desc.camera;
    let fov = c.fov();
    if !(fov.is_finite() && fov > 0.0 && fov < 180.0) {
        return Err(bad(
            "--fov ([camera] fov)",
            "a vertical field of view in (0, 180) degrees",
            fov,
        ));
    }
    let up = c.camera_up();
    if !finite(&up) || up == [0.0; 3] {
        return Err(bad(
            "--camera-up ([camera] up)",
            "a finite, non-zero vector",
            rgb(up),
        ));
    }
    if let (Some(from), Some(to)) = (c.camera_from, c.camera_to) {
        if !from.iter().chain(&to).all(|x| x.is_finite()) || from == to {
            return Err(Error::input(format!(
                "--camera-from and --camera-to ([camera] from, to) must be two different \
                 finite points, got {from:?} and {to:?}"
            )));
        }
    }
    Ok(())
}

/// The shorthands' values, as the `[[light]]` tables check theirs: a
/// direction finite and non-zero, strengths finite and >= 0.
fn sun_and_sky(desc: &SceneDescription) -> Result<()> {
    let sun = desc.sun.clone().unwrap_or_default();
    if sun.sun() {
        let d = sun.sun_dir();
        if !finite(&d) || d == [0.0; 3] {
            return Err(bad(
                "--sun-dir ([sun] direction)",
                "a finite, non-zero direction (from the sun toward the scene)",
                rgb(d),
            ));
        }
        let e = sun.sun_irradiance();
        if !finite(&e) || e.iter().any(|&x| x < 0.0) {
            return Err(bad(
                "--sun-irradiance ([sun] irradiance)",
                "finite and >= 0 in every channel",
                rgb(e),
            ));
        }
        let a = sun.sun_angle();
        if !(a.is_finite() && (0.0..180.0).contains(&a)) {
            return Err(bad(
                "--sun-angle ([sun] angle)",
                "an angular diameter in [0, 180) degrees",
                a,
            ));
        }
    }
    let env = desc.environment.clone().unwrap_or_default();
    let l = env.env_radiance();
    if !finite(&l) || l.iter().any(|&x| x < 0.0) {
        return Err(bad(
            "--env-radiance ([environment] radiance)",
            "finite and >= 0 in every channel",
            rgb(l),
        ));
    }
    let i = env.env_intensity();
    if !(i.is_finite() && i >= 0.0) {
        return Err(bad(
            "--env-intensity ([environment] intensity)",
            "finite and >= 0",
            i,
        ));
    }
    if !env.env_rotation().is_finite() {
        return Err(bad(
            "--env-rotation ([environment] rotation)",
            "finite",
            env.env_rotation(),
        ));
    }
    Ok(())
}

fn sampling(desc: &SceneDescription) -> Result<()> {
    let r = &desc.render;
    if let Some(t) = r.noise_threshold {
        if !(t.is_finite() && t > 0.0) {
            return Err(bad(
                "--noise-threshold ([render] noise_threshold)",
                "a relative error > 0 (e.g. 0.02)",
                t,
            ));
        }
        // With a time budget --spp is unused; with samples it is the most
        // any pixel takes, so it cannot be below the least.
        if r.time.is_none() && r.min_spp() > r.spp() {
            return Err(Error::input(format!(
                "--min-spp {} is above --spp {}: with --noise-threshold every pixel takes at \
                 least --min-spp samples and at most --spp; lower --min-spp or raise --spp \
                 ([render] min_spp, spp)",
                r.min_spp(),
                r.spp()
            )));
        }
    }
    let depth = r.refine_optical_depth();
    if !(depth.is_finite() && depth >= 0.0) {
        return Err(bad(
            "--refine-optical-depth ([render] refine_optical_depth)",
            "finite and >= 0",
            depth,
        ));
    }
    let far = r.holdout_far();
    if !(far.is_finite() && far > 0.0) {
        return Err(bad("--holdout-far ([render] holdout_far)", "> 0", far));
    }
    let o = &desc.output;
    if !o.exposure().is_finite() {
        return Err(bad(
            "--exposure ([output] exposure)",
            "finite",
            o.exposure(),
        ));
    }
    if o.deep_samples() == 0 {
        return Err(bad(
            "--deep-samples ([output] deep_samples)",
            "at least 1",
            0,
        ));
    }
    Ok(())
}

/// The phase parameters every phase function reads; the others are
/// checked by the phase function that takes them.
fn volume(v: &VolumeSpec) -> Result<()> {
    for (setting, g) in [
        ("--g ([[volume]] g)", v.g()),
        ("--g2 ([[volume]] g2)", v.g2()),
    ] {
        if !(g.is_finite() && (-1.0..=1.0).contains(&g)) {
            return Err(bad(setting, "an asymmetry in [-1, 1]", g));
        }
    }
    let w = v.lobe_weight();
    if !(w.is_finite() && (0.0..=1.0).contains(&w)) {
        return Err(bad(
            "--lobe-weight ([[volume]] lobe_weight)",
            "in [0, 1]",
            w,
        ));
    }
    let a = v.draine_alpha();
    if !(a.is_finite() && a >= 0.0) {
        return Err(bad(
            "--draine-alpha ([[volume]] draine_alpha)",
            "finite and >= 0",
            a,
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error_of(toml: &str) -> String {
        let mut desc = SceneDescription::parse(toml).unwrap();
        if desc.volumes.is_empty() {
            desc.volumes.push(VolumeSpec {
                file: "cloud.vdb".into(),
                ..Default::default()
            });
        }
        check(&desc).map_or_else(|e| e.to_string(), |()| "accepted".into())
    }

    #[test]
    fn out_of_range_values_are_refused_by_name() {
        for (toml, named) in [
            ("[camera]\nfov = 0\n", "--fov"),
            ("[camera]\nfov = 200\n", "--fov"),
            ("[sun]\ndirection = [0, 0, 0]\n", "--sun-dir"),
            ("[sun]\nirradiance = [1, -1, 1]\n", "--sun-irradiance"),
            ("[sun]\nangle = -2\n", "--sun-angle"),
            ("[environment]\nradiance = [0, -0.1, 0]\n", "--env-radiance"),
            (
                "[render]\nspp = 8\nnoise_threshold = 0.05\n",
                "--min-spp 16 is above --spp 8",
            ),
            ("[render]\nnoise_threshold = 0\n", "--noise-threshold"),
            ("[[volume]]\nfile = \"a.vdb\"\ng = 1.2\n", "a.vdb: --g "),
            ("[[volume]]\nfile = \"a.vdb\"\ng = -3\n", "--g "),
            (
                "[[volume]]\nfile = \"a.vdb\"\nlobe_weight = 2\n",
                "--lobe-weight",
            ),
        ] {
            let e = error_of(toml);
            assert!(e.contains(named), "{toml:?}: {e}");
        }
    }

    #[test]
    fn values_at_the_ends_of_their_ranges_pass() {
        for toml in [
            "[camera]\nfov = 179\n",
            "[sun]\nenabled = false\ndirection = [0, 0, 0]\n",
            "[render]\nspp = 16\nnoise_threshold = 0.05\n",
            "[render]\ntime = 1\nmin_spp = 64\nnoise_threshold = 0.05\n",
            "[[volume]]\nfile = \"a.vdb\"\ng = -1\n",
            "[[volume]]\nfile = \"a.vdb\"\ng = 1\n",
        ] {
            assert_eq!(error_of(toml), "accepted", "{toml:?}");
        }
    }
}
