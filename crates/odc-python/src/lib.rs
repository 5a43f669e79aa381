//! The native half of the `odc` Python package (`odc._odc`): device files loaded, checked,
//! converted, compared and documented through the same library calls the `odc` commands make
//! (`odc-pipeline`, `odc-eds`, `odc-xdd`, `odc-diff`, `odc-doc`), and the checked model handed
//! to Python as read-only classes (`model.rs`).
//!
//! The Python half (`python/odc`) re-exports these functions with their documentation, turns
//! `diff`'s JSON into dicts and builds python-canopen objects (`odc.canopen`).
// Bad input is a Python exception, never a panic.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]
// The functions take Python's keyword arguments, one parameter each.
#![allow(clippy::too_many_arguments)]

mod canopen;
mod model;

use std::path::{Path, PathBuf};

use odc_model::{Diagnostic, Format, Sources};
use odc_pipeline::{Level, Loaded, Options, Select};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// The rule levels and device selection every function takes, as `odc`'s command line has them
/// (`-A`, `-W`, `-D`, `--strict`, `--config`, `--device`).
pub(crate) struct Rules {
    allow: Vec<String>,
    warn: Vec<String>,
    deny: Vec<String>,
    strict: bool,
    config: Option<PathBuf>,
    device: Option<String>,
}

impl Rules {
    fn options(&self, base: Options) -> Options {
        let mut options = base.strict(self.strict);
        options.config_file = self.config.clone();
        for (names, level) in
            [(&self.allow, Level::Allow), (&self.warn, Level::Warn), (&self.deny, Level::Deny)]
        {
            for name in names {
                options = options.level(name.clone(), level);
            }
        }
        if let Some(spec) = &self.device {
            options = options.select(Select::Spec(spec.clone()));
        }
        options
    }
}

/// Reads and checks a file; `bytes` when the caller read it already (a file-like object).
pub(crate) fn load_file(
    path: &Path,
    bytes: Option<Vec<u8>>,
    rules: &Rules,
    base: Options,
) -> PyResult<Loaded> {
    let options = rules.options(base);
    let loaded = match bytes {
        Some(bytes) => odc_pipeline::load_bytes(path, bytes, &options),
        None => odc_pipeline::load(path, &options),
    };
    loaded.map_err(|e| match e {
        odc_pipeline::Error::Io { ref source, .. } => {
            // FileNotFoundError, PermissionError, … as Python's own `open` raises them.
            let message = e.to_string();
            let err = PyErr::from(std::io::Error::from(source.kind()));
            Python::attach(|py| {
                let kind = err.get_type(py);
                PyErr::from_type(kind, message)
            })
        }
        other => PyValueError::new_err(other.to_string()),
    })
}

/// The error gate: `odc.Refused` (a `ValueError`) with the error-level diagnostics.
pub(crate) fn gate(py: Python<'_>, loaded: &Loaded) -> PyResult<()> {
    match loaded.gate() {
        Ok(()) => Ok(()),
        Err(refused) => {
            let errors: Vec<Diagnostic> = loaded.errors().cloned().collect();
            let diagnostics = diagnostics_list(py, &loaded.sources, &errors)?;
            let class = py.import("odc._errors")?.getattr("Refused")?;
            let value = class.call1((refused.to_string(), diagnostics))?;
            Err(PyErr::from_value(value))
        }
    }
}

/// The one device the function works on (`device=` picks one of an ESI's).
pub(crate) fn one_device(loaded: &Loaded) -> PyResult<&odc_model::Device> {
    loaded.device().map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Diagnostics as dicts: code, severity, message, file, line, column (of the primary label;
/// `None` when the diagnostic has no place in a file), notes.
fn diagnostics_list<'py>(
    py: Python<'py>,
    sources: &Sources,
    diags: &[Diagnostic],
) -> PyResult<Bound<'py, PyList>> {
    let list = PyList::empty(py);
    for d in diags {
        let dict = PyDict::new(py);
        dict.set_item("code", d.code)?;
        dict.set_item("severity", d.severity.as_str())?;
        dict.set_item("message", &d.message)?;
        let span = d.primary_span().filter(|s| !s.is_dummy());
        let place = span.and_then(|s| sources.line_col(s).map(|lc| (s, lc)));
        dict.set_item("file", span.and_then(|s| sources.name(s.file)))?;
        dict.set_item("line", place.map(|(_, lc)| lc.line))?;
        dict.set_item("column", place.map(|(_, lc)| lc.column))?;
        dict.set_item("notes", &d.notes)?;
        match d.object {
            Some((index, sub)) => dict.set_item("object", (index, sub))?,
            None => dict.set_item("object", py.None())?,
        }
        list.append(dict)?;
    }
    Ok(list)
}

pub(crate) fn rules(
    allow: Vec<String>,
    warn: Vec<String>,
    deny: Vec<String>,
    strict: bool,
    config: Option<PathBuf>,
    device: Option<String>,
) -> Rules {
    Rules { allow, warn, deny, strict, config, device }
}

/// Reads and checks a device file; the checked model (`odc.Device`). Refused (`odc.Refused`)
/// when a diagnostic is at error level.
#[pyfunction]
#[pyo3(signature = (path, *, allow=Vec::new(), warn=Vec::new(), deny=Vec::new(), strict=false, config=None, device=None, data=None))]
fn load(
    py: Python<'_>,
    path: PathBuf,
    allow: Vec<String>,
    warn: Vec<String>,
    deny: Vec<String>,
    strict: bool,
    config: Option<PathBuf>,
    device: Option<String>,
    data: Option<Vec<u8>>,
) -> PyResult<Py<model::Device>> {
    let rules = rules(allow, warn, deny, strict, config, device);
    let mut base = Options::new();
    base.source_hash = false;
    let loaded = py.detach(|| load_file(&path, data, &rules, base))?;
    gate(py, &loaded)?;
    let device = one_device(&loaded)?;
    model::device(py, device, &loaded.sources, &loaded.diagnostics, true)
}

/// The diagnostics of a device file as dicts (every device of an ESI, unless `device=`).
#[pyfunction]
#[pyo3(signature = (path, *, allow=Vec::new(), warn=Vec::new(), deny=Vec::new(), strict=false, config=None, device=None))]
fn check<'py>(
    py: Python<'py>,
    path: PathBuf,
    allow: Vec<String>,
    warn: Vec<String>,
    deny: Vec<String>,
    strict: bool,
    config: Option<PathBuf>,
    device: Option<String>,
) -> PyResult<Bound<'py, PyList>> {
    let rules = rules(allow, warn, deny, strict, config, device);
    let mut base = Options::new();
    base.source_hash = false;
    let loaded = py.detach(|| load_file(&path, None, &rules, base))?;
    diagnostics_list(py, &loaded.sources, &loaded.diagnostics)
}

/// A device file written as EDS, DCF, XDD or XDC (`to`); the text. As `odc convert`: an ESI
/// device gets the CiA 301 mandatory objects it lacks.
#[pyfunction]
#[pyo3(signature = (path, to, *, allow=Vec::new(), warn=Vec::new(), deny=Vec::new(), strict=false, config=None, device=None))]
fn convert(
    py: Python<'_>,
    path: PathBuf,
    to: &str,
    allow: Vec<String>,
    warn: Vec<String>,
    deny: Vec<String>,
    strict: bool,
    config: Option<PathBuf>,
    device: Option<String>,
) -> PyResult<String> {
    let format = match to.to_ascii_lowercase().as_str() {
        "eds" => Format::Eds,
        "dcf" => Format::Dcf,
        "xdd" => Format::Xdd,
        "xdc" => Format::Xdc,
        other => {
            return Err(PyValueError::new_err(format!(
                "cannot convert to {other:?}; formats: eds, dcf, xdd, xdc"
            )));
        }
    };
    let rules = rules(allow, warn, deny, strict, config, device);
    let loaded = py.detach(|| load_file(&path, None, &rules, Options::new()))?;
    gate(py, &loaded)?;
    let mut device = one_device(&loaded)?.clone();
    Ok(py.detach(|| {
        odc_eds::add_mandatory_objects(&mut device);
        match format {
            Format::Xdd | Format::Xdc => odc_xdd::write(&device, format).text,
            _ => odc_eds::write(&device, format),
        }
    }))
}

/// What changed between two device files, as `odc diff --format json` prints it (a JSON
/// array; the Python side parses it). The CiA and ETG rules do not gate a comparison.
#[pyfunction]
#[pyo3(signature = (a, b, *, ignore_names=false, ignore_comments=false, ignore_defaults=false, device_a=None, device_b=None))]
fn diff_json(
    py: Python<'_>,
    a: PathBuf,
    b: PathBuf,
    ignore_names: bool,
    ignore_comments: bool,
    ignore_defaults: bool,
    device_a: Option<String>,
    device_b: Option<String>,
) -> PyResult<String> {
    let load_one = |path: &Path, device: Option<String>| -> PyResult<Loaded> {
        let rules = rules(
            ["cia301", "cia402", "etg"].map(str::to_owned).to_vec(),
            Vec::new(),
            Vec::new(),
            false,
            None,
            device,
        );
        let mut base = Options::new();
        base.source_hash = false;
        let loaded = py.detach(|| load_file(path, None, &rules, base))?;
        gate(py, &loaded)?;
        Ok(loaded)
    };
    let (la, lb) = (load_one(&a, device_a)?, load_one(&b, device_b)?);
    let (da, db) = (one_device(&la)?, one_device(&lb)?);
    let opts = odc_diff::Options { ignore_names, ignore_comments, ignore_defaults };
    Ok(py.detach(|| odc_diff::json(&odc_diff::diff(da, db, &opts))))
}

/// A device's data sheet as `odc doc` writes it: `format` "html" (one self-contained page) or
/// "md" (Markdown); the text.
#[pyfunction]
#[pyo3(signature = (path, format="html", *, allow=Vec::new(), warn=Vec::new(), deny=Vec::new(), strict=false, config=None, device=None))]
fn doc(
    py: Python<'_>,
    path: PathBuf,
    format: &str,
    allow: Vec<String>,
    warn: Vec<String>,
    deny: Vec<String>,
    strict: bool,
    config: Option<PathBuf>,
    device: Option<String>,
) -> PyResult<String> {
    let html = match format.to_ascii_lowercase().as_str() {
        "html" => true,
        "md" | "markdown" => false,
        other => {
            return Err(PyValueError::new_err(format!(
                "no data sheet format {other:?}; formats: html, md"
            )));
        }
    };
    let rules = rules(allow, warn, deny, strict, config, device);
    let loaded = py.detach(|| load_file(&path, None, &rules, Options::new()))?;
    gate(py, &loaded)?;
    let device = one_device(&loaded)?;
    let file = loaded.file_name();
    let input = odc_doc::Input {
        device,
        file: &file,
        sources: Some(&loaded.sources),
        diagnostics: &loaded.diagnostics,
        schemes: &loaded.codegen.scheme,
    };
    Ok(py.detach(|| {
        if html { odc_doc::render_html(&input) } else { odc_doc::render_markdown(&input) }
    }))
}

/// The module `odc._odc`.
#[pymodule]
fn _odc(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(convert, m)?)?;
    m.add_function(wrap_pyfunction!(diff_json, m)?)?;
    m.add_function(wrap_pyfunction!(doc, m)?)?;
    m.add_function(wrap_pyfunction!(canopen::load_canopen, m)?)?;
    model::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
