//! `cirrus render FILE|SCENE.toml -o OUT.exr [flags]`: maps the flags onto
//! the scene library, renders, writes the outputs and prints a summary.

use super::CliResult;
use cirrus_render::Rendered;
use cirrus_scene::{OutputFlags, Scene, SceneFlags};

#[derive(clap::Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneFlags,
    #[command(flatten)]
    pub output: OutputFlags,
}

pub fn run(args: &RenderArgs) -> CliResult {
    let mut scene = Scene::load(&args.scene.file)?;
    let mut overrides = args.scene.overrides();
    args.output.write_into(&mut overrides);
    scene.apply(&overrides);
    scene.progress_bar = true;
    let outputs = scene.outputs();
    let Some(exr) = outputs.exr.clone() else {
        return Err(
            if args.scene.file.extension().is_some_and(|e| e == "toml") {
                "an output file is required: -o OUT.exr or [output] exr = \"...\"".into()
            } else {
                "an output file is required: -o OUT.exr".into()
            },
        );
    };
    let rendered = scene.render()?;
    if rendered.stats.volumes_culled > 0 {
        eprintln!(
            "{} volume(s) neither the camera nor the lights can reach: not loaded",
            rendered.stats.volumes_culled
        );
    }
    outputs.write(&rendered)?;
    summary(&exr, &rendered);
    Ok(())
}

fn summary(exr: &std::path::Path, rendered: &Rendered) {
    let s = &rendered.stats;
    eprintln!(
        "{}: {}x{} at {} spp in {:.2} s ({:.0} paths/s; {} real, {} null collisions; load {:.2} s)",
        exr.display(),
        s.width,
        s.height,
        s.spp,
        s.wall_seconds,
        s.rays_per_second,
        s.counters.real_collisions,
        s.counters.null_collisions,
        s.load_seconds
    );
}
