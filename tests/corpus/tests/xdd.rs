//! The corpus XDD/XDC files (kind `xdd`): every one reads without a panic, at least 95% with
//! no error; XDD → model → XDD → model is equal and writing is deterministic.

#![allow(clippy::unwrap_used, clippy::panic)]

use odc_model::{Device, Format, Sources};
use odc_tests_corpus::{files, path};

fn read(file: &str) -> (Option<Device>, Vec<odc_model::Diagnostic>) {
    let bytes = std::fs::read(path(file)).unwrap();
    let p = odc_xdd::parse(&mut Sources::new(), file, &bytes);
    (p.device, p.diagnostics)
}

/// The model with what an XDD cannot hold or gives no place cleared, and spans-only
/// differences ignored (spans compare equal).
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
    assert!(clean * 100 >= list.len() * 95, "{clean}/{}:\n{report}", list.len());
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
