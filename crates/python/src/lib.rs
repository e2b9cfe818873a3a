//! The `cirrus._cirrus` extension module: the scene library for Python.
//!
//! It stays small and typed in plain values: reports and statistics cross
//! as JSON text, pixels and voxels as bytes with a shape, and the Python
//! half (`python/cirrus/__init__.py`) turns them into dicts and numpy
//! arrays, so no numpy crate has to be kept in step with pyo3.
//!
//! A render runs on its own thread with the GIL released; the calling
//! thread wakes every 50 ms to run Python's signal handlers (Ctrl-C) and
//! the progress callback, and cancels the render through its
//! `RenderControl` when either raises. Every library error becomes
//! `OSError` (a file) or `ValueError` (the input), with the message the
//! command line prints.

use std::path::PathBuf;
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use cirrus_render::exr_layers::Aov;
use cirrus_render::{RenderControl, Rendered};
use cirrus_scene::{
    Device, Error, ErrorKind, Overrides, RenderTarget, Scene, SceneDescription, VolumeCache,
};
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

fn py_err(e: Error) -> PyErr {
    let message = e.to_string();
    match e.kind() {
        ErrorKind::File => PyOSError::new_err(message),
        ErrorKind::Input => PyValueError::new_err(message),
        ErrorKind::Cancelled => PyKeyboardInterrupt::new_err(message),
    }
}

fn f32_bytes(values: impl IntoIterator<Item = f32>) -> Vec<u8> {
    values.into_iter().flat_map(f32::to_le_bytes).collect()
}

/// The `cirrus info --json` report of a file, as JSON text.
#[pyfunction]
fn file_report(path: PathBuf) -> PyResult<String> {
    let report = cirrus_scene::info::file_report(&path).map_err(py_err)?;
    Ok(report.to_string())
}

/// Grid `name` of `path` over an inclusive index box (or its active box):
/// `(bytes, shape, dtype)` with dtype "f4" or "f8", little-endian, C order.
#[pyfunction]
#[pyo3(signature = (path, name, bbox=None))]
fn read_dense<'py>(
    py: Python<'py>,
    path: PathBuf,
    name: &str,
    bbox: Option<([i32; 3], [i32; 3])>,
) -> PyResult<(Bound<'py, PyBytes>, Vec<usize>, &'static str)> {
    let dense = py
        .detach(|| cirrus_scene::dense::read_dense(&path, name, bbox))
        .map_err(py_err)?;
    let (bytes, dtype) = match (&dense.f32, &dense.f64) {
        (Some(v), _) => (f32_bytes(v.iter().copied()), "f4"),
        (None, Some(v)) => (v.iter().flat_map(|x| x.to_le_bytes()).collect(), "f8"),
        (None, None) => (Vec::new(), "f4"),
    };
    Ok((PyBytes::new(py, &bytes), dense.shape, dtype))
}

/// Converts a grid of `src` to a `.cbrk` at `dst`; returns the `info` report of `dst`.
#[pyfunction]
#[pyo3(signature = (src, dst, grid=None, precision="f16"))]
fn convert(
    py: Python<'_>,
    src: PathBuf,
    dst: PathBuf,
    grid: Option<String>,
    precision: &str,
) -> PyResult<String> {
    let precision = cirrus_bricks::Precision::from_name(precision).ok_or_else(|| {
        PyValueError::new_err(format!("precision {precision:?}: expected f32, f16 or u8"))
    })?;
    py.detach(|| -> Result<String, Error> {
        let file = cirrus_vdb::VolumeFile::open(&src)?;
        let index = cirrus_scene::grids::choose_grid(&file, grid.as_deref())?;
        let g = file.read_grid(index)?;
        let volume = cirrus_bricks::convert(&g, precision)
            .map_err(|e| Error::input(format!("{}: {e}", src.display())))?;
        cirrus_bricks::write_cbrk(&volume, &dst)
            .map_err(|e| Error::file(format!("{}: {e}", dst.display())))?;
        Ok(cirrus_scene::info::file_report(&dst)?.to_string())
    })
    .map_err(py_err)
}

/// What a render hands back: RGBA f32 bytes, width, height, the stats as
/// JSON, and each AOV layer as (name, channel count, f32 bytes).
type RenderOutput<'py> = (
    Bound<'py, PyBytes>,
    u32,
    u32,
    String,
    Vec<(String, usize, Bound<'py, PyBytes>)>,
);

/// Renders a scene file (TOML or a USD stage) or volume (`path`) or a description (`scene_json`,
/// relative to `base_dir`), with overrides as JSON; writes the outputs the
/// overrides or the file name.
#[pyfunction]
#[pyo3(signature = (path, scene_json, base_dir, overrides_json, progress=None, threads=None))]
fn render<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    scene_json: Option<String>,
    base_dir: PathBuf,
    overrides_json: &str,
    progress: Option<Py<PyAny>>,
    threads: Option<usize>,
) -> PyResult<RenderOutput<'py>> {
    let overrides: Overrides = serde_json::from_str(overrides_json)
        .map_err(|e| PyValueError::new_err(format!("overrides: {e}")))?;
    let mut scene = match (path, scene_json) {
        (Some(p), _) => Scene::load(&p),
        (None, Some(text)) => SceneDescription::from_json(&text)
            .map_err(|e| Error::input(format!("scene: {e}")))
            .and_then(|d| Scene::from_description(d, &base_dir)),
        (None, None) => Err(Error::input("give a scene file, a volume file or a dict")),
    }
    .map_err(py_err)?;
    scene.apply(&overrides);
    let control = Arc::new(RenderControl::new());
    let rendered = render_watched(py, scene.clone(), control, progress, threads)?;
    let outputs = scene.outputs();
    py.detach(|| outputs.write(&rendered)).map_err(py_err)?;
    let image = &rendered.image;
    let rgba = PyBytes::new(py, &f32_bytes(image.rgba.iter().flatten().copied()));
    let aovs = match &rendered.aovs {
        None => Vec::new(),
        Some(a) => outputs
            .aovs
            .iter()
            .map(|&aov: &Aov| {
                let channels = aov.channels(a);
                let n = channels.len();
                let len = channels.first().map_or(0, |c| c.1.len());
                let interleaved = (0..len).flat_map(|i| channels.iter().map(move |c| c.1[i]));
                (
                    aov.name().to_string(),
                    n,
                    PyBytes::new(py, &f32_bytes(interleaved)),
                )
            })
            .collect(),
    };
    // What the scene's reader could not render rides with the stats.
    let mut stats: serde_json::Value = serde_json::from_str(&rendered.stats.to_json())
        .map_err(|e| PyValueError::new_err(format!("stats: {e}")))?;
    let mut warnings = scene.warnings().to_vec();
    warnings.extend(rendered.stats.warnings.iter().cloned());
    stats["warnings"] = serde_json::json!(warnings);
    let mut aovs = aovs;
    aovs.extend(group_layers(py, &rendered));
    Ok((rgba, image.width, image.height, stats.to_string(), aovs))
}

/// The light-group layers of a render, as AOV layers (name, 3, RGB bytes).
fn group_layers<'py>(
    py: Python<'py>,
    rendered: &Rendered,
) -> Vec<(String, usize, Bound<'py, PyBytes>)> {
    let Some(layers) = &rendered.layers else {
        return Vec::new();
    };
    let names = layers.group_names.iter().zip(&layers.groups);
    names
        .map(|(name, values)| {
            let bytes = f32_bytes(values.iter().flatten().copied());
            (name.clone(), 3, PyBytes::new(py, &bytes))
        })
        .collect()
}

/// Runs the render on its own thread and waits with the GIL released,
/// waking to run signal handlers and the progress callback.
fn render_watched(
    py: Python<'_>,
    scene: Scene,
    control: Arc<RenderControl>,
    progress: Option<Py<PyAny>>,
    threads: Option<usize>,
) -> PyResult<Rendered> {
    let (tx, rx) = mpsc::channel();
    // Waiting happens with the GIL released, which needs a `Sync` handle;
    // only this thread ever locks it.
    let rx = Mutex::new(rx);
    let wait = |timeout: Option<Duration>| {
        let rx = rx.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        match timeout {
            Some(t) => rx.recv_timeout(t),
            None => rx.recv().map_err(|_| mpsc::RecvTimeoutError::Disconnected),
        }
    };
    let worker_control = control.clone();
    let worker = std::thread::spawn(move || {
        // `device = "gpu"|"auto"` (the scene's, or the keyword's) renders
        // where `cirrus render --device` would; the CPU is watched (`auto`'s
        // fall-back to it too), a GPU render runs to its end.
        let device = scene.settings().map(|s| s.device).unwrap_or_default();
        let run = || match device {
            Device::Cpu => scene.render_with(Some(worker_control)),
            _ => RenderTarget::open(device).and_then(|t| {
                t.render_cached(&scene, &mut VolumeCache::default(), Some(worker_control))
            }),
        };
        let result = match threads {
            None => run(),
            Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
                Ok(pool) => pool.install(run),
                Err(e) => Err(Error::input(format!("threads: {e}"))),
            },
        };
        let _ = tx.send(result);
    });
    loop {
        let waited = py.detach(|| wait(Some(Duration::from_millis(50))));
        match waited {
            Ok(result) => {
                let _ = worker.join();
                return result.map_err(py_err);
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                let _ = worker.join();
                return Err(PyValueError::new_err(
                    "the render thread ended without a result",
                ));
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
        // The callback hears of the render once it has a total (not while
        // the volume loads: (0, 0) would say nothing).
        let checked = py.check_signals().and_then(|()| match &progress {
            Some(callback) if control.progress().1 > 0 => {
                callback.call1(py, control.progress()).map(drop)
            }
            _ => Ok(()),
        });
        if let Err(e) = checked {
            control.cancel();
            // The render stops at its next tile; wait for it so no thread
            // outlives the call.
            let _ = py.detach(|| wait(None));
            let _ = worker.join();
            return Err(e);
        }
    }
}

#[pymodule]
fn _cirrus(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(file_report, m)?)?;
    m.add_function(wrap_pyfunction!(read_dense, m)?)?;
    m.add_function(wrap_pyfunction!(convert, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    Ok(())
}
