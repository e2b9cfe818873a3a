//! `cirrus render FILE|SCENE.toml -o OUT.exr [flags]`: maps the flags onto
//! the scene library, renders, writes the outputs and prints a summary;
//! with `--frames` (or a scene file's `[render] frames`), once per frame.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use super::CliResult;
use cirrus_render::Rendered;
use cirrus_scene::frames::{has_pattern, substitute, FrameRange};
use cirrus_scene::{OutputFlags, Overrides, RenderTarget, Scene, SceneFlags};
use indicatif::{ProgressBar, ProgressStyle};

#[derive(clap::Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneFlags,
    #[command(flatten)]
    pub output: OutputFlags,
    /// Render frames whose EXR already exists (by default they are
    /// skipped, so an interrupted sequence resumes where it stopped).
    #[arg(long)]
    pub overwrite: bool,
    /// Removed (learned path guiding); kept to say so.
    #[arg(long, hide = true, value_name = "MODE")]
    pub guiding: Option<String>,
}

/// What `--guiding` answers.
pub const GUIDING_REMOVED: &str = "--guiding: learned path guiding was removed. \
On every scene measured (a thick sun-lit cloud, a thin sky-lit one) it rendered at 0.15-0.73x \
the efficiency of unguided rendering at equal time, and its default, auto, already left it off; \
the write-up and figures are in BENCHMARKS.md (\"Guided path tracing\"), the code in commit \
0258f19. Drop the flag: the image is what --guiding auto gave.";

pub fn run(args: &RenderArgs) -> CliResult {
    if args.guiding.is_some() {
        return Err(GUIDING_REMOVED.into());
    }
    let mut overrides = args.scene.overrides();
    args.output.write_into(&mut overrides);
    let file = &args.scene.file;
    let range = frame_range(args, &overrides)?;
    match range {
        None => {
            let scene = load(file, &overrides, None)?;
            let target = RenderTarget::open(scene.settings()?.device)?;
            warn_unused_velocity(&scene, &overrides);
            render_one(&scene, &target, true)?;
            Ok(())
        }
        Some(range) => {
            // A scene file that cannot be read is reported per frame; the
            // device is the flag's, else the first scene file's.
            let mut device = overrides.device.unwrap_or_default();
            if let Ok(scene) = load(file, &overrides, None) {
                outputs_tell_frames_apart(&scene, &range)?;
                warn_unused_velocity(&scene, &overrides);
                device = scene.settings()?.device;
            }
            let target = RenderTarget::open(device)?;
            sequence(file, &overrides, range, args.overwrite, &target)
        }
    }
}

/// `--frames`, else a scene file's `[render] frames`, else none.
fn frame_range(
    args: &RenderArgs,
    overrides: &Overrides,
) -> Result<Option<FrameRange>, Box<dyn std::error::Error>> {
    let file = &args.scene.file;
    if let Some(s) = &args.scene.render.frames {
        return Ok(Some(FrameRange::parse(s)?));
    }
    if has_pattern(&file.to_string_lossy()) {
        return Err(format!("{}: a frame pattern needs --frames A-B", file.display()).into());
    }
    // A stage's own range renders when the outputs can tell its frames
    // apart; with one output file it renders its first frame.
    let usd = cirrus_scene::usd::is_usd(file);
    let patterned = |p: &Option<PathBuf>| {
        p.as_ref()
            .is_some_and(|p| has_pattern(&p.to_string_lossy()))
    };
    if usd && overrides.output.is_some() && !patterned(&overrides.output) {
        return Ok(None);
    }
    let scene_file = file.extension().is_some_and(|e| e == "toml") || usd;
    let from_file = match scene_file {
        true => Scene::load(file)?.description().render.frames.clone(),
        false => None,
    };
    Ok(from_file
        .map(|s| FrameRange::parse(&s).map_err(|e| format!("{}: [render] {e}", file.display())))
        .transpose()?)
}

/// `--velocity NAME` moves nothing while the shutter is closed: said,
/// since the flag was given to blur.
fn warn_unused_velocity(scene: &Scene, overrides: &Overrides) {
    let [open, close] = scene.description().render.shutter();
    if let (Some(name), true) = (&overrides.velocity, open == close) {
        eprintln!(
            "cirrus: warning: --velocity {name}: unused while the shutter is closed; open it \
             (--shutter -0.25,0.25) for motion blur"
        );
    }
}

/// Several frames need outputs with a frame pattern: without one each
/// frame would write the same file (and, the file existing, the next
/// frames would be skipped as finished).
fn outputs_tell_frames_apart(scene: &Scene, range: &FrameRange) -> CliResult {
    if range.count() < 2 {
        return Ok(());
    }
    let outputs = scene.outputs();
    for path in outputs.files() {
        if !has_pattern(&path.to_string_lossy()) {
            return Err(format!(
                "{}: {} frames would all be written to this one file; put a frame pattern \
                 in it (out.####.exr or out.%04d.exr)",
                path.display(),
                range.count()
            )
            .into());
        }
    }
    Ok(())
}

/// The scene of `file` with the flags applied, for one frame or none.
fn load(file: &Path, overrides: &Overrides, frame: Option<i64>) -> cirrus_scene::Result<Scene> {
    let path = frame.map_or_else(|| file.to_path_buf(), |f| substitute(file, f));
    let mut scene = Scene::load(&path)?;
    scene.apply(overrides);
    Ok(match frame {
        Some(f) => scene.for_frame(f),
        None => scene,
    })
}

/// Renders and writes one scene on `target`; `bar`: show the render's
/// progress (a bar on a terminal, plain lines in a log). Returns the
/// first file written.
fn render_one(
    scene: &Scene,
    target: &RenderTarget,
    bar: bool,
) -> Result<PathBuf, Box<dyn std::error::Error>> {
    let outputs = scene.outputs();
    let Some(first) = outputs.exr.clone().or_else(|| outputs.png.clone()) else {
        return Err(
            "an output file is required: -o OUT.exr, -o OUT.png or --png OUT.png \
             (or [output] exr = \"...\" in a scene file)"
                .into(),
        );
    };
    for warning in scene.warnings() {
        eprintln!("cirrus: warning: {warning}");
    }
    match (outputs.denoise_at_merge, &outputs.exr) {
        (false, _) => {}
        (true, Some(exr)) => eprintln!(
            "cirrus: a crop is denoised over the whole image by `cirrus merge`: {} keeps the \
             noisy image and the denoiser's inputs",
            exr.display()
        ),
        (true, None) => eprintln!(
            "cirrus: warning: a crop is denoised over the whole image by `cirrus merge`, from \
             its EXR; this PNG-only crop stays noisy"
        ),
    }
    let mut scene = scene.clone();
    scene.progress_bar = bar;
    scene.warn_on_stderr = true;
    let rendered = target.render(&scene)?;
    for warning in Scene::render_warnings(&rendered) {
        eprintln!("cirrus: warning: {warning}");
    }
    if rendered.stats.volumes_culled > 0 {
        eprintln!(
            "{} volume(s) neither the camera nor the lights can reach: not loaded",
            rendered.stats.volumes_culled
        );
    }
    outputs.write(&rendered)?;
    summary(&first, &rendered);
    let files: Vec<String> = outputs
        .files()
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    eprintln!("wrote {}", files.join(", "));
    Ok(first)
}

/// Every frame of `range`: frames whose EXR exists are skipped unless
/// `overwrite` (outputs are written whole or not at all, so an existing
/// file is a finished frame); a frame that fails is reported by number and
/// file and the others go on; the run fails if any frame did.
fn sequence(
    file: &Path,
    overrides: &Overrides,
    range: FrameRange,
    overwrite: bool,
    target: &RenderTarget,
) -> CliResult {
    let bar = ProgressBar::new(range.count());
    bar.set_style(
        ProgressStyle::with_template("[{elapsed_precise}] [{wide_bar}] {pos}/{len} frames {msg}")
            .expect("valid template"),
    );
    let (mut rendered, mut skipped, mut failed) = (0u64, 0u64, 0u64);
    for frame in range.frames() {
        bar.set_message(format!("(frame {frame})"));
        let result = load(file, overrides, Some(frame))
            .map_err(|e| e.into())
            .and_then(|scene| {
                let outputs = scene.outputs();
                let first = outputs.exr.or(outputs.png);
                let done = first.filter(|p| p.exists() && !overwrite);
                // In a log (no terminal) each frame reports its progress.
                let lines = !std::io::stderr().is_terminal();
                match done {
                    Some(_) => Ok(false),
                    None => bar
                        .suspend(|| render_one(&scene, target, lines))
                        .map(|_| true),
                }
            });
        match result {
            Ok(true) => rendered += 1,
            Ok(false) => skipped += 1,
            Err(e) => {
                failed += 1;
                bar.suspend(|| eprintln!("cirrus: frame {frame}: {e}"));
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    eprintln!(
        "{} frames: {rendered} rendered, {skipped} skipped, {failed} failed",
        range.count()
    );
    if failed > 0 {
        return Err(format!("{failed} of {} frames failed", range.count()).into());
    }
    Ok(())
}

fn summary(first: &Path, rendered: &Rendered) {
    let s = &rendered.stats;
    // With adaptive sampling pixels stop at different counts.
    let spp = match s.spp_min == s.spp_max {
        true => format!("{} spp", s.spp_max),
        false => format!(
            "{:.1} spp on average ({}-{})",
            s.spp_mean, s.spp_min, s.spp_max
        ),
    };
    eprintln!(
        "{}: {}x{} at {spp} in {:.2} s ({:.0} paths/s; {} real, {} null collisions; load {:.2} s)",
        first.display(),
        s.width,
        s.height,
        s.wall_seconds,
        s.rays_per_second,
        s.counters.real_collisions,
        s.counters.null_collisions,
        s.load_seconds
    );
    if s.counters.collision_cap_hits > 0 {
        eprintln!(
            "cirrus: warning: {} tracking calls hit the cap of {} collisions (a density far \
             above the rest, such as 1e30): those rays ended carrying no light, so the image is \
             darker there; see the largest values with `cirrus info --stats`",
            s.counters.collision_cap_hits,
            cirrus_render::kernel::tracking::MAX_COLLISIONS
        );
    }
    if let Some(c) = s.camera.as_ref().filter(|c| c.framed) {
        let point = |p: [f64; 3]| format!("{},{},{}", short(p[0]), short(p[1]), short(p[2]));
        eprintln!(
            "camera framed on the volumes: --camera-from {} --camera-to {} --fov {}",
            point(c.from),
            point(c.to),
            c.fov
        );
    }
}

/// A coordinate to four decimals, without trailing zeros.
fn short(x: f64) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    match s {
        "-0" => "0".into(),
        s => s.into(),
    }
}
