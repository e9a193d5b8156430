//! `drapelab._drapelab`: the native half of drapelab's Python package (`python/drapelab/`), built
//! by maturin (`pip install .`). Thin pyo3 glue over the application layer: every function takes
//! plain values (paths, JSON text, little-endian byte buffers) and returns them, and the Python half
//! turns them into NumPy arrays, dicts and a `Result` object. Bad input raises
//! `drapelab.InputError` (a `ValueError`) whose message names the file or key, as the command line's
//! exit code 2 does; a solve that does not converge is a status, never an exception. Long work
//! releases the GIL; a solve checks for Ctrl-C between its iterations.

#![warn(missing_docs)]
#![allow(non_snake_case)]

mod convert;
mod interrupt;
mod watch;

use convert::{bytes_f64, f64_bytes, json, load_scene, u32_bytes};
use drapelab_app::calibration::calibrate::{CalibrateParams, calibrate_one, calibrate_one_lm};
use interrupt::Interrupt;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::Path;

pyo3::create_exception!(
    _drapelab,
    InputError,
    PyValueError,
    "Bad input: the message names the file (or argument) and the key, as the command line's exit code 2 does."
);

/// Any error of the layers below as a Python exception: an input error as `InputError`.
pub(crate) fn to_py(e: anyhow::Error) -> PyErr {
    let input = e
        .chain()
        .find_map(|c| c.downcast_ref::<drapelab_core::error::InputError>());
    match input {
        Some(ie) => InputError::new_err(ie.to_string()),
        None => PyRuntimeError::new_err(format!("{e:#}")),
    }
}

/// What `simulate` hands the Python half: run.json's text, positions (n × 3 f64, m), present
/// (n bytes), triangles (m × 3 u32), nx, ny, the seconds spent in Rust (scene loaded, solved,
/// files written, arrays made), the sensitivities asked for (key, n × 3 f64 m per unit) and the
/// frames kept (iteration or step, simulated time, n × 3 f64 m).
type Simulated<'py> = (
    String,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    Bound<'py, PyBytes>,
    usize,
    usize,
    f64,
    Vec<(String, Bound<'py, PyBytes>)>,
    Vec<(usize, Option<f64>, Bound<'py, PyBytes>)>,
);

/// Solves a scene (a TOML file, or a table as JSON text) with dotted overrides (JSON object) into
/// the folder `out`, as `drapelab simulate --out` does.
#[pyfunction]
#[pyo3(signature = (scene_path, scene_json, set_json, out, sensitivity=Vec::new(), frames=0, progress=None, start=None))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    scene_path: Option<String>,
    scene_json: Option<String>,
    set_json: &str,
    out: &str,
    sensitivity: Vec<String>,
    frames: usize,
    progress: Option<Py<PyAny>>,
    start: Option<String>,
) -> PyResult<Simulated<'py>> {
    let started = std::time::Instant::now();
    let loaded = load_scene(scene_path.as_deref(), scene_json.as_deref(), set_json)?;
    drapelab_core::build::check_something_free(&loaded)
        .map_err(|e| InputError::new_err(e.to_string()))?;
    for key in &sensitivity {
        drapelab_core::sensitivity::check_key(&loaded.scene, key, "sensitivity")
            .map_err(|e| InputError::new_err(e.to_string()))?;
    }
    let start = start
        .map(|f| drapelab_record::read_start(Path::new(&f), &loaded.scene, "start"))
        .transpose()
        .map_err(|e| InputError::new_err(e.to_string()))?;
    let extras = drapelab_record::SimulateExtras {
        sensitivity_keys: sensitivity,
        start,
        ..Default::default()
    };
    let out = Path::new(out).to_path_buf();
    let n = loaded.scene.grid().len();
    let (done, interrupted, watch) = py.detach(|| {
        let mut stop = Interrupt::new();
        let mut watch = watch::Watch::new(progress, frames, n);
        let mut both = drapelab_core::solve::Observers(vec![&mut stop, &mut watch]);
        let done = drapelab_record::simulate_to_dir_with(&loaded, &out, &mut both, &extras);
        (done, stop.into_error(), watch)
    });
    if let Some(e) = interrupted.or(watch.error) {
        return Err(e);
    }
    let s = done.map_err(to_py)?;
    let run = std::fs::read_to_string(out.join("run.json"))
        .map_err(|e| PyRuntimeError::new_err(format!("cannot read run.json: {e}")))?;
    let xyz: Vec<f64> = s.x.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    let present: Vec<u8> = s.absent.iter().map(|&a| u8::from(!a)).collect();
    let tris: Vec<u32> = drapelab_core::build::scene_triangles(&loaded.scene)
        .into_iter()
        .flatten()
        .collect();
    Ok((
        run,
        PyBytes::new(py, &f64_bytes(&xyz)),
        PyBytes::new(py, &present),
        PyBytes::new(py, &u32_bytes(&tris)),
        s.grid.nx,
        s.grid.ny,
        started.elapsed().as_secs_f64(),
        s.sensitivity
            .iter()
            .map(|(k, dx)| {
                let v: Vec<f64> = dx.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
                (k.clone(), PyBytes::new(py, &f64_bytes(&v)))
            })
            .collect(),
        watch
            .frames
            .iter()
            .map(|(i, t, x)| (*i, *t, PyBytes::new(py, &f64_bytes(x))))
            .collect(),
    ))
}

/// The Cusick tester's measures (BS 5058 drape coefficient, nodes, the outline) of a mesh's
/// vertical projection: positions (n × 3 f64, m) and triangles (m × 3 u32); JSON text.
#[pyfunction]
fn drape_of_mesh(positions: &[u8], triangles: &[u8]) -> PyResult<String> {
    let x = bytes_f64(positions)?;
    let t = convert::bytes_to_u32(triangles)?;
    if !x.len().is_multiple_of(3) || !t.len().is_multiple_of(3) {
        return Err(InputError::new_err(
            "positions must be n × 3 and triangles m × 3",
        ));
    }
    let n = x.len() / 3;
    let pts: Vec<nalgebra::Vector3<f64>> = x
        .chunks(3)
        .map(|c| nalgebra::Vector3::new(c[0], c[1], c[2]))
        .collect();
    let tris: Vec<[usize; 3]> = t
        .chunks(3)
        .map(|c| [c[0] as usize, c[1] as usize, c[2] as usize])
        .collect();
    if let Some(bad) = tris.iter().flatten().find(|&&i| i >= n) {
        return Err(InputError::new_err(format!(
            "triangles: vertex {bad} of {n} positions"
        )));
    }
    shadow(&drapelab_core::cusick::mesh_projection(&pts, &tris))
}

/// The tester's measures of a shadow as JSON text.
fn shadow(p: &drapelab_core::measure::Projection) -> PyResult<String> {
    let tester = drapelab_core::cusick::Tester::default();
    json(&drapelab_core::cusick::shadow_measures(p, &tester))
}

/// The same measures of a silhouette photo (dark shadow on light), with its scale as JSON text
/// (`px_per_m`, `centre_px`, `threshold`; defaults those of the BDP dataset).
#[pyfunction]
fn drape_of_silhouette(path: &str, scale_json: &str) -> PyResult<String> {
    let scale: drapelab_core::cusick::SilhouetteScale =
        serde_json::from_str(scale_json).map_err(|e| InputError::new_err(format!("scale: {e}")))?;
    let img = image::open(path)
        .map_err(|e| InputError::new_err(format!("{path}: cannot read the photo: {e}")))?
        .to_luma8();
    shadow(&drapelab_core::cusick::silhouette_projection(&img, &scale))
}

/// The edges of a photo (seed 000 Figs 11-12) calibrated by `camera` (camera.json); JSON text.
#[pyfunction]
fn fit_edges(py: Python<'_>, photo: &str, camera: &str, degree: usize) -> PyResult<String> {
    let edges = py
        .detach(|| {
            drapelab_app::photos::fit_edges::photo_edges(
                Path::new(photo),
                Path::new(camera),
                degree,
            )
        })
        .map_err(to_py)?;
    json(&edges)
}

/// One sample of an edges table calibrated by ICA (seed 000) with the calibrate stage's parameters
/// (JSON text); the results row as JSON text.
#[pyfunction]
fn calibrate(
    py: Python<'_>,
    edges: &str,
    samples: &str,
    scene: &str,
    sample: &str,
    params_json: &str,
) -> PyResult<String> {
    let p = calibrate_params(params_json, false)?;
    let files = (Path::new(edges), Path::new(samples), Path::new(scene));
    let row = py
        .detach(|| calibrate_one(files, sample, &p))
        .map_err(to_py)?;
    json(&row)
}

/// The calibrate stage's parameters from JSON text, checked as the stage checks them; `without_ica`:
/// ICA's settings play no part (calibration by gradients) and may be left out.
fn calibrate_params(params_json: &str, without_ica: bool) -> PyResult<CalibrateParams> {
    let mut p: CalibrateParams = serde_json::from_str(params_json)
        .map_err(|e| InputError::new_err(format!("params: {e}")))?;
    if without_ica {
        p.ica_from_input = p.ica.is_none();
    }
    p.check()
        .map_err(|e| InputError::new_err(format!("params: key `{}`: {}", e.key, e.message)))?;
    Ok(p)
}

/// One sample of an edges table calibrated by gradients (Levenberg–Marquardt on the drapes'
/// sensitivities) with the calibrate stage's grid, side and edge source; its row as JSON text.
#[pyfunction]
fn calibrate_lm(
    py: Python<'_>,
    edges: &str,
    samples: &str,
    scene: &str,
    sample: &str,
    params_json: &str,
) -> PyResult<String> {
    let p = calibrate_params(params_json, true)?;
    let files = (Path::new(edges), Path::new(samples), Path::new(scene));
    let row = py
        .detach(|| calibrate_one_lm(files, sample, &p))
        .map_err(to_py)?;
    json(&row)
}

/// Runs a pipeline make-style (`drapelab run`); the summary as JSON text.
#[pyfunction]
#[pyo3(signature = (path, until, force, progress=None))]
fn run_pipeline(
    py: Python<'_>,
    path: &str,
    until: Option<String>,
    force: Vec<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let registry = drapelab_stages::registry();
    let plan = drapelab_pipeline::load_checked_plan(Path::new(path), &registry).map_err(to_py)?;
    let opts = drapelab_pipeline::RunOptions {
        until,
        force,
        ..Default::default()
    };
    let lines = interrupt::StageLines::with(progress);
    let summary = py.detach(|| drapelab_pipeline::run_pipeline(&plan, &opts, &lines));
    if let Some(e) = lines.into_error() {
        return Err(e);
    }
    let summary = summary.map_err(to_py)?;
    let failed: serde_json::Map<String, serde_json::Value> = summary
        .failed
        .iter()
        .map(|(n, why)| (n.clone(), why.to_string().into()))
        .collect();
    json(&serde_json::json!({
        "pipeline": plan.name,
        "run_dir": plan.run_dir().display().to_string(),
        "ran": summary.ran,
        "up_to_date": summary.skipped,
        "failed": failed,
        "ok": summary.failed.is_empty(),
    }))
}

/// drapelab's version.
#[pyfunction]
fn version() -> &'static str {
    drapelab_core::VERSION
}

/// A TOML scene file's text parsed and validated; its table back as JSON text (the dict a
/// notebook edits and passes to `simulate`), the files it names as absolute paths.
#[pyfunction]
fn read_scene(path: &str) -> PyResult<String> {
    let mut table = drapelab_core::config::read_toml_table(Path::new(path))
        .map_err(|e| InputError::new_err(e.to_string()))?;
    // The files it names made absolute: the dict means the same scene from any folder.
    drapelab_core::scene::absolute_file_keys(&mut table, Path::new(path));
    json(&table)
}

#[pymodule]
fn _drapelab(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(drape_of_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(drape_of_silhouette, m)?)?;
    m.add_function(wrap_pyfunction!(fit_edges, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_lm, m)?)?;
    m.add_function(wrap_pyfunction!(run_pipeline, m)?)?;
    m.add_function(wrap_pyfunction!(read_scene, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    Ok(())
}
