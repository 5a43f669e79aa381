//! What the EtherCAT tests of this binary share: datagrams as a master sends them, in a frame
//! run through a simulated chain (ETG.1000.4 Table 6 layout), and SM register blocks
//! (ETG.1000.4 §6: 0x0800 + 8n).

#![allow(clippy::unwrap_used)]

use odc_sim::ethercat::Chain;

pub const APWR: u8 = 2;
pub const FPRD: u8 = 4;
pub const FPWR: u8 = 5;
/// The configured station address the tests give the first device.
pub const ADDR: u16 = 0x1001;

/// One datagram in a frame, run through the chain: (data, WKC).
pub fn datagram(c: &mut Chain, cmd: u8, adp: u16, ado: u16, data: &[u8]) -> (Vec<u8>, u16) {
    let mut f = vec![0xFF; 6];
    f.extend([0x02, 0, 0, 0, 0, 0, 0x88, 0xA4]);
    f.extend(((12 + data.len()) as u16 | 0x1000).to_le_bytes());
    f.extend([cmd, 0]);
    f.extend(adp.to_le_bytes());
    f.extend(ado.to_le_bytes());
    f.extend((data.len() as u16).to_le_bytes());
    f.extend([0, 0]);
    f.extend(data);
    f.extend([0, 0]);
    c.process(&mut f, 0).unwrap();
    let d = f[26..26 + data.len()].to_vec();
    let w = 26 + data.len();
    (d, u16::from_le_bytes([f[w], f[w + 1]]))
}

/// An SM register block: start, length, control, status, activate (enable), PDI control.
pub fn sm(start: u16, len: u16, control: u8) -> [u8; 8] {
    let [s0, s1] = start.to_le_bytes();
    let [l0, l1] = len.to_le_bytes();
    [s0, s1, l0, l1, control, 0, u8::from(len > 0), 0]
}
