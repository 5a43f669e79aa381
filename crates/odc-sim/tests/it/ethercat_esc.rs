//! The emulated ESC against ETG.1000.4: datagrams built byte by byte as the standard lays
//! them out (Table 6: command, index, address, length/flags, IRQ, data, working counter),
//! run through a chain of three devices, and the working counters, address fields and
//! register contents the standard prescribes (Table 7 for the counters; the register map of
//! §6 and the ESC datasheets for the registers).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc_model::Sources;
use odc_sim::ethercat::{Chain, HOP_NS, SubDevice};

/// A device with an identity of its own (values from this ESI text, not from the code).
const ESI: &str = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>#x00000099</Id><Name>V</Name></Vendor>
  <Descriptions>
    <Groups><Group><Type>IO</Type><Name>IO</Name></Group></Groups>
    <Devices>
      <Device Physics="YY">
        <Type ProductCode="#x12345678" RevisionNo="#x00020001" SerialNo="7">T1</Type>
        <Name LcId="1033">Test terminal</Name>
        <GroupType>IO</GroupType>
        <Fmmu>Outputs</Fmmu><Fmmu>Inputs</Fmmu>
        <Sm MinSize="34" MaxSize="128" DefaultSize="128" StartAddress="#x1000" ControlByte="#x26" Enable="1">MBoxOut</Sm>
        <Sm MinSize="34" MaxSize="128" DefaultSize="128" StartAddress="#x1080" ControlByte="#x22" Enable="1">MBoxIn</Sm>
        <Sm StartAddress="#x1100" ControlByte="#x64" Enable="1">Outputs</Sm>
        <Sm StartAddress="#x1180" ControlByte="#x20" Enable="1">Inputs</Sm>
        <Mailbox><CoE SdoInfo="false" CompleteAccess="false"/></Mailbox>
        <Eeprom><ByteSize>2048</ByteSize><ConfigData>0800CC0A</ConfigData></Eeprom>
      </Device>
    </Devices>
  </Descriptions>
</EtherCATInfo>"##;

fn device() -> SubDevice {
    let p = odc_esi::parse(&mut Sources::new(), "t.xml", ESI.as_bytes());
    assert!(!p.diagnostics.iter().any(|d| d.is_error()), "{:?}", p.diagnostics);
    SubDevice::new(&p.devices[0]).unwrap()
}

fn chain(n: usize) -> Chain {
    Chain::new((0..n).map(|_| device()).collect())
}

/// One datagram: command, ADP, ADO (or a logical address split the same way), data.
struct Dg {
    cmd: u8,
    adp: u16,
    ado: u16,
    data: Vec<u8>,
}

fn dg(cmd: u8, adp: u16, ado: u16, data: &[u8]) -> Dg {
    Dg { cmd, adp, ado, data: data.to_vec() }
}

/// An Ethernet frame of `dgs` (ETG.1000.4 §5.3: EtherType 0x88A4 big-endian, EtherCAT
/// header little-endian: length 11 bits, type 1 in bits 12–15).
fn frame(dgs: &[Dg]) -> Vec<u8> {
    let mut body = Vec::new();
    for (i, d) in dgs.iter().enumerate() {
        let more = if i + 1 < dgs.len() { 0x8000 } else { 0 };
        body.push(d.cmd);
        body.push(i as u8);
        body.extend(d.adp.to_le_bytes());
        body.extend(d.ado.to_le_bytes());
        body.extend((d.data.len() as u16 | more).to_le_bytes());
        body.extend([0, 0]);
        body.extend(&d.data);
        body.extend([0, 0]);
    }
    let mut f = vec![0xFF; 6];
    f.extend([0x02, 0, 0, 0, 0, 0]);
    f.extend([0x88, 0xA4]);
    f.extend((body.len() as u16 | 0x1000).to_le_bytes());
    f.extend(body);
    f
}

/// Each datagram's (ADP, data, WKC) after the frame came back.
fn parse(f: &[u8], dgs: &[Dg]) -> Vec<(u16, Vec<u8>, u16)> {
    let mut at = 16;
    dgs.iter()
        .map(|d| {
            let adp = u16::from_le_bytes([f[at + 2], f[at + 3]]);
            let data = f[at + 10..at + 10 + d.data.len()].to_vec();
            let w = at + 10 + d.data.len();
            let wkc = u16::from_le_bytes([f[w], f[w + 1]]);
            at = w + 2;
            (adp, data, wkc)
        })
        .collect()
}

fn run(c: &mut Chain, dgs: &[Dg]) -> Vec<(u16, Vec<u8>, u16)> {
    let mut f = frame(dgs);
    c.process(&mut f, 1_000_000).unwrap();
    // The first ESC's port 0 sets the locally administered bit of the source address.
    assert_eq!(f[6], 0x02);
    parse(&f, dgs)
}

const APRD: u8 = 1;
const APWR: u8 = 2;
const APRW: u8 = 3;
const FPRD: u8 = 4;
const FPWR: u8 = 5;
const FPRW: u8 = 6;
const BRD: u8 = 7;
const BWR: u8 = 8;
const BRW: u8 = 9;
const LRD: u8 = 10;
const LWR: u8 = 11;
const LRW: u8 = 12;
const ARMW: u8 = 13;
const FRMW: u8 = 14;

/// Station addresses 0x1001.. by position (APWR to ADP 0, -1, -2).
fn address(c: &mut Chain) {
    let dgs: Vec<Dg> = (0..c.devices().len() as u16)
        .map(|i| dg(APWR, 0u16.wrapping_sub(i), 0x0010, &(0x1001 + i).to_le_bytes()))
        .collect();
    for (_, _, wkc) in run(c, &dgs) {
        assert_eq!(wkc, 1);
    }
}

#[test]
fn broadcast_read_counts_every_device_and_increments_adp() {
    let mut c = chain(3);
    // BRD of the type register: each of the 3 devices reads (WKC 3) and increments ADP.
    let r = run(&mut c, &[dg(BRD, 0, 0x0000, &[0])]);
    assert_eq!((r[0].0, r[0].2), (3, 3));
    assert_ne!(r[0].1, [0]);
    // BWR: each writes. BRW: read 1 + write 2 per device.
    let r = run(&mut c, &[dg(BWR, 0, 0x0200, &[0x0F, 0]), dg(BRW, 0, 0x0200, &[0, 0])]);
    assert_eq!((r[0].2, r[1].2), (3, 9));
    assert_eq!(r[1].1, [0x0F, 0], "BRW reads the ORed registers before writing");
}

#[test]
fn auto_increment_and_configured_addressing() {
    let mut c = chain(3);
    address(&mut c);
    // APRD at position 2 (ADP -2): only the third device answers, ADP comes back +3.
    let r = run(&mut c, &[dg(APRD, 0xFFFE, 0x0010, &[0, 0])]);
    assert_eq!(r[0], (1, 0x1003u16.to_le_bytes().to_vec(), 1));
    // FPRD by station address; an address no device has gets WKC 0 and the data unchanged.
    let r = run(&mut c, &[dg(FPRD, 0x1002, 0x0010, &[0, 0]), dg(FPRD, 0x2000, 0x0010, &[9, 9])]);
    assert_eq!((r[0].1.clone(), r[0].2), (0x1002u16.to_le_bytes().to_vec(), 1));
    assert_eq!((r[1].1.clone(), r[1].2), (vec![9, 9], 0));
    // FPRW and APRW: the old value comes back, the new one is written, WKC 1 + 2.
    let r = run(&mut c, &[dg(FPRW, 0x1001, 0x0F80, &[0xAA]), dg(APRW, 0xFFFF, 0x0F80, &[0xBB])]);
    assert_eq!((r[0].1.clone(), r[0].2), (vec![0], 3));
    assert_eq!((r[1].1.clone(), r[1].2), (vec![0], 3));
    let r = run(&mut c, &[dg(FPRD, 0x1001, 0x0F80, &[0]), dg(FPWR, 0x1003, 0x0F80, &[0xCC])]);
    assert_eq!((r[0].1.clone(), r[0].2), (vec![0xAA], 1));
    assert_eq!(r[1].2, 1);
    let r = run(&mut c, &[dg(BRD, 0, 0x0F80, &[0])]);
    assert_eq!(r[0].1, [0xAA | 0xBB | 0xCC]);
}

#[test]
fn read_only_registers_keep_their_value() {
    let mut c = chain(1);
    address(&mut c);
    // AL status is read-only: the write is counted but changes nothing (INIT = 1).
    let r = run(&mut c, &[dg(FPWR, 0x1001, 0x0130, &[0x08, 0]), dg(FPRD, 0x1001, 0x0130, &[0, 0])]);
    assert_eq!(r[0].2, 1);
    assert_eq!(r[1].1, [0x01, 0x00]);
}

#[test]
fn read_multiple_write_distributes_the_addressed_value() {
    let mut c = chain(3);
    address(&mut c);
    // FRMW: the addressed device reads (1), the two others write (1 each).
    let r = run(&mut c, &[dg(FRMW, 0x1001, 0x0910, &[0; 8])]);
    assert_eq!(r[0].2, 3);
    // ARMW at position 1: one read, two writes; ADP incremented by each device. The first
    // device writes what the frame brings (7), the second puts its value (0x55) in, the
    // third writes that.
    run(&mut c, &[dg(FPWR, 0x1002, 0x0F80, &[0x55])]);
    let r = run(&mut c, &[dg(ARMW, 0xFFFF, 0x0F80, &[7])]);
    assert_eq!((r[0].0, r[0].1.clone(), r[0].2), (2, vec![0x55], 3));
    let r = run(
        &mut c,
        &[dg(BRD, 0, 0x0F80, &[0]), dg(FPRD, 0x1001, 0x0F80, &[0]), dg(FPRD, 0x1003, 0x0F80, &[0])],
    );
    assert_eq!((r[1].1.clone(), r[2].1.clone()), (vec![7], vec![0x55]));
}

#[test]
fn sii_reads_the_image_of_the_esi() {
    let mut c = chain(1);
    address(&mut c);
    // Read command (0x0502 bit 8) at word address 8: vendor ID and product code
    // (ETG.2010 words 0x08–0x0B), 8 bytes at 0x0508 (read size bit 6 set).
    let r = run(
        &mut c,
        &[
            dg(FPWR, 0x1001, 0x0502, &[0x00, 0x01, 0x08, 0x00, 0x00, 0x00]),
            dg(FPRD, 0x1001, 0x0502, &[0, 0]),
            dg(FPRD, 0x1001, 0x0508, &[0; 8]),
        ],
    );
    let control = u16::from_le_bytes([r[1].1[0], r[1].1[1]]);
    assert_eq!(control & 0x8000, 0, "not busy");
    assert_eq!(control & 0x0040, 0x0040, "8-byte reads");
    assert_eq!(r[2].1, [0x99, 0, 0, 0, 0x78, 0x56, 0x34, 0x12]);
    // Word 0x0C: revision 0x00020001.
    let r = run(
        &mut c,
        &[
            dg(FPWR, 0x1001, 0x0502, &[0x00, 0x01, 0x0C, 0x00, 0x00, 0x00]),
            dg(FPRD, 0x1001, 0x0508, &[0; 4]),
        ],
    );
    assert_eq!(r[1].1, [0x01, 0x00, 0x02, 0x00]);
    // A write without write enable (bit 0) is refused: bit 14, write enable error.
    let r = run(
        &mut c,
        &[
            dg(FPWR, 0x1001, 0x0502, &[0x00, 0x02, 0x04, 0, 0, 0]),
            dg(FPRD, 0x1001, 0x0502, &[0, 0]),
        ],
    );
    assert_eq!(u16::from_le_bytes([r[1].1[0], r[1].1[1]]) & 0x4000, 0x4000);
}

/// A device whose ESI announces SoE beside CoE and FoE: its EEPROM's mailbox protocols (word
/// 0x1C, ETG.2010 Table 2: bit 2 CoE, bit 3 FoE, bit 4 SoE) leave SoE out, which the firmware
/// stack does not serve (SOEM's config_map read a SoE drive's mapping over it and failed on
/// the corpus's Beckhoff AX5xxx drives); `odc sii` still writes the ESI's.
#[test]
fn the_eeprom_announces_no_soe() {
    let esi = ESI.replace("</Mailbox>", "<SoE/><FoE/></Mailbox>");
    let p = odc_esi::parse(&mut Sources::new(), "t.xml", esi.as_bytes());
    assert!(!p.diagnostics.iter().any(|d| d.is_error()), "{:?}", p.diagnostics);
    let image = odc_sii::write(&p.devices[0]).unwrap();
    assert_eq!(image[0x38..0x3A], [0x1C, 0x00], "CoE, FoE and SoE in odc sii's image");
    let mut c = Chain::new(vec![SubDevice::new(&p.devices[0]).unwrap()]);
    address(&mut c);
    let r = run(
        &mut c,
        &[
            dg(FPWR, 0x1001, 0x0502, &[0x00, 0x01, 0x1C, 0x00, 0x00, 0x00]),
            dg(FPRD, 0x1001, 0x0508, &[0; 2]),
        ],
    );
    assert_eq!(r[1].1, [0x0C, 0x00], "CoE and FoE");
}

/// FMMU registers (ETG.1000.4 Table 56): logical start, length, start/stop bits, physical
/// start, physical start bit, type (1 read, 2 write), activate.
fn fmmu(logical: u32, len: u16, physical: u16, kind: u8) -> Vec<u8> {
    let mut v = logical.to_le_bytes().to_vec();
    v.extend(len.to_le_bytes());
    v.extend([0, 7]);
    v.extend(physical.to_le_bytes());
    v.extend([0, kind, 1, 0, 0, 0]);
    v
}

#[test]
fn logical_commands_through_the_fmmus() {
    let mut c = chain(2);
    address(&mut c);
    // Device 1: 2 output bytes at logical 0x10000 → 0x1800, 2 input bytes at 0x10002 ←
    // 0x1900; device 2: 1 output byte at 0x10004, 1 input byte at 0x10005.
    let setup = [
        dg(FPWR, 0x1001, 0x0600, &fmmu(0x10000, 2, 0x1800, 2)),
        dg(FPWR, 0x1001, 0x0610, &fmmu(0x10002, 2, 0x1900, 1)),
        dg(FPWR, 0x1001, 0x1900, &[0x11, 0x22]),
        dg(FPWR, 0x1002, 0x0600, &fmmu(0x10004, 1, 0x1800, 2)),
        dg(FPWR, 0x1002, 0x0610, &fmmu(0x10005, 1, 0x1900, 1)),
        dg(FPWR, 0x1002, 0x1900, &[0x33]),
    ];
    run(&mut c, &setup);
    // LRW of the 6 bytes: each device reads (+1) and writes (+2): WKC 6.
    let r = run(&mut c, &[dg(LRW, 0x0000, 0x0001, &[0xA1, 0xA2, 0, 0, 0xA3, 0])]);
    assert_eq!(r[0].1, [0xA1, 0xA2, 0x11, 0x22, 0xA3, 0x33]);
    assert_eq!(r[0].2, 6);
    let r = run(&mut c, &[dg(FPRD, 0x1001, 0x1800, &[0, 0]), dg(FPRD, 0x1002, 0x1800, &[0])]);
    assert_eq!((r[0].1.clone(), r[1].1.clone()), (vec![0xA1, 0xA2], vec![0xA3]));
    // LRD counts the reads only (1 each), LWR the writes only (1 each); outside every
    // FMMU, WKC 0.
    let r = run(
        &mut c,
        &[
            dg(LRD, 0x0000, 0x0001, &[0; 6]),
            dg(LWR, 0x0000, 0x0001, &[0; 6]),
            dg(LRW, 0x0000, 0x0002, &[0; 4]),
        ],
    );
    assert_eq!((r[0].2, r[1].2, r[2].2), (2, 2, 0));
    assert_eq!(r[0].1, [0, 0, 0x11, 0x22, 0, 0x33], "LRD leaves output bytes as sent");
}

/// An FMMU of bits: `len` logical bytes from `start_bit` of the first to `stop_bit` of the
/// last, onto the physical bits from `phys_bit`.
fn fmmu_bits(logical: u32, len: u16, bits: (u8, u8), physical: (u16, u8), kind: u8) -> Vec<u8> {
    let mut v = logical.to_le_bytes().to_vec();
    v.extend(len.to_le_bytes());
    v.extend([bits.0, bits.1]);
    v.extend(physical.0.to_le_bytes());
    v.extend([physical.1, kind, 1, 0, 0, 0]);
    v
}

/// Three devices of 4 output and 4 input bits, packed as SOEM packs them (ecx_config_map: a
/// device of fewer than 8 bits starts where the previous one's bits end): device 1 in bits
/// 0–3 of logical byte 0, device 2 in bits 4–7, device 3 in bits 0–3 of byte 1; each one's
/// bits at bit 0 of its physical byte (#31: byte-granular FMMUs gave device 2 0x5 for 0xA).
#[test]
fn fmmus_map_bits_of_shared_bytes() {
    let mut c = chain(3);
    address(&mut c);
    let mut setup = Vec::new();
    for (k, (byte, start)) in [(0u32, 0u8), (0, 4), (1, 0)].into_iter().enumerate() {
        let station = 0x1001 + k as u16;
        let (first, last) = (start, start + 3);
        setup.push(dg(
            FPWR,
            station,
            0x0600,
            &fmmu_bits(0x100 + byte, 1, (first, last), (0x1800, 0), 2),
        ));
        setup.push(dg(
            FPWR,
            station,
            0x0610,
            &fmmu_bits(0x200 + byte, 1, (first, last), (0x1900, 0), 1),
        ));
        // Inputs 0x9, 0x6, 0x3 in the low nibble, a high nibble the FMMU does not map.
        setup.push(dg(FPWR, station, 0x1900, &[0xF0 | [0x9, 0x6, 0x3][k]]));
        setup.push(dg(FPWR, station, 0x1800, &[0xF0]));
    }
    run(&mut c, &setup);
    // Outputs 0x5, 0xA, 0xC; inputs read into bytes whose other bits stay as sent (0x0_).
    let r = run(&mut c, &[dg(LWR, 0x0100, 0x0000, &[0xA5, 0x0C]), dg(LRD, 0x0200, 0, &[0, 0x00])]);
    assert_eq!((r[0].2, r[1].2), (3, 3));
    assert_eq!(r[1].1, [0x69, 0x03]);
    let reads: Vec<_> = (0..3).map(|k| dg(FPRD, 0x1001 + k, 0x1800, &[0])).collect();
    let r = run(&mut c, &reads);
    // Each device's own bits, its high nibble untouched.
    let got: Vec<u8> = r.iter().map(|d| d.1[0]).collect();
    assert_eq!(got, [0xF5, 0xFA, 0xFC]);
}

/// SM registers (ETG.1000.4 Table 58): start, length, control, status, activate, PDI.
fn sm(start: u16, len: u16, control: u8) -> Vec<u8> {
    let mut v = start.to_le_bytes().to_vec();
    v.extend(len.to_le_bytes());
    v.extend([control, 0, 1, 0]);
    v
}

#[test]
fn mailbox_sync_managers_guard_their_buffers() {
    let mut c = chain(1);
    address(&mut c);
    // SM0 mailbox write (control 0x26), SM1 mailbox read (0x22), as the ESI gives them.
    run(
        &mut c,
        &[
            dg(FPWR, 0x1001, 0x0800, &sm(0x1000, 128, 0x26)),
            dg(FPWR, 0x1001, 0x0808, &sm(0x1080, 128, 0x22)),
        ],
    );
    // The read mailbox is empty: reading it is refused (WKC 0).
    let r = run(&mut c, &[dg(FPRD, 0x1001, 0x1080, &[0; 128])]);
    assert_eq!(r[0].2, 0);
    // Reading the write mailbox is refused too; writing it (to its last byte) is taken.
    let r =
        run(&mut c, &[dg(FPRD, 0x1001, 0x1000, &[0; 128]), dg(FPWR, 0x1001, 0x1000, &[0; 128])]);
    assert_eq!((r[0].2, r[1].2), (0, 1));
}

#[test]
fn receive_times_show_the_line() {
    let mut c = chain(3);
    address(&mut c);
    // BWR to 0x0900 latches the receive times of every port.
    let mut dgs = vec![dg(BWR, 0, 0x0900, &[0; 4])];
    for a in 0x1001..=0x1003 {
        dgs.push(dg(FPRD, a, 0x0900, &[0; 8]));
    }
    let r = run(&mut c, &dgs);
    assert_eq!(r[0].2, 3);
    let t = |i: usize, p: usize| u32::from_le_bytes(r[i].1[4 * p..4 * p + 4].try_into().unwrap());
    // In a line the frame returns through port 1 after travelling to the end and back:
    // 2 × (devices after it) hops later than it arrived at port 0.
    assert_eq!(t(1, 1).wrapping_sub(t(1, 0)) as u64, 4 * HOP_NS);
    assert_eq!(t(2, 1).wrapping_sub(t(2, 0)) as u64, 2 * HOP_NS);
    assert_eq!(t(3, 1), 0, "the last device's port 1 is closed");
}

#[test]
fn system_times_follow_the_reference_clock() {
    let mut c = chain(3);
    address(&mut c);
    let system_times = |c: &mut Chain| {
        let dgs: Vec<Dg> = (0x1001..=0x1003).map(|a| dg(FPRD, a, 0x0910, &[0; 8])).collect();
        let r = run(c, &dgs);
        r.iter().map(|(_, d, _)| u64::from_le_bytes(d[..].try_into().unwrap())).collect::<Vec<_>>()
    };
    // Free-running clocks that started at different moments disagree.
    let t = system_times(&mut c);
    assert!(t[1].abs_diff(t[0]) > 1_000_000, "{t:?}");
    // The master writes each device's transmission delay from the reference (0x0928,
    // here the hops the frame makes to it), then distributes the reference's time with FRMW
    // (ETG.1000.4 §9.2.3): every device takes it, plus its delay.
    for (i, a) in (0u64..).zip(0x1002..=0x1003u16) {
        run(&mut c, &[dg(FPWR, a, 0x0928, &((i + 1) as u32 * HOP_NS as u32).to_le_bytes())]);
    }
    run(&mut c, &[dg(FRMW, 0x1001, 0x0910, &[0; 8])]);
    // Read in one frame, each device at the moment the frame passes it: one clock, read
    // HOP_NS apart.
    let t = system_times(&mut c);
    assert_eq!(t[1] - t[0], HOP_NS);
    assert_eq!(t[2] - t[0], 2 * HOP_NS);
}
