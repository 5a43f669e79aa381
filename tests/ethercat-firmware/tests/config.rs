//! The firmware's `SYNC_MANAGERS` and `CONFIG` (written by build.rs) say what the ESI says
//! (esi/servoone.xml: two 34–256-byte mailboxes, process data up to 32 bytes, CoE without
//! complete access, FoE, SDO Information).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::ethercat::subdevice::al;
use odc_model::ethercat::SmUsage;
use odc_tests_ethercat_firmware::{CONFIG, SYNC_MANAGERS};

#[test]
fn sync_managers_and_mailbox_are_the_esi_s() {
    let path = match option_env!("ODC_FIRMWARE_ESI") {
        Some(esi) => std::path::PathBuf::from(esi),
        None => std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../esi/servoone.xml"),
    };
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let ecat = loaded.device().unwrap().ethercat.as_deref().unwrap();
    assert_eq!(ecat.sync_managers.len(), SYNC_MANAGERS.len());
    for (sm, spec) in ecat.sync_managers.iter().zip(&SYNC_MANAGERS) {
        let kind = match sm.usage {
            SmUsage::MBoxOut => al::MBOX_OUT,
            SmUsage::MBoxIn => al::MBOX_IN,
            SmUsage::Outputs => al::OUTPUTS,
            SmUsage::Inputs => al::INPUTS,
            _ => 0,
        };
        assert_eq!((sm.number, kind), (spec.number, spec.kind));
        assert_eq!(sm.min_size, Some(u32::from(spec.min)));
        assert_eq!(sm.max_size, Some(u32::from(spec.max)));
        assert_eq!(sm.control_byte.as_ref().map(|c| c.value), Some(spec.control));
    }
    let coe = ecat.mailbox.as_ref().and_then(|m| m.coe.as_ref());
    assert_eq!(CONFIG.coe, coe.is_some());
    assert_eq!(CONFIG.complete_access, coe.unwrap().complete_access);
    assert_eq!(CONFIG.foe, ecat.mailbox.as_ref().is_some_and(|m| m.foe));
    // SDO Information from the generated `slave::DESCRIPTION` where the ESI says `SdoInfo`.
    assert_eq!(CONFIG.describe.is_some(), coe.unwrap().sdo_info);
    assert!(CONFIG.fixed.is_empty(), "the ServoOne assigns every PDO through 0x1C12/0x1C13");
    if option_env!("ODC_FIRMWARE_ESI").is_none() {
        // esi/servoone.xml, `Device/Sm`, as the datasheet of this firmware says.
        assert_eq!(SYNC_MANAGERS.map(|s| (s.min, s.max)), [(34, 256), (34, 256), (0, 32), (0, 32)]);
        assert_eq!(SYNC_MANAGERS.map(|s| s.control), [0x26, 0x22, 0x64, 0x20]);
    }
}
