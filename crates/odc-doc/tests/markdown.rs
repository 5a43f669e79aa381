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
