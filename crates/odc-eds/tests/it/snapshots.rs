//! Snapshots of the IR of every fixture, of the diagnostics of the invalid files, and the
//! round trip of every fixture.

use odc_model::{Format, Sources};

fn read(path: &std::path::Path) -> (Sources, odc_eds::Parsed, String) {
    let bytes = std::fs::read(path).unwrap_or_default();
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut sources = Sources::new();
    let parsed = odc_eds::parse(&mut sources, &name, &bytes);
    (sources, parsed, name)
}

fn round_trip(name: &str, dev: &odc_model::Device) {
    let format = dev.format.unwrap_or(Format::Eds);
    let text = odc_eds::write(dev, format);
    let mut sources = Sources::new();
    let again = odc_eds::parse(&mut sources, name, text.as_bytes());
    assert_eq!(&again.device, dev, "{name}: round trip changed the model\n{text}");
    assert_eq!(odc_eds::write(&again.device, format), text, "{name}: writer not stable");
}

#[test]
fn fixtures() {
    insta::glob!("..", "fixtures/*", |path| {
        let (sources, parsed, name) = read(path);
        let diags = odc_model::diag::render_short(&sources, &parsed.diagnostics);
        insta::assert_yaml_snapshot!(parsed.device);
        insta::assert_snapshot!(format!("{name} diagnostics"), diags);
        round_trip(&name, &parsed.device);
    });
}

#[test]
fn invalid() {
    insta::glob!("..", "invalid/*", |path| {
        let (sources, parsed, name) = read(path);
        let human = odc_model::diag::render_human(&sources, &parsed.diagnostics, false);
        let short = odc_model::diag::render_short(&sources, &parsed.diagnostics);
        insta::assert_snapshot!(format!("{short}\n{human}"));
        round_trip(&name, &parsed.device);
    });
}

#[test]
fn windows_1252_and_bom() {
    let mut sources = Sources::new();
    let p = odc_eds::parse(
        &mut sources,
        "a.eds",
        b"[1000]\r\nParameterName=Gr\xfc\xdfe \x80\r\nDataType=7\r\nAccessType=ro",
    );
    let name = &p.device.objects[&0x1000].name;
    assert_eq!(name, "Grüße €");
    assert_eq!(p.diagnostics[0].code, "F125");
    let p = odc_eds::parse(
        &mut sources,
        "b.eds",
        b"\xEF\xBB\xBF[1000]\nParameterName=x\nDataType=7\nAccessType=ro\n",
    );
    assert!(p.diagnostics.is_empty(), "{:?}", p.diagnostics);
    assert_eq!(p.device.format, Some(Format::Eds));
}

#[test]
fn rules_are_documented_and_unique() {
    let mut codes: Vec<_> = odc_eds::RULES.iter().map(|r| r.code).collect();
    codes.sort_unstable();
    let n = codes.len();
    codes.dedup();
    assert_eq!(codes.len(), n);
    assert!(odc_eds::RULES.iter().all(|r| r.group == "format" && r.explanation.len() > 80));
}
