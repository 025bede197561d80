//! The `phong` Python module's native part (`phong._phong`): a scene held as its document,
//! rendered by phong's renderers into numpy arrays with the GIL released. The Python package
//! (`python/phong/`) adds the attribute access, pickling and documentation; no rendering or
//! scene logic lives on either side of the binding that the CLI does not share.

mod render;
mod scene;

use pyo3::prelude::*;

pyo3::create_exception!(
    _phong,
    InputError,
    pyo3::exceptions::PyValueError,
    "An error in what was given (a scene, a model, a value): the message is the `phong` command's exit-2 message, naming the file, line, column and key."
);
pyo3::create_exception!(
    _phong,
    RenderError,
    pyo3::exceptions::PyRuntimeError,
    "A render that failed for a reason other than its input (no GPU adapter, an internal error)."
);

/// A Python exception for a phong error: `InputError` where it is in the input.
pub(crate) fn py_err(e: phong_run::Error) -> PyErr {
    if e.is_input() {
        InputError::new_err(phong_run::message(&e))
    } else {
        RenderError::new_err(phong_run::message(&e))
    }
}

/// Runs `f`, turning a panic into a `RenderError` (a bug, never an abort of the interpreter).
pub(crate) fn guarded<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|p| {
        let what = p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default();
        Err(RenderError::new_err(format!(
            "internal error (a bug in phong; please report it): {what}"
        )))
    })
}

#[pymodule]
fn _phong(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add("RenderError", m.py().get_type::<RenderError>())?;
    m.add_class::<scene::SceneCore>()?;
    m.add_class::<render::RendererCore>()?;
    m.add_function(wrap_pyfunction!(render::render_path, m)?)?;
    m.add_function(wrap_pyfunction!(scene::materials, m)?)?;
    m.add_function(wrap_pyfunction!(render::save_png, m)?)?;
    m.add_function(wrap_pyfunction!(render::is_complete_png, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
