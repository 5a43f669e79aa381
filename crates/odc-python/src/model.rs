//! The checked model as Python sees it: read-only classes (`odc.Device`, `odc.Object`,
//! `odc.SubObject`, `odc.Pdo`, …) with plain Python values.
//!
//! Classes rather than dicts: attributes complete in an editor and a REPL, a misspelt field is
//! an `AttributeError` instead of a silent `None`, and `repr` names the object. They are
//! frozen: the model is what the file says, not a dictionary to edit (python-canopen's
//! objects, from `odc.canopen`, are the editable ones). Indexes are keys of plain dicts, so
//! `device.objects[0x1018].subs[1]` reads as the standard writes it.
//!
//! Values are Python's own: `int`, `float` (a REAL32 as its shortest decimal), `bool`, `str` (VISIBLE_STRING and
//! UNICODE_STRING), `bytes` (OCTET_STRING, DOMAIN), `(ms, days)` for TIME_OF_DAY and
//! TIME_DIFFERENCE; `$NODEID+n` stays symbolic as [`NodeIdPlus`] (odc's policy: resolved once a
//! node-ID is known), and text that is not a value of its type (allowed F107/F108) is
//! [`Invalid`].

use odc_model::{Diagnostic, Sources, Spanned, Value};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyTuple};

/// `$NODEID + offset`: a value that depends on the node-ID.
#[pyclass(frozen, get_all, eq, hash, module = "odc")]
#[derive(PartialEq, Eq, Hash)]
pub struct NodeIdPlus {
    /// What is added to the node-ID.
    offset: i64,
}

#[pymethods]
impl NodeIdPlus {
    #[new]
    fn new(offset: i64) -> Self {
        NodeIdPlus { offset }
    }

    /// The value for a node-ID.
    fn resolve(&self, node_id: i64) -> i64 {
        self.offset.saturating_add(node_id)
    }

    fn __repr__(&self) -> String {
        format!("NodeIdPlus(0x{:X})", self.offset)
    }
}

/// Text that does not read as a value of its type (kept as written; a diagnostic said so).
#[pyclass(frozen, get_all, eq, hash, module = "odc")]
#[derive(PartialEq, Eq, Hash)]
pub struct Invalid {
    /// The text as written.
    text: String,
}

#[pymethods]
impl Invalid {
    #[new]
    fn new(text: String) -> Self {
        Invalid { text }
    }

    fn __repr__(&self) -> String {
        format!("Invalid({:?})", self.text)
    }
}

/// A sub-object: the unit that has a type, an access and a value. A VAR is an object with one
/// sub-object at sub-index 0.
#[pyclass(frozen, get_all, module = "odc")]
pub struct SubObject {
    /// The object's index.
    index: u16,
    /// The sub-index.
    sub_index: u8,
    /// `ParameterName`.
    name: String,
    /// The CiA 301 data type code (0x0007 for UNSIGNED32).
    data_type: u16,
    /// Its name (`UNSIGNED32`).
    data_type_name: String,
    /// `ro`, `wo`, `rw`, `rwr`, `rww` or `const`.
    access: &'static str,
    /// Whether the file lets a PDO map it.
    pdo_mapping: bool,
    /// `DefaultValue`, or `None`.
    default: Py<PyAny>,
    /// The `DefaultValue` text as written, or `None` (absent, or implied by the file).
    default_raw: Option<String>,
    /// `LowLimit`, or `None`.
    low_limit: Py<PyAny>,
    /// `HighLimit`, or `None`.
    high_limit: Py<PyAny>,
    /// DCF `ParameterValue`, or `None`.
    parameter_value: Py<PyAny>,
    /// The `ParameterValue` text as written, or `None`.
    parameter_value_raw: Option<String>,
    /// The size in bits the file states (ESI `BitSize`), else that of the type; `None` for
    /// strings and domains.
    bit_size: Option<u32>,
    /// DCF `Denotation`, or `None`.
    denotation: Option<String>,
    /// The keys odc does not interpret (`Unit`, `Factor`, `Description`, `StorageLocation`,
    /// vendor keys), by their spelling in the file.
    extra: Py<PyDict>,
}

#[pymethods]
impl SubObject {
    fn __repr__(&self) -> String {
        format!(
            "<SubObject 0x{:04X}sub{} {:?} {} {}>",
            self.index, self.sub_index, self.name, self.data_type_name, self.access
        )
    }
}

/// An object of the dictionary.
#[pyclass(frozen, get_all, module = "odc")]
pub struct Object {
    /// The index.
    index: u16,
    /// `ParameterName`.
    name: String,
    /// `VAR`, `ARRAY`, `RECORD`, `DOMAIN`, `DEFTYPE`, `DEFSTRUCT` or `NULL`.
    kind: &'static str,
    /// The sub-objects by sub-index (a VAR has one, at 0).
    subs: Py<PyDict>,
    /// `CompactSubObj`, or `None`.
    compact_sub_obj: Option<u8>,
    /// `ObjFlags`, or `None`.
    obj_flags: Option<u32>,
    /// Whether the file writes the object out (`False` for objects implied by `CompactPDO` or
    /// made from an ESI's PDO entries).
    in_file: bool,
    /// The keys odc does not interpret, by their spelling in the file.
    extra: Py<PyDict>,
}

#[pymethods]
impl Object {
    /// The sub-object at `sub`.
    fn __getitem__(&self, py: Python<'_>, sub: u8) -> PyResult<Py<PyAny>> {
        match self.subs.bind(py).get_item(sub)? {
            Some(s) => Ok(s.unbind()),
            None => Err(pyo3::exceptions::PyKeyError::new_err(format!(
                "0x{:04X} has no sub-index {sub}",
                self.index
            ))),
        }
    }

    fn __repr__(&self) -> String {
        format!("<Object 0x{:04X} {:?} {}>", self.index, self.name, self.kind)
    }
}

/// One mapping entry of a PDO.
#[pyclass(frozen, get_all, module = "odc")]
pub struct PdoEntry {
    /// The mapped object's index (a data-type index for a dummy entry, 0 for an EtherCAT gap).
    index: u16,
    /// The mapped sub-index.
    sub: u8,
    /// The length in bits.
    bits: u16,
    /// The ESI entry's name, or `None`.
    name: Option<String>,
}

#[pymethods]
impl PdoEntry {
    fn __repr__(&self) -> String {
        format!("<PdoEntry 0x{:04X}sub{} {} bits>", self.index, self.sub, self.bits)
    }
}

/// A PDO of the default mapping.
#[pyclass(frozen, get_all, module = "odc")]
pub struct Pdo {
    /// `rx` (master to device) or `tx` (device to master).
    direction: &'static str,
    /// The mapping object (0x1600…, 0x1A00…).
    mapping_index: u16,
    /// The communication object (0x1400…, 0x1800…), or `None`.
    comm_index: Option<u16>,
    /// The name the file gives it.
    name: String,
    /// The COB-ID (an `int` or a `NodeIdPlus`), or `None`.
    cob_id: Py<PyAny>,
    /// Transmission type, or `None`.
    transmission_type: Option<u8>,
    /// Inhibit time in 100 µs, or `None`.
    inhibit_time: Option<u16>,
    /// Event timer in ms, or `None`.
    event_timer: Option<u16>,
    /// EtherCAT: the sync manager, or `None`.
    sync_manager: Option<u8>,
    /// The mapped entries in wire order.
    entries: Py<PyList>,
}

#[pymethods]
impl Pdo {
    fn __repr__(&self) -> String {
        format!("<Pdo {} 0x{:04X} {:?}>", self.direction, self.mapping_index, self.name)
    }
}

/// Who the device is and what it supports (`[DeviceInfo]`; an ESI's `<Type>` and `<Name>`).
#[pyclass(frozen, get_all, module = "odc")]
pub struct Identity {
    vendor_name: Option<String>,
    vendor_number: Option<u32>,
    product_name: Option<String>,
    product_number: Option<u32>,
    revision_number: Option<u32>,
    order_code: Option<String>,
    /// Supported bit rates in kbit/s, ascending.
    baud_rates: Vec<u32>,
    simple_boot_up_master: Option<bool>,
    simple_boot_up_slave: Option<bool>,
    granularity: Option<u8>,
    dynamic_channels_supported: Option<u8>,
    group_messaging: Option<bool>,
    nr_of_rx_pdo: Option<u16>,
    nr_of_tx_pdo: Option<u16>,
    lss_supported: Option<bool>,
}

#[pymethods]
impl Identity {
    fn __repr__(&self) -> String {
        format!(
            "<Identity vendor 0x{:08X} product 0x{:08X} revision 0x{:08X}>",
            self.vendor_number.unwrap_or(0),
            self.product_number.unwrap_or(0),
            self.revision_number.unwrap_or(0)
        )
    }
}

/// A device read and checked by odc.
#[pyclass(frozen, get_all, module = "odc")]
pub struct Device {
    /// `eds`, `dcf`, `esi`, `xdd` or `xdc`.
    format: Option<&'static str>,
    /// Identity and capabilities.
    identity: Py<Identity>,
    /// The objects by index, in index order.
    objects: Py<PyDict>,
    /// The PDOs of the default mapping.
    pdos: Py<PyList>,
    /// The data types `[DummyUsage]` lets a PDO map as gap fillers.
    dummy_usage: Vec<u16>,
    /// `[Comments]` lines.
    comments: Vec<String>,
    /// DCF `[DeviceComissioning]` `NodeID`, or `None`.
    node_id: Option<u8>,
    /// DCF `[DeviceComissioning]` `Baudrate` in kbit/s, or `None`.
    baud_rate: Option<u32>,
    /// The diagnostics below error level (dicts, as `odc.check` gives them).
    diagnostics: Py<PyList>,
}

#[pymethods]
impl Device {
    /// The object at `index`.
    fn __getitem__(&self, py: Python<'_>, index: u16) -> PyResult<Py<PyAny>> {
        match self.objects.bind(py).get_item(index)? {
            Some(o) => Ok(o.unbind()),
            None => Err(pyo3::exceptions::PyKeyError::new_err(format!("no object 0x{index:04X}"))),
        }
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let name = self.identity.get().product_name.clone().unwrap_or_default();
        format!("<Device {:?}: {} objects>", name, self.objects.bind(py).len())
    }
}

/// A value as Python's own.
pub(crate) fn value(py: Python<'_>, v: &Value) -> PyResult<Py<PyAny>> {
    Ok(match v {
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any().unbind(),
        Value::Unsigned(u) => u.into_pyobject(py)?.into_any().unbind(),
        Value::Signed(i) => i.into_pyobject(py)?.into_any().unbind(),
        Value::Real32(bits) => real32(f32::from_bits(*bits)).into_pyobject(py)?.into_any().unbind(),
        Value::Real64(bits) => f64::from_bits(*bits).into_pyobject(py)?.into_any().unbind(),
        Value::Text(t) => t.as_ref().into_pyobject(py)?.into_any().unbind(),
        Value::Bytes(b) => PyBytes::new(py, b).into_any().unbind(),
        Value::Unicode(units) => {
            String::from_utf16_lossy(units).into_pyobject(py)?.into_any().unbind()
        }
        Value::Time { ms, days } => {
            PyTuple::new(py, [u64::from(*ms), u64::from(*days)])?.into_any().unbind()
        }
        Value::NodeIdPlus(n) => Py::new(py, NodeIdPlus { offset: *n })?.into_any(),
        Value::Invalid(t) => Py::new(py, Invalid { text: t.to_string() })?.into_any(),
    })
}

/// A REAL32 as the Python float of its shortest decimal (`1.2`, not `1.2000000476837158`):
/// the float a Python user would write for it, and the same REAL32 when packed back.
fn real32(x: f32) -> f64 {
    // Rust's `Display` of an f32 is the shortest decimal that reads back as the same f32;
    // `inf`, `-inf` and `NaN` parse as f64 too. A failure cannot happen; the widened value
    // stands in for it.
    x.to_string().parse().unwrap_or(f64::from(x))
}

fn opt_value(py: Python<'_>, v: Option<&Spanned<Value>>) -> PyResult<Py<PyAny>> {
    match v {
        Some(v) => value(py, &v.value),
        None => Ok(py.None()),
    }
}

/// The text a value was read from, when it has a place of its own in the file (not a value a
/// `CompactSubObj` or `[xxxxName]` section implied, whose span is the line that implied it).
pub(crate) fn raw(sources: &Sources, v: Option<&Spanned<Value>>) -> Option<String> {
    let span = v?.span;
    if span.is_dummy() {
        return None;
    }
    let text = sources.text(span.file)?.get(span.range())?;
    // A value's span covers the value; a longer one (a section header, a whole line) is the
    // place that implied it.
    (!text.contains('=') && !text.starts_with('[')).then(|| text.to_owned())
}

fn extra<'py>(py: Python<'py>, entries: &[odc_model::RawEntry]) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    for e in entries {
        dict.set_item(&e.key, &e.value)?;
    }
    Ok(dict)
}

/// `object_extra`: the keys of a VAR's section, which are its one sub-object's.
fn sub(
    py: Python<'_>,
    index: u16,
    s: &odc_model::SubObject,
    sources: &Sources,
    object_extra: &[odc_model::RawEntry],
) -> PyResult<SubObject> {
    let rare = s.rare();
    let extra = extra(py, &rare.extra)?;
    for e in object_extra {
        extra.set_item(&e.key, &e.value)?;
    }
    Ok(SubObject {
        index,
        sub_index: s.sub_index,
        name: s.name.to_string(),
        data_type: s.data_type.code(),
        data_type_name: s.data_type.name().into_owned(),
        access: s.access.as_str(),
        pdo_mapping: s.pdo_mapping.is_mappable(),
        default: opt_value(py, s.default.as_ref())?,
        default_raw: raw(sources, s.default.as_ref()),
        low_limit: opt_value(py, s.low_limit.as_deref())?,
        high_limit: opt_value(py, s.high_limit.as_deref())?,
        parameter_value: opt_value(py, s.parameter_value.as_ref())?,
        parameter_value_raw: raw(sources, s.parameter_value.as_ref()),
        bit_size: s.bit_size.or_else(|| s.data_type.bit_size()),
        denotation: rare.denotation.as_ref().map(|d| d.value.clone()),
        extra: extra.unbind(),
    })
}

fn object(py: Python<'_>, o: &odc_model::Object, sources: &Sources) -> PyResult<Object> {
    let subs = PyDict::new(py);
    let var_extra: &[odc_model::RawEntry] = if o.kind.has_subs() { &[] } else { &o.extra };
    for (i, s) in o.subs.iter() {
        subs.set_item(i, Py::new(py, sub(py, o.index, s, sources, var_extra)?)?)?;
    }
    Ok(Object {
        index: o.index,
        name: o.name.clone(),
        kind: o.kind.name(),
        subs: subs.unbind(),
        compact_sub_obj: o.compact_sub_obj.as_ref().map(|c| c.value),
        obj_flags: o.obj_flags.as_ref().map(|f| f.value),
        in_file: o.origin == odc_model::Origin::File,
        extra: extra(py, &o.extra)?.unbind(),
    })
}

fn pdo(py: Python<'_>, p: &odc_model::Pdo) -> PyResult<Pdo> {
    let entries = PyList::empty(py);
    for e in &p.entries {
        let entry = PdoEntry { index: e.index, sub: e.sub, bits: e.bits, name: e.name.clone() };
        entries.append(Py::new(py, entry)?)?;
    }
    Ok(Pdo {
        direction: match p.direction {
            odc_model::Direction::Rx => "rx",
            odc_model::Direction::Tx => "tx",
        },
        mapping_index: p.mapping_index,
        comm_index: p.comm_index,
        name: p.name.clone(),
        cob_id: match &p.cob_id {
            Some(v) => value(py, v)?,
            None => py.None(),
        },
        transmission_type: p.transmission_type,
        inhibit_time: p.inhibit_time,
        event_timer: p.event_timer,
        sync_manager: p.sync_manager,
        entries: entries.unbind(),
    })
}

fn identity(info: &odc_model::DeviceInfo) -> Identity {
    fn v<T: Clone>(s: &Option<Spanned<T>>) -> Option<T> {
        s.as_ref().map(|s| s.value.clone())
    }
    Identity {
        vendor_name: v(&info.vendor_name),
        vendor_number: v(&info.vendor_number),
        product_name: v(&info.product_name),
        product_number: v(&info.product_number),
        revision_number: v(&info.revision_number),
        order_code: v(&info.order_code),
        baud_rates: info.baud_rates.clone(),
        simple_boot_up_master: v(&info.simple_boot_up_master),
        simple_boot_up_slave: v(&info.simple_boot_up_slave),
        granularity: v(&info.granularity),
        dynamic_channels_supported: v(&info.dynamic_channels_supported),
        group_messaging: v(&info.group_messaging),
        nr_of_rx_pdo: v(&info.nr_of_rx_pdo),
        nr_of_tx_pdo: v(&info.nr_of_tx_pdo),
        lss_supported: v(&info.lss_supported),
    }
}

/// The Python model of a loaded device; `diagnostics` are the file's (below error level, as
/// it passed the gate). Without `with_objects` its `objects` are left empty (`odc.canopen`
/// makes its own from the model, see `canopen.rs`).
pub fn device(
    py: Python<'_>,
    d: &odc_model::Device,
    sources: &Sources,
    diagnostics: &[Diagnostic],
    with_objects: bool,
) -> PyResult<Py<Device>> {
    let objects = PyDict::new(py);
    for (i, o) in d.objects.iter().filter(|_| with_objects) {
        objects.set_item(i, Py::new(py, object(py, o, sources)?)?)?;
    }
    let pdos = PyList::empty(py);
    for p in &d.pdos {
        pdos.append(Py::new(py, pdo(py, p)?)?)?;
    }
    let commissioning = d.commissioning.as_ref();
    let device = Device {
        format: d.format.map(|f| match f {
            odc_model::Format::Eds => "eds",
            odc_model::Format::Dcf => "dcf",
            odc_model::Format::Esi => "esi",
            odc_model::Format::Xdd => "xdd",
            odc_model::Format::Xdc => "xdc",
        }),
        identity: Py::new(py, identity(&d.device_info))?,
        objects: objects.unbind(),
        pdos: pdos.unbind(),
        dummy_usage: d.dummy_usage.iter().filter(|(_, on)| on.value).map(|(i, _)| *i).collect(),
        comments: d.comments.clone(),
        node_id: commissioning.and_then(|c| c.node_id.as_ref()).map(|n| n.value),
        baud_rate: commissioning.and_then(|c| c.baudrate.as_ref()).map(|b| b.value),
        diagnostics: crate::diagnostics_list(py, sources, diagnostics)?.unbind(),
    };
    Py::new(py, device)
}

/// Adds the classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Device>()?;
    m.add_class::<Identity>()?;
    m.add_class::<Object>()?;
    m.add_class::<SubObject>()?;
    m.add_class::<Pdo>()?;
    m.add_class::<PdoEntry>()?;
    m.add_class::<NodeIdPlus>()?;
    m.add_class::<Invalid>()?;
    Ok(())
}
