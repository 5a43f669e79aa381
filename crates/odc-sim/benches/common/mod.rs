//! The device of the cyclic benchmarks (`benches/ethercat_lrw.rs`, `examples/line100.rs`):
//! `esi/servoone.xml` with the CSP image mapped, 6 output bytes (controlword, target
//! position) and 6 input bytes (statusword, position actual value), written as its firmware
//! would set them (the ServoOne has no factory mapping), mode 8 (cyclic synchronous position).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, dead_code)]

use odc::slave::ObjectDictionary;
use odc_sim::ethercat::SubDevice;

/// Output and input bytes of one device.
pub const IMAGE: (usize, usize) = (6, 6);

/// The ServoOne model.
pub fn servoone() -> odc_model::Device {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../esi/servoone.xml");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    loaded.device().unwrap().clone()
}

/// A simulated ServoOne with the CSP mapping assigned.
pub fn servoone_csp(model: &odc_model::Device) -> SubDevice {
    let mut device = SubDevice::new(model).unwrap();
    let od = device.dictionary_mut();
    for (index, sub, data) in [
        (0x1600u16, 1u8, 0x6040_0010u32.to_le_bytes().to_vec()),
        (0x1600, 2, 0x607A_0020u32.to_le_bytes().to_vec()),
        (0x1600, 0, vec![2]),
        (0x1A00, 1, 0x6041_0010u32.to_le_bytes().to_vec()),
        (0x1A00, 2, 0x6064_0020u32.to_le_bytes().to_vec()),
        (0x1A00, 0, vec![2]),
        (0x1C12, 1, 0x1600u16.to_le_bytes().to_vec()),
        (0x1C12, 0, vec![1]),
        (0x1C13, 1, 0x1A00u16.to_le_bytes().to_vec()),
        (0x1C13, 0, vec![1]),
        (0x6060, 0, vec![8]),
    ] {
        od.write(index, sub, &data).unwrap();
    }
    device
}
