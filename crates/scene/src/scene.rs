//! [`Scene`]: a description on its way to an image.
//!
//! A scene is made from a scene file, from a lone volume file (rendered as
//! `cirrus render FILE` renders it: a scene of that one volume, placed on
//! its own grid), or from a description built in code. [`Overrides`] are
//! written over it, then [`Scene::render`] takes the one road of
//! `prepare.rs`: the volumes are planned from their headers, culled
//! (`cull.rs`), only the grids that can matter are read (`plan.rs`), and
//! the instances render together under a top-level BVH (one instance takes
//! the renderer's fast path).
//!
//! Input paths of a scene file are relative to the file; output paths and
//! paths given as overrides are relative to the working directory.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use cirrus_render::{RenderControl, Rendered};

use crate::description::{SceneDescription, VolumeSpec};
use crate::error::{Error, Result};
use crate::output::Outputs;
use crate::overrides::Overrides;
use crate::plan::VolumeCache;
use crate::prepare::{prepare, Placement, Prepared};
use crate::settings::SceneSettings;

/// A scene description ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    description: SceneDescription,
    placement: Placement,
    /// Show progress on stderr while rendering: a bar on a terminal,
    /// plain lines every few seconds on anything else (a log).
    pub progress_bar: bool,
    /// Print what loading found wrong (bad voxels, an open shutter with
    /// no velocity) on stderr as it is found, before the render; it is in
    /// the statistics' `warnings` either way.
    pub warn_on_stderr: bool,
    /// What the scene's reader could not render (a USD stage's meshes...).
    warnings: Vec<String>,
}

impl Scene {
    /// A scene file (`.toml`), a USD stage (`.usd`, `.usda`, `.usdc`,
    /// `.usdz`; `usd/`), or a lone `.vdb`, `.nvdb` or `.cbrk` volume.
    pub fn load(path: &Path) -> Result<Scene> {
        if crate::usd::is_usd(path) {
            let stage = crate::usd::read(path)?;
            let mut scene = Scene::from_description(stage.description, parent(path))
                .map_err(|e| e.within(path.display()))?;
            scene.warnings = stage.warnings;
            Ok(scene)
        } else if path.extension().is_some_and(|e| e == "toml") {
            let description = SceneDescription::read(path)?;
            Scene::from_description(description, parent(path)).map_err(|e| e.within(path.display()))
        } else {
            Ok(Scene::volume(path))
        }
    }

    /// A lone volume file, rendered under the default sun and sky.
    pub fn volume(path: &Path) -> Scene {
        Scene {
            description: SceneDescription {
                volumes: vec![VolumeSpec {
                    file: path.to_path_buf(),
                    ..Default::default()
                }],
                ..Default::default()
            },
            placement: Placement::OwnGrid,
            progress_bar: false,
            warn_on_stderr: false,
            warnings: Vec::new(),
        }
    }

    /// A description whose input paths are relative to `dir`.
    pub fn from_description(mut description: SceneDescription, dir: &Path) -> Result<Scene> {
        if description.volumes.is_empty() {
            return Err(Error::input("no [[volume]] in the scene"));
        }
        description.rebase(dir);
        crate::light_checks::check_maps(&description)?;
        crate::compositing::instance_names(&description)?;
        description.hold_file_samples();
        Ok(Scene {
            description,
            placement: Placement::Volumes,
            progress_bar: false,
            warn_on_stderr: false,
            warnings: Vec::new(),
        })
    }

    /// What the reader could not render (listed, never fatal).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    pub fn description(&self) -> &SceneDescription {
        &self.description
    }

    /// Writes the given overrides over the description.
    pub fn apply(&mut self, overrides: &Overrides) {
        overrides.apply(&mut self.description);
    }

    /// The scene-wide settings, resolved (reads the sky map, if any).
    pub fn settings(&self) -> Result<SceneSettings> {
        SceneSettings::resolve(&self.description)
    }

    pub fn outputs(&self) -> Outputs {
        Outputs::resolve(&self.description)
    }

    /// Renders the scene; see the module doc.
    pub fn render(&self) -> Result<Rendered> {
        self.render_with(None)
    }

    /// [`Scene::render`], watched and stoppable through `control`.
    pub fn render_with(&self, control: Option<Arc<RenderControl>>) -> Result<Rendered> {
        self.render_cached(&mut VolumeCache::default(), control)
    }

    /// An error where every sample of `rendered` was dropped as NaN or
    /// infinite, whichever device made it: its image would be black.
    pub fn refuse_all_dropped(rendered: &Rendered) -> Result<()> {
        refuse_all_dropped(&rendered.stats.counters)
    }

    /// What to tell the user about a finished render: samples it dropped
    /// as NaN or infinite (each counted, none written), and an image
    /// with no light in it at all.
    pub fn render_warnings(rendered: &Rendered) -> Vec<String> {
        let c = &rendered.stats.counters;
        let mut out = Vec::new();
        if c.nonfinite_samples > 0 {
            out.push(format!(
                "{} of {} samples were NaN or infinite and were dropped: the image is darker \
                 where they fell",
                c.nonfinite_samples, c.paths
            ));
        }
        let rgba = &rendered.image.rgba;
        if !rgba.is_empty() && rgba.iter().all(|p| p[..3] == [0.0; 3]) {
            out.push(
                "the image is black: no light reaches the camera (are the lights pointed at \
                 the volumes, and bright enough?)"
                    .into(),
            );
        }
        out
    }

    /// [`Scene::render_with`] reading files and grids through `cache`,
    /// which keeps them for the next render (a preview's passes).
    pub fn render_cached(
        &self,
        cache: &mut VolumeCache,
        control: Option<Arc<RenderControl>>,
    ) -> Result<Rendered> {
        let prepared = self.prepare(cache, control.clone())?;
        if self.warn_on_stderr {
            for w in &prepared.warnings {
                eprintln!("cirrus: warning: {w}");
            }
        }
        let mut rendered = prepared.render();
        if control.as_ref().is_some_and(|c| c.is_cancelled()) {
            return Err(Error::cancelled());
        }
        refuse_all_dropped(&rendered.stats.counters)?;
        // A crop is denoised where the whole image exists, at the merge
        // (denoise_tiles.rs): it keeps the denoiser's inputs instead.
        if self.description.render.denoise.unwrap_or(false) {
            match self.outputs().crop {
                None => crate::denoise::denoise(&mut rendered)?,
                Some(_) => rendered.stats.warnings.push(
                    "a crop is not denoised alone: its EXR keeps the denoiser's inputs and \
                     `cirrus merge` denoises the whole image"
                        .into(),
                ),
            }
        }
        Ok(rendered)
    }

    /// What the renderer takes for this scene: its settings resolved, the
    /// outputs' crop and AOVs, and the volumes that can matter loaded
    /// through `cache` and placed in render space.
    pub fn prepare<'c>(
        &self,
        cache: &'c mut VolumeCache,
        control: Option<Arc<RenderControl>>,
    ) -> Result<Prepared<'c>> {
        let outputs = self.outputs();
        outputs.check()?;
        let mut settings = self.settings()?;
        let denoise = self.description.render.denoise.unwrap_or(false);
        let r = &mut settings.render;
        r.crop = outputs.crop;
        // The denoiser is guided by the albedo AOV, and its error is
        // measured on the two halves of the samples.
        r.aovs = !outputs.aovs.is_empty() || denoise;
        r.halves = denoise;
        r.control = control;
        r.progress = self.progress_bar;
        if let Some(c) = &outputs.crop {
            c.validate(settings.res.0, settings.res.1)?;
        }
        if let Some(deep) = &outputs.deep {
            // Before the render, not after it: the library is loaded at
            // run time and may be missing.
            cirrus_deep_exr::load_library()
                .map_err(|e| Error::file(format!("{}: {e}", deep.display())))?;
        }
        crate::compositing::configure(
            &mut settings.render,
            outputs.layer_request(),
            &self.description,
            settings.res,
        )?;
        prepare(&self.description, settings, self.placement, cache)
    }

    /// The scene of frame `frame`: every input and output path with its
    /// frame pattern replaced (see [`frames`](crate::frames)).
    pub fn for_frame(&self, frame: i64) -> Scene {
        let mut scene = self.clone();
        scene.description.substitute_frame(frame);
        scene
    }

    /// The volume files the scene names (after overrides).
    pub fn inputs(&self) -> Vec<PathBuf> {
        self.description
            .volumes
            .iter()
            .map(|v| v.file.clone())
            .collect()
    }
}

fn parent(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// An error where every sample of a render was dropped as NaN or
/// infinite: its image would be black, not a picture of the scene.
fn refuse_all_dropped(c: &cirrus_render::Counters) -> Result<()> {
    if c.paths > 0 && c.nonfinite_samples >= c.paths {
        return Err(Error::input(format!(
            "every one of the {} samples was NaN or infinite and was dropped, so the image \
             would be black: the lights' or the media's values overflow (they are counted \
             as nonfinite_samples in --stats)",
            c.nonfinite_samples
        )));
    }
    Ok(())
}

#[cfg(test)]
mod dropped_samples_tests {
    use super::*;

    #[test]
    fn a_render_fails_only_when_every_sample_was_dropped() {
        let mut c = cirrus_render::Counters {
            paths: 1024,
            nonfinite_samples: 1023,
            ..Default::default()
        };
        assert!(refuse_all_dropped(&c).is_ok());
        c.nonfinite_samples = 1024;
        let e = refuse_all_dropped(&c).unwrap_err().to_string();
        assert!(e.contains("every one of the 1024 samples"), "{e}");
        // No paths (an empty crop): nothing to refuse.
        assert!(refuse_all_dropped(&cirrus_render::Counters::default()).is_ok());
    }
}
