//! Snapshot tests over `tests/fixtures/*.xml`: the lowered devices of every valid fixture, and
//! the rendered diagnostics of the `invalid_*` ones.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc_model::{Sources, diag};

#[test]
fn fixtures() {
    insta::glob!("..", "fixtures/*.xml", |path| {
        let bytes = std::fs::read(path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let mut sources = Sources::new();
        let parsed = odc_esi::parse(&mut sources, &name, &bytes);
        // Bytes by value (decoded in place) give the same result.
        let by_value = odc_esi::parse_vec(&mut Sources::new(), &name, bytes.clone());
        assert_eq!(by_value.devices, parsed.devices, "{name}");
        assert_eq!(by_value.diagnostics, parsed.diagnostics, "{name}");
        if name.starts_with("invalid_") {
            assert!(parsed.diagnostics.iter().any(|d| d.is_error()), "{name}: no error");
            let short = diag::render_short(&sources, &parsed.diagnostics);
            let human = diag::render_human(&sources, &parsed.diagnostics, false);
            insta::assert_snapshot!(format!("{short}\n{human}"));
        } else {
            let short = diag::render_short(&sources, &parsed.diagnostics);
            assert!(!parsed.diagnostics.iter().any(|d| d.is_error()), "{name}:\n{short}");
            insta::assert_yaml_snapshot!(parsed.devices);
        }
    });
}

#[test]
fn english_name_preferred_and_identity() {
    let mut sources = Sources::new();
    let bytes =
        std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/minimal.xml")).unwrap();
    let p = odc_esi::parse(&mut sources, "minimal.xml", &bytes);
    let d = &p.devices[0];
    assert_eq!(
        d.device_info.product_name.as_deref().map(String::as_str),
        Some("EX1000 8 channel input")
    );
    assert_eq!(d.device_info.vendor_name.as_deref().map(String::as_str), Some("Example GmbH"));
    assert_eq!(d.device_info.vendor_number.as_deref(), Some(&0x999));
    assert_eq!(d.device_info.product_number.as_deref(), Some(&0x0001_0001));
    assert_eq!(d.device_info.revision_number.as_deref(), Some(&0x0002_0000));
    assert_eq!(d.device_info.order_code.as_deref().map(String::as_str), Some("EX1000"));
    // Spans point at the text.
    let span = d.device_info.order_code.as_ref().unwrap().span;
    assert_eq!(&sources.text(p.file).unwrap()[span.range()], "EX1000");
    let ec = d.ethercat.as_ref().unwrap();
    assert_eq!(ec.raw.len(), 2);
    assert_eq!(ec.raw[0].path, "Vendor/URL");
    assert!(ec.raw[1].xml.starts_with("<Info>") && ec.raw[1].xml.ends_with("</Info>"));
}
