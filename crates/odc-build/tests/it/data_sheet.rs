//! `Config::data_sheet`: the data sheet written beside the generated code.
#![allow(clippy::unwrap_used)]

use std::path::Path;

#[test]
fn the_sheet_is_written_beside_the_code() {
    let out = std::env::temp_dir().join(format!("odc-build-sheet-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    let eds = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lxm23a.eds");
    odc_build::Config::new()
        .device(&eds)
        .data_sheet()
        .out_dir(&out)
        .emit_rerun_if_changed(false)
        .compile()
        .unwrap();
    assert!(out.join("lxm23a.rs").is_file());
    let html = std::fs::read_to_string(out.join("lxm23a.html")).unwrap();
    // The LXM23A's six default PDOs with entries, drawn.
    assert_eq!(html.matches("<svg").count(), 6);
    let md = std::fs::read_to_string(out.join("lxm23a.md")).unwrap();
    assert!(md.starts_with("# LXM23A\n"), "{}", &md[..40]);
    // Without the call, no sheet.
    let bare = out.join("bare");
    std::fs::create_dir_all(&bare).unwrap();
    odc_build::Config::new()
        .device(&eds)
        .out_dir(&bare)
        .emit_rerun_if_changed(false)
        .compile()
        .unwrap();
    assert!(bare.join("lxm23a.rs").is_file() && !bare.join("lxm23a.html").exists());
    let _ = std::fs::remove_dir_all(&out);
}
