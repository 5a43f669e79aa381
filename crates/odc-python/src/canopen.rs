//! What `odc.canopen.import_od` needs to make python-canopen's objects: per object its index,
//! kind, name and storage location, and its python-canopen `ODVariable`s, made here with the
//! attributes python-canopen's importer gives them.
//!
//! Made here rather than from `odc.load`'s classes in Python: a `SubObject` and then an
//! `ODVariable` set attribute by attribute in Python was most of the import's time
//! (BENCHMARKS.md, "In Python").

use std::path::PathBuf;

use odc_model::{Sources, Spanned, Value};
use odc_pipeline::Options;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::model;

/// A value as python-canopen holds it: `$NODEID+n` resolved with the node-ID (`None` without
/// one), a value that did not read `None`, TIME_OF_DAY and TIME_DIFFERENCE as the 48-bit integer
/// of their wire form (milliseconds, then days above bit 32).
fn value(py: Python<'_>, v: &Value, node_id: Option<i64>) -> PyResult<Py<PyAny>> {
    match v {
        Value::NodeIdPlus(n) => match node_id {
            Some(id) => Ok(n.saturating_add(id).into_pyobject(py)?.into_any().unbind()),
            None => Ok(py.None()),
        },
        Value::Invalid(_) => Ok(py.None()),
        Value::Time { ms, days } => {
            let wire = u64::from(*ms) | (u64::from(*days) << 32);
            Ok(wire.into_pyobject(py)?.into_any().unbind())
        }
        other => model::value(py, other),
    }
}

/// The text of a value the file implies without writing it (a `CompactSubObj` member's), as
/// python-canopen would write it back.
fn implied_raw(v: &Value) -> String {
    match v {
        Value::NodeIdPlus(n) if *n < 0 => format!("$NODEID-0x{:X}", n.unsigned_abs()),
        Value::NodeIdPlus(n) => format!("$NODEID+0x{n:X}"),
        Value::Invalid(t) | Value::Text(t) => t.to_string(),
        Value::Bytes(b) => b.iter().map(|x| format!("{x:02X}")).collect(),
        Value::Bool(b) => u8::from(*b).to_string(),
        Value::Unsigned(u) => format!("0x{u:X}"),
        Value::Signed(i) if *i >= 0 => format!("0x{i:X}"),
        Value::Signed(i) => i.to_string(),
        Value::Real32(bits) => format!("{:?}", f32::from_bits(*bits)),
        Value::Real64(bits) => format!("{:?}", f64::from_bits(*bits)),
        Value::Unicode(units) => String::from_utf16_lossy(units),
        Value::Time { ms, days } => (u64::from(*ms) | (u64::from(*days) << 32)).to_string(),
    }
}

/// The key's value among a section's uninterpreted keys, its last if repeated (keys read
/// case-insensitively, odc's policy).
fn key<'e>(extra: &'e [odc_model::RawEntry], name: &str) -> Option<&'e str> {
    extra.iter().rev().find(|e| e.key.eq_ignore_ascii_case(name)).map(|e| e.value.as_str())
}

/// How a python-canopen `ODVariable` is made without its `__init__`: `object.__new__(cls)`,
/// then as `__dict__` a copy of `template` (a fresh variable's scalar attributes) with a new
/// empty container for each of `containers` (`value_descriptions`, `bit_definitions`, …) and
/// the file's values.
struct Maker<'py> {
    template: Bound<'py, PyDict>,
    containers: Vec<(Bound<'py, PyAny>, Bound<'py, PyAny>)>,
    cls: Bound<'py, PyAny>,
    new: Bound<'py, PyAny>,
}

impl<'py> Maker<'py> {
    fn make(&self, attrs: Bound<'py, PyDict>) -> PyResult<Bound<'py, PyAny>> {
        for (key, kind) in &self.containers {
            attrs.set_item(key, kind.call0()?)?;
        }
        let var = self.new.call1((&self.cls,))?;
        var.setattr(intern!(attrs.py(), "__dict__"), attrs)?;
        Ok(var)
    }
}

/// The attributes of one `ODVariable` (keys interned: made once, not once a variable).
#[allow(clippy::too_many_arguments)] // the parts of a variable, each from its own place
fn variable<'py>(
    py: Python<'py>,
    name: &str,
    index: u16,
    s: &odc_model::SubObject,
    extra: &[odc_model::RawEntry],
    sources: &Sources,
    node_id: Option<i64>,
    template: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = template.copy()?;
    d.set_item(intern!(py, "name"), name)?;
    d.set_item(intern!(py, "index"), index)?;
    d.set_item(intern!(py, "subindex"), s.sub_index)?;
    d.set_item(intern!(py, "data_type"), s.data_type.code())?;
    d.set_item(intern!(py, "access_type"), s.access.as_str())?;
    d.set_item(intern!(py, "pdo_mappable"), s.pdo_mapping.is_mappable())?;
    d.set_item(intern!(py, "storage_location"), key(extra, "StorageLocation"))?;
    if let Some(low) = s.low_limit.as_deref() {
        d.set_item(intern!(py, "min"), value(py, &low.value, node_id)?)?;
    }
    if let Some(high) = s.high_limit.as_deref() {
        d.set_item(intern!(py, "max"), value(py, &high.value, node_id)?)?;
    }
    let put = |v: &Spanned<Value>, raw_key, key| -> PyResult<()> {
        let raw = model::raw(sources, Some(v)).unwrap_or_else(|| implied_raw(&v.value));
        d.set_item(raw_key, raw)?;
        d.set_item(key, value(py, &v.value, node_id)?)
    };
    if let Some(default) = &s.default {
        put(default, intern!(py, "default_raw"), intern!(py, "default"))?;
        d.set_item(intern!(py, "relative"), default.value.is_node_relative())?;
    }
    if let Some(parameter) = &s.parameter_value {
        put(parameter, intern!(py, "value_raw"), intern!(py, "value"))?;
    }
    if let Some(factor) = key(extra, "Factor").and_then(|f| f.trim().parse::<f64>().ok()) {
        d.set_item(intern!(py, "factor"), factor)?;
    }
    if let Some(description) = key(extra, "Description") {
        d.set_item(intern!(py, "description"), description)?;
    }
    if let Some(unit) = key(extra, "Unit") {
        d.set_item(intern!(py, "unit"), unit)?;
    }
    Ok(d)
}

/// Reads and checks a device file for `odc.canopen`: `(device, objects, node_id)`, where
/// `device` is an `odc.Device` without objects, `objects` a list of `(index, kind, name,
/// storage_location, [variable])` and `node_id` the one values were resolved with (the
/// argument, else a DCF's commissioning NodeID, else `None`). The variables are `cls`
/// (python-canopen's `ODVariable`) made by `new` (`object.__new__`) with a copy of `template`
/// and new `containers` (`(name, type)` pairs) as their attributes, then the file's.
#[pyfunction]
#[pyo3(signature = (path, *, node_id=None, allow=Vec::new(), warn=Vec::new(), deny=Vec::new(), strict=false, data=None, template, containers, cls, new))]
pub fn load_canopen<'py>(
    py: Python<'py>,
    path: PathBuf,
    node_id: Option<i64>,
    allow: Vec<String>,
    warn: Vec<String>,
    deny: Vec<String>,
    strict: bool,
    data: Option<Vec<u8>>,
    template: Bound<'py, PyDict>,
    containers: Vec<(Bound<'py, PyAny>, Bound<'py, PyAny>)>,
    cls: Bound<'py, PyAny>,
    new: Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyTuple>> {
    let maker = Maker { template, containers, cls, new };
    let rules = crate::rules(allow, warn, deny, strict, None, None);
    let mut base = Options::new();
    base.source_hash = false;
    let loaded = py.detach(|| crate::load_file(&path, data, &rules, base))?;
    crate::gate(py, &loaded)?;
    let dev = crate::one_device(&loaded)?;
    let sources = &loaded.sources;
    let node_id = node_id.or_else(|| {
        dev.commissioning.as_ref().and_then(|c| c.node_id.as_ref()).map(|n| i64::from(n.value))
    });
    let objects = PyList::empty(py);
    for (index, o) in &dev.objects {
        let members = PyList::empty(py);
        if o.kind.has_subs() {
            for (_, s) in o.subs.iter() {
                let rare = s.rare();
                let attrs = variable(
                    py,
                    &s.name,
                    *index,
                    s,
                    &rare.extra,
                    sources,
                    node_id,
                    &maker.template,
                )?;
                members.append(maker.make(attrs)?)?;
            }
        } else if let Some(s) = o.subs.get(&0) {
            // A VAR's keys are in its object's section.
            let attrs =
                variable(py, &o.name, *index, s, &o.extra, sources, node_id, &maker.template)?;
            members.append(maker.make(attrs)?)?;
        }
        let storage = key(&o.extra, "StorageLocation");
        objects.append((*index, o.kind.name(), &o.name, storage, members))?;
    }
    let device = model::device(py, dev, sources, &loaded.diagnostics, false)?;
    PyTuple::new(
        py,
        [
            device.into_any(),
            objects.into_any().unbind(),
            node_id.into_pyobject(py)?.into_any().unbind(),
        ],
    )
}
