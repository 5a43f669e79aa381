//! A generated dictionary starts with the values the runtime works out from the device file:
//! for every row, the stored bytes of `slave::Dictionary::new` equal those of
//! `odc_sim::ModelDictionary`, which builds its table from the model at run time and
//! initialises it entry by entry (`Table::init`'s typed path). EtherCAT devices (no `$NODEID`
//! default) take their values from the `INITIAL` image the generator wrote; CANopen ones
//! still initialise at run time: both must agree with the model's.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

use odc::slave::{Row, Storage};
use odc_tests_generated::{coe_implied, lexium_mdrive, lxm23a, mini_drive, pdi_terminal, servoone};

fn model(file: &str) -> odc_model::Device {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(file);
    odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap().devices.remove(0)
}

/// Compares every row's stored bytes; returns how many rows hold a value other than zero (so
/// that a test of all-zero dictionaries cannot pass).
fn agree(
    file: &str,
    rows: &[Row],
    generated: &dyn Storage,
    node: Option<odc::cob::NodeId>,
) -> usize {
    let model = odc_sim::ModelDictionary::new(&model(file), node);
    let mut set = 0;
    for row in rows {
        let (i, s) = (row.addr().index, row.addr().sub);
        let (ours, theirs) = (generated.raw(i, s), model.raw(i, s));
        assert_eq!(ours, theirs, "{file} {i:04X}:{s:02X} on node {node:?}");
        set += usize::from(ours.is_some_and(|b| b.iter().any(|&b| b != 0)));
    }
    set
}

#[test]
fn ethercat_images_hold_the_initial_values() {
    for node in [None, Some(odc::node_id!(1)), Some(odc::node_id!(127))] {
        let files = [
            (
                "esi/servoone.xml",
                servoone::slave::TABLE.rows(),
                &servoone::slave::Dictionary::new(node) as &dyn Storage,
            ),
            (
                "crates/odc-codegen/tests/fixtures/pdi-terminal.xml",
                pdi_terminal::slave::TABLE.rows(),
                &pdi_terminal::slave::Dictionary::new(node),
            ),
            (
                "crates/odc-esi/tests/fixtures/coe_implied.xml",
                coe_implied::slave::TABLE.rows(),
                &coe_implied::slave::Dictionary::new(node),
            ),
        ];
        for (file, rows, generated) in files {
            assert!(agree(file, rows, generated, node) > 10, "{file}: hardly any default");
        }
    }
}

#[test]
fn canopen_dictionaries_initialise_as_the_model() {
    for node in [None, Some(odc::node_id!(5))] {
        agree(
            "eds/lxm23a.eds",
            lxm23a::slave::TABLE.rows(),
            &lxm23a::slave::Dictionary::new(node),
            node,
        );
        agree(
            "eds/lexium-mdrive.eds",
            lexium_mdrive::slave::TABLE.rows(),
            &lexium_mdrive::slave::Dictionary::new(node),
            node,
        );
        agree(
            "crates/odc-codegen/tests/fixtures/mini-drive.eds",
            mini_drive::slave::TABLE.rows(),
            &mini_drive::slave::Dictionary::new(node),
            node,
        );
    }
}
