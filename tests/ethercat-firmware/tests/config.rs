//! The firmware's `SYNC_MANAGERS` and `CONFIG` say what esi/servoone.xml says.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::ethercat::subdevice::al;
use odc_model::ethercat::SmUsage;
use odc_tests_ethercat_firmware::{CONFIG, SYNC_MANAGERS};

#[test]
fn sync_managers_and_mailbox_are_the_esi_s() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../esi/servoone.xml");
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
}
