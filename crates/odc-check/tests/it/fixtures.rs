//! Device files read with `odc_eds::parse` (EDS/DCF) or `odc_esi::parse` (`.xml`): those under
//! `fixtures/pass` must give no diagnostic at all; those under `fixtures/fail` are snapshotted
//! in the human rendering.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

use std::path::Path;

use odc_check::{Config, check};
use odc_model::{Sources, diag};

fn render(path: &Path) -> (String, usize) {
    let bytes = std::fs::read(path).unwrap();
    let name = format!("{}", path.file_name().unwrap().to_string_lossy());
    let mut sources = Sources::new();
    let config = Config::in_registry(odc_check::rules());
    let mut diags = Vec::new();
    if name.ends_with(".xml") {
        let parsed = odc_esi::parse(&mut sources, &name, &bytes);
        let mut front_end = parsed.diagnostics;
        for device in &parsed.devices {
            diags.extend(config.apply(device, std::mem::take(&mut front_end)));
            diags.extend(check(device, &config));
        }
        diags.extend(front_end);
    } else {
        let parsed = odc_eds::parse(&mut sources, &name, &bytes);
        diags.extend(config.apply(&parsed.device, parsed.diagnostics));
        diags.extend(check(&parsed.device, &config));
    }
    diag::sort(&mut diags);
    (diag::render_human(&sources, &diags, false), diags.len())
}

fn fixtures(kind: &str) -> Vec<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(kind);
    let mut files: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    files
}

#[test]
fn pass_fixtures_are_clean() {
    for f in fixtures("pass") {
        let (out, n) = render(&f);
        assert_eq!(n, 0, "{}:\n{out}", f.display());
    }
}

#[test]
fn fail_fixtures() {
    for f in fixtures("fail") {
        let (out, n) = render(&f);
        assert!(n > 0, "{} trips nothing", f.display());
        let name = f.file_stem().unwrap().to_string_lossy().into_owned();
        insta::assert_snapshot!(name, out);
    }
}

/// An empty `LowLimit=`/`HighLimit=` on a string or domain is no limit (python-canopen
/// comparison, issue 14): no C208, whatever the type.
#[test]
fn empty_limits_of_strings_are_no_limits() {
    for dt in ["0x0009", "0x000A", "0x000B", "0x000F"] {
        let text = format!(
            "[2000]\nParameterName=s\nObjectType=0x7\nDataType={dt}\nAccessType=rw\nLowLimit=\nHighLimit=\n"
        );
        let mut sources = Sources::new();
        let parsed = odc_eds::parse(&mut sources, "t.eds", text.as_bytes());
        let diags = check(&parsed.device, &Config::in_registry(odc_check::rules()));
        assert!(!diags.iter().any(|d| d.code == "C208"), "{dt}: {diags:?}");
    }
}

/// A PDO entry that maps a PDO's own mapping object, which the ESI's dictionary lacks (as the
/// Somanet files of the corpus do): T601 names it; the mapping object odc synthesised for the
/// CoE device (`Origin::CoeImplied`) neither hides it nor trips T602 with its own 32 bits.
#[test]
fn synthesised_mapping_objects_are_not_the_files_dictionary() {
    let pass = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pass/coe_implied.xml");
    let xml = std::fs::read_to_string(pass).unwrap().replacen(
        "<Entry><Index>0</Index><BitLen>8</BitLen></Entry>",
        "<Entry><Index>#x1A00</Index><SubIndex>1</SubIndex><BitLen>8</BitLen></Entry>",
        1,
    );
    let parsed = odc_esi::parse(&mut Sources::new(), "t.xml", xml.as_bytes());
    let device = &parsed.devices[0];
    let origin = device.objects[&0x1A00].origin;
    assert_eq!(origin, odc_model::Origin::CoeImplied);
    let diags = check(device, &Config::in_registry(odc_check::rules()));
    let codes: Vec<&str> = diags.iter().map(|d| d.code).collect();
    assert_eq!(codes, ["T601"], "{diags:?}");
    assert!(diags[0].message.contains("0x1A00:01"), "{}", diags[0].message);
}

/// The file's own 0x1C13 with room for two PDOs and no assignment of its own: odc-esi starts
/// it with the PDOs the `Sm` attributes assign (note F231), but T608 still compares the
/// file's own words. Sub 0 written as 0: "assigns none", as before the filling; sub 0 without
/// a default: nothing to compare, no T608.
#[test]
fn filled_assignment_objects_are_checked_as_the_file_wrote_them() {
    let pass = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pass/coe_implied.xml");
    let base = std::fs::read_to_string(pass).unwrap();
    let types = r#"<DataType><Name>DT1C13</Name><BitSize>48</BitSize>
        <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize><BitOffs>0</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
        <SubItem><SubIdx>1</SubIdx><Name>SubIndex 001</Name><Type>UINT</Type><BitSize>16</BitSize><BitOffs>16</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
        <SubItem><SubIdx>2</SubIdx><Name>SubIndex 002</Name><Type>UINT</Type><BitSize>16</BitSize><BitOffs>32</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
      </DataType></DataTypes>"#;
    let codes = |info: &str| {
        let own = format!(
            "<Object><Index>#x1C13</Index><Name>TxPDO assign</Name><Type>DT1C13</Type>\
             <BitSize>48</BitSize>{info}</Object></Objects>"
        );
        let xml = base.replacen("</DataTypes>", types, 1).replacen("</Objects>", &own, 1);
        let parsed = odc_esi::parse(&mut Sources::new(), "t.xml", xml.as_bytes());
        let device = &parsed.devices[0];
        // The device starts with 0x1A00 and the mandatory 0x1A02.
        let s2 = device.objects[&0x1C13].sub(2).unwrap().default.as_ref().unwrap();
        assert_eq!(s2.value, odc_model::Value::Unsigned(0x1A02));
        let diags = check(device, &Config::in_registry(odc_check::rules()));
        let mut codes: Vec<&str> = parsed.diagnostics.iter().map(|d| d.code).collect();
        codes.extend(diags.iter().map(|d| d.code));
        (codes, diags)
    };
    let zero = "<Info><SubItem><Name>SubIndex 000</Name><Info><DefaultData>00</DefaultData>\
                </Info></SubItem></Info>";
    let (found, diags) = codes(zero);
    assert_eq!(found, ["F231", "T608"], "{diags:?}");
    assert!(diags[0].message.contains("0x1C13 assigns none to SM 3"), "{}", diags[0].message);
    let (found, diags) = codes("");
    assert_eq!(found, ["F231"], "{diags:?}");
}
