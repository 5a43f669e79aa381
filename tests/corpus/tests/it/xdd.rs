//! The corpus XDD/XDC files (kind `xdd`): every one reads without a panic and with no error; XDD → model → XDD → model is equal and writing is deterministic.

#![allow(clippy::unwrap_used, clippy::panic)]

use odc_model::{Device, Format, Sources};
use odc_tests_corpus::{files, path};

fn read(file: &str) -> (Option<Device>, Vec<odc_model::Diagnostic>) {
    let bytes = std::fs::read(path(file)).unwrap();
    let p = odc_xdd::parse(&mut Sources::new(), file, &bytes);
    (p.device, p.diagnostics)
}

/// The corpus XDD files an old CANopenEditor wrote without the data type of their CiA 301
/// ARRAY objects (`dataType` absent on the object, `dataType="0000"` on the sub-objects, no
/// type in the parameters): read with the standard's element types and a warning (F323).
const ILL_TYPED: [&str; 2] =
    ["eds/psas-oresat__app_battery_v1-app.xdd", "eds/psas-oresat__app_template-app.xdd"];

/// Writes `dev` as XDD (XDC for an XDC) twice, asserts the bytes are the same, and reads the
/// text back.
fn xdd_again(dev: &Device) -> (Device, String) {
    let format = dev.format.unwrap_or(Format::Xdd);
    let w = odc_xdd::write(dev, format);
    let again = odc_xdd::write(dev, format);
    assert_eq!(w.text, again.text, "writing twice gives other bytes");
    let p = odc_xdd::parse(&mut Sources::new(), "again.xdd", w.text.as_bytes());
    let errors: Vec<_> = p.diagnostics.iter().filter(|d| d.is_error()).collect();
    assert!(p.device.is_some(), "the written XDD does not read: {errors:?}");
    (p.device.unwrap(), w.text)
}

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn every_xdd_reads_and_round_trips() {
    let list = files(&["xdd"]);
    assert_eq!(list.len(), 26, "the manifest's xdd files");
    let mut clean = 0;
    let mut report = String::new();
    for f in &list {
        let (dev, diags) = read(f);
        let errors: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
        if errors.is_empty() {
            clean += 1;
        } else {
            report.push_str(&format!(
                "{f}: {} error(s), first {} {}\n",
                errors.len(),
                errors[0].code,
                errors[0].message
            ));
        }
        let standard_types =
            diags.iter().filter(|d| d.code == odc_xdd::codes::STANDARD_DATA_TYPE).count();
        assert_eq!(
            standard_types > 0,
            ILL_TYPED.contains(&f.as_str()),
            "{f}: F323 × {standard_types}"
        );
        let dev = dev.unwrap_or_else(|| panic!("{f}: no device: {diags:?}"));
        assert!(!dev.objects.is_empty(), "{f}: no objects");
        let (again, _) = xdd_again(&dev);
        let mut want = dev.clone();
        want.format = again.format; // an XDD without values reads back as XDD
        if let Some(field) = first_difference(&want, &again) {
            panic!("{f}: XDD -> model -> XDD -> model differs in {field}");
        }
    }
    eprintln!("{clean}/{} read with no error\n{report}", list.len());
    assert_eq!(clean, list.len(), "{report}");
}

/// The first part of two models that differs, named (Debug output of the whole model is
/// megabytes).
pub fn first_difference(a: &Device, b: &Device) -> Option<String> {
    for (i, o) in &a.objects {
        match b.objects.get(i) {
            None => return Some(format!("object {i:04X}: missing")),
            Some(p) if p != o => {
                for (s, x) in o.subs.iter() {
                    if p.subs.get(s) != Some(x) {
                        return Some(format!(
                            "object {i:04X} sub {s}:\n{x:?}\n{:?}",
                            p.subs.get(s)
                        ));
                    }
                }
                return Some(format!("object {i:04X}:\n{:?}\n{:?}", o.extra, p.extra));
            }
            _ => {}
        }
    }
    let fields: [(&str, bool); 13] = [
        ("format", a.format == b.format),
        ("file_info", a.file_info == b.file_info),
        ("device_info", a.device_info == b.device_info),
        ("dummy_usage", a.dummy_usage == b.dummy_usage),
        ("comments", a.comments == b.comments),
        ("object_lists", a.object_lists == b.object_lists),
        ("objects", a.objects == b.objects),
        ("modules", a.modules == b.modules),
        ("commissioning", a.commissioning == b.commissioning),
        ("pdos", a.pdos == b.pdos),
        ("ethercat", a.ethercat == b.ethercat),
        ("extra_sections", a.extra_sections == b.extra_sections),
        ("xml_extra", a.xml_extra == b.xml_extra),
    ];
    fields.iter().find(|(_, eq)| !eq).map(|(n, _)| match *n {
        "device_info" => format!("device_info:\n{:?}\n{:?}", a.device_info, b.device_info),
        "file_info" => format!("file_info:\n{:?}\n{:?}", a.file_info, b.file_info),
        "commissioning" => format!("commissioning:\n{:?}\n{:?}", a.commissioning, b.commissioning),
        "xml_extra" => format!("xml_extra:\n{:?}\n{:?}", a.xml_extra, b.xml_extra),
        n => n.to_string(),
    })
}

/// What an XDD has no place for (each named in `odc_xdd::Written::lost`), cleared, so that the
/// rest can be compared: identity and file data CiA 311 lacks, EDS structure (object lists,
/// comments, CompactPDO, CompactSubObj, object links, modules, unknown sections), and the
/// format itself.
fn without_eds_only(mut d: Device) -> Device {
    d.format = None;
    d.file_info.file_revision = None;
    d.file_info.eds_version = None;
    d.file_info.extra.retain(|e| e.key == "fileVersion");
    d.device_info.revision_number = None;
    d.device_info.compact_pdo = None;
    d.device_info.extra.clear();
    d.comments.clear();
    d.object_lists = Default::default();
    d.modules = Default::default();
    d.extra_sections.clear();
    if let Some(c) = &mut d.commissioning {
        c.lss_serial_number = None;
        c.node_refd = None;
        c.net_refd = None;
    }
    for o in d.objects.values_mut() {
        o.links.clear();
        o.compact_sub_obj = None;
        o.origin = odc_model::Origin::File;
        if o.denotation.as_ref().is_some_and(|d| d.value.is_empty()) {
            o.denotation = None;
        }
        for s in o.subs.values_mut() {
            // `denotation=""` and `actualValue=""` are absent in an XDD: CANopenEditor writes
            // them on every object.
            let empty = |v: &odc_model::Value| match v {
                odc_model::Value::Text(t) => t.is_empty(),
                odc_model::Value::Bytes(b) => b.is_empty(),
                odc_model::Value::Unicode(u) => u.is_empty(),
                _ => false,
            };
            if s.parameter_value.as_ref().is_some_and(|v| empty(&v.value)) {
                s.parameter_value = None;
            }
            if s.rare().denotation.as_ref().is_some_and(|d| d.value.is_empty()) {
                s.rare_mut().denotation = None;
            }
            if s.rare().upload_file.is_some() || s.rare().download_file.is_some() {
                s.rare_mut().upload_file = None;
                s.rare_mut().download_file = None;
            }
        }
    }
    d.pdos = odc_model::pdo::resolve_canopen_pdos(&d);
    d
}

/// The EDS/DCF files of the corpus and of `eds/`.
fn eds_inputs() -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = files(&["eds", "dcf"]).iter().map(|f| path(f)).collect();
    let shipped = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds");
    for e in std::fs::read_dir(shipped).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "eds" || x == "dcf") {
            v.push(p);
        }
    }
    v
}

/// EDS → XDD → EDS: the model read back equals the first but for what an XDD cannot hold
/// (the writer names each), and the XDD is written deterministically.
#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn every_eds_round_trips_through_xdd() {
    let inputs = eds_inputs();
    let mut read = 0;
    let mut failures = Vec::new();
    for p in &inputs {
        let bytes = std::fs::read(p).unwrap();
        let name = p.display().to_string();
        let first = odc_eds::parse(&mut Sources::new(), &name, &bytes);
        if first.diagnostics.iter().any(|d| d.code == odc_eds::codes::SIZE_LIMIT) {
            continue;
        }
        read += 1;
        let eds_format = first.device.format.unwrap_or(Format::Eds);
        let xml_format = if eds_format == Format::Dcf { Format::Xdc } else { Format::Xdd };
        let (xdd_model, _) =
            xdd_again(&Device { format: Some(xml_format), ..first.device.clone() });
        let text = odc_eds::write(&xdd_model, eds_format);
        let back = odc_eds::parse(&mut Sources::new(), "back.eds", text.as_bytes()).device;
        let (a, b) = (without_eds_only(first.device), without_eds_only(back));
        if let Some(field) = first_difference(&a, &b) {
            failures
                .push(format!("{name}: {}", field.lines().take(3).collect::<Vec<_>>().join(" | ")));
        }
    }
    eprintln!("{read} EDS/DCF files read, {} differ after EDS -> XDD -> EDS", failures.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
