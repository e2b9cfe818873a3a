//! The `cirrus render` command line that reproduces a preview: the same
//! overrides the preview rendered with, written as flags.
//!
//! Numbers are printed in Rust's shortest round-trip form, so the command
//! parses back to exactly the values the preview used.

use std::fmt::Display;
use std::path::Path;

use cirrus_scene::Overrides;

/// `cirrus render INPUT -o STEM.exr --png STEM.png FLAGS...` for `o`.
pub fn render_command(input: &Path, o: &Overrides) -> String {
    let stem = input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "preview".into());
    let mut args: Vec<String> = vec!["cirrus".into(), "render".into()];
    args.push(input.display().to_string());
    let mut flag = |name: &str, value: Option<String>| {
        if let Some(v) = value {
            // `--g=-0.3`: a value starting with '-' must not read as a flag.
            if v.starts_with('-') {
                args.push(format!("--{name}={v}"));
            } else {
                args.push(format!("--{name}"));
                args.push(v);
            }
        }
    };
    flag("res", o.res.map(|(w, h)| format!("{w}x{h}")));
    flag("spp", o.spp.map(text));
    flag("seed", o.seed.map(text));
    flag("integrator", o.integrator.map(|i| i.name().to_string()));
    flag("step", o.step.map(text));
    flag("camera-from", o.camera_from.map(triple));
    flag("camera-to", o.camera_to.map(triple));
    flag("camera-up", o.camera_up.map(triple));
    flag("fov", o.fov.map(text));
    flag("sun-dir", o.sun_dir.map(triple));
    flag("sun-irradiance", o.sun_irradiance.map(triple));
    flag("env-radiance", o.env_radiance.map(triple));
    flag("env-intensity", o.env_intensity.map(text));
    flag("density-scale", o.density_scale.map(text));
    flag("albedo", o.albedo.map(text));
    flag("g", o.g.map(text));
    flag("exposure", o.exposure.map(text));
    // The CPU is the default: said only when another device rendered.
    flag(
        "device",
        o.device
            .filter(|d| *d != cirrus_scene::Device::Cpu)
            .map(|d| d.name().to_string()),
    );
    args.push("-o".into());
    args.push(format!("{stem}.render.exr"));
    args.push("--png".into());
    args.push(format!("{stem}.render.png"));
    if o.sun == Some(false) {
        args.push("--no-sun".into());
    }
    if o.denoise == Some(true) {
        args.push("--denoise".into());
    }
    args.iter().map(|a| quote(a)).collect::<Vec<_>>().join(" ")
}

fn text(x: impl Display) -> String {
    x.to_string()
}

fn triple(v: [impl Display; 3]) -> String {
    let [x, y, z] = v;
    format!("{x},{y},{z}")
}

/// A POSIX shell word for `s`: as it is when it is plainly safe, else in
/// single quotes.
fn quote(s: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "_-+=.,/:@%".contains(c);
    if !s.is_empty() && s.chars().all(safe) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_round_trip_and_words_are_quoted() {
        let o = Overrides {
            res: Some((64, 32)),
            spp: Some(16),
            seed: Some(0),
            g: Some(-0.3),
            camera_from: Some([1.0, -2.5, 0.1]),
            camera_to: Some([0.0; 3]),
            sun: Some(false),
            ..Default::default()
        };
        let c = render_command(Path::new("my clouds/a.vdb"), &o);
        assert_eq!(
            c,
            "cirrus render 'my clouds/a.vdb' --res 64x32 --spp 16 --seed 0 \
             --camera-from 1,-2.5,0.1 --camera-to 0,0,0 --g=-0.3 \
             -o a.render.exr --png a.render.png --no-sun"
        );
    }
}
