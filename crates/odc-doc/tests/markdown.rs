//! The Markdown sheet of every device file in `eds/` (snapshots, reviewed).
#![allow(clippy::unwrap_used)]

mod common;

#[test]
fn markdown_of_the_shipped_eds_files() {
    for name in ["lxm23a", "lexium-mdrive", "servoone", "lenze-e94aycca", "linmot-e1200"] {
        let loaded = common::load(&format!("eds/{name}.eds"));
        assert_eq!(loaded.devices.len(), 1);
        let md = odc_doc::markdown::markdown(&common::sheet(&loaded));
        // Deterministic: the same device gives the same bytes.
        assert_eq!(
            md,
            odc_doc::markdown::markdown(&common::sheet(&common::load(&format!("eds/{name}.eds"))))
        );
        insta::assert_snapshot!(name, md);
    }
}

/// A CoE device whose ESI dictionary leaves out 0x1C00, 0x1C12/0x1C13 and the mapping objects
/// (odc-esi's fixture): the sheet marks the objects odc synthesised (†) and explains the mark
/// under the table; the file's own objects carry none. The file's own 0x1C13 without a
/// default, which odc starts with the ESI's assignment: marked ‡.
#[test]
fn objects_odc_made_are_marked() {
    let loaded = common::load("crates/odc-esi/tests/fixtures/coe_implied.xml");
    let md = odc_doc::markdown::markdown(&common::sheet(&loaded));
    let row = |index: &str| {
        let at = format!("</a>{index}");
        md.lines().find(|l| l.contains(&at)).unwrap_or_else(|| panic!("no row {index}")).to_owned()
    };
    assert!(row("1C12").contains("</a>1C12† |"), "{}", row("1C12"));
    assert!(row("1A01").contains("</a>1A01† |"), "{}", row("1A01"));
    assert!(row("1000").contains("</a>1000 |"), "{}", row("1000"));
    assert!(row("6000").contains("</a>6000 |"), "{}", row("6000"));
    assert!(md.contains("\n† not in the file: odc synthesised it"), "no legend");
    assert!(!md.contains("\n‡ "), "no filled defaults here");
    let html = odc_doc::html::page(&common::sheet(&loaded));
    assert!(html.contains("1C12†</td>") && html.contains("<p class=\"legend\">† not in"));

    // The shipped EDS files have no such object: no mark, no legend.
    let md = odc_doc::markdown::markdown(&common::sheet(&common::load("eds/lxm23a.eds")));
    assert!(!md.contains('†') && !md.contains('‡'));
}

#[test]
fn defaults_odc_took_from_the_esi_are_marked() {
    let path = common::root().join("crates/odc-esi/tests/fixtures/coe_implied.xml");
    let own = r#"<Object><Index>#x1C13</Index><Name>TxPDO assign</Name><Type>DT1C13</Type>
      <BitSize>48</BitSize></Object></Objects>"#;
    let types = r#"<DataType><Name>DT1C13</Name><BitSize>48</BitSize>
        <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize><BitOffs>0</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
        <SubItem><SubIdx>1</SubIdx><Name>SubIndex 001</Name><Type>UINT</Type><BitSize>16</BitSize><BitOffs>16</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
        <SubItem><SubIdx>2</SubIdx><Name>SubIndex 002</Name><Type>UINT</Type><BitSize>16</BitSize><BitOffs>32</BitOffs><Flags><Access>rw</Access></Flags></SubItem>
      </DataType></DataTypes>"#;
    let xml = std::fs::read_to_string(path).unwrap().replacen("</Objects>", own, 1).replacen(
        "</DataTypes>",
        types,
        1,
    );
    let mut sources = odc_model::Sources::new();
    let parsed = odc_esi::parse(&mut sources, "t.xml", xml.as_bytes());
    let input = odc_doc::Input {
        device: &parsed.devices[0],
        file: "t.xml",
        sources: Some(&sources),
        diagnostics: &[],
        schemes: &[],
    };
    let md = odc_doc::render_markdown(&input);
    let rows: Vec<&str> = md.lines().filter(|l| l.contains("</a>1C13")).collect();
    // The object's row and its three sub-objects', each marked; 0x1C12 stays odc's own.
    assert_eq!(rows.len(), 4, "{rows:?}");
    assert!(rows.iter().all(|r| r.contains("</a>1C13‡ |")), "{rows:?}");
    assert!(md.contains("</a>1C12† |"));
    assert!(md.contains("\n‡ the file gives no default"));
}
