//! The mailbox and CoE SDO server of the simulated device, byte by byte against ETG.1000.4
//! §5.6 (mailbox header: length, address, channel/priority, type/counter) and ETG.1000.6
//! §5.6.2 (CoE header: number, service 2 request / 3 response; SDO command bytes as CiA 301:
//! initiate download 0x2x, initiate upload 0x40, segments 0x00/0x60 with toggle bit 4, the
//! responses 0x60, 0x4x, 0x0x/0x2x, abort 0x80), through datagrams on a chain.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc::slave::ObjectDictionary;
use odc_sim::ethercat::{Chain, SubDevice};

use super::frames::{ADDR, APWR, FPRD, FPWR, datagram, sm};

fn servoone() -> odc_model::Device {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../esi/servoone.xml");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    loaded.device().unwrap().clone()
}

/// A device in PRE-OP with mailboxes of `mbx` bytes at the ESI's addresses.
fn pre_op(device: &odc_model::Device, mbx: u16) -> Chain {
    pre_op_device(SubDevice::new(device).unwrap(), mbx)
}

/// [`pre_op`] of a device built by the caller.
fn pre_op_device(device: SubDevice, mbx: u16) -> Chain {
    let mut c = Chain::new(vec![device]);
    datagram(&mut c, APWR, 0, 0x0010, &ADDR.to_le_bytes());
    datagram(&mut c, FPWR, ADDR, 0x0800, &sm(0x1000, mbx, 0x26));
    datagram(&mut c, FPWR, ADDR, 0x0808, &sm(0x1080, mbx, 0x22));
    datagram(&mut c, FPWR, ADDR, 0x0120, &[0x02, 0]);
    assert_eq!(datagram(&mut c, FPRD, ADDR, 0x0130, &[0, 0]).0, [0x02, 0]);
    c
}

/// Sends the CoE data `coe` in a mailbox (counter 1) and returns the reply's mailbox
/// (header and data, as long as its header says).
fn exchange(c: &mut Chain, mbx: u16, coe: &[u8]) -> Vec<u8> {
    let mut m = (coe.len() as u16).to_le_bytes().to_vec();
    m.extend([0, 0, 0, 0x13]);
    m.extend(coe);
    m.resize(usize::from(mbx), 0);
    assert_eq!(datagram(c, FPWR, ADDR, 0x1000, &m).1, 1);
    // SM1 status: mailbox full (bit 3).
    assert_eq!(datagram(c, FPRD, ADDR, 0x080D, &[0]).0[0] & 0x08, 0x08);
    let (reply, wkc) = datagram(c, FPRD, ADDR, 0x1080, &vec![0; usize::from(mbx)]);
    assert_eq!(wkc, 1);
    let len = usize::from(u16::from_le_bytes([reply[0], reply[1]]));
    // Type 3 (CoE) in the low nibble of byte 5.
    assert_eq!(reply[5] & 0x0F, 3);
    reply[..6 + len].to_vec()
}

/// The SDO part of a reply (after mailbox and CoE headers); checks the CoE header says SDO
/// response (service 3).
/// The value of `index`:`sub` in the device's dictionary (at most 4 bytes).
fn stored(device: &SubDevice, index: u16, sub: u8) -> Vec<u8> {
    let mut b = [0u8; 4];
    let n = device.dictionary().read(index, sub, &mut b).unwrap();
    b[..n].to_vec()
}

fn sdo(reply: &[u8]) -> &[u8] {
    assert_eq!(reply[7] >> 4, 3, "SDO response");
    &reply[8..]
}

/// The SDO part of an abort, which a device sends as CoE service 2, SDO request (ETG.1000.6,
/// Abort SDO Transfer Request).
fn abort(reply: &[u8]) -> &[u8] {
    assert_eq!(reply[7] >> 4, 2, "an abort is an SDO request");
    &reply[8..]
}

#[test]
fn expedited_upload_and_download() {
    let mut c = pre_op(&servoone(), 128);
    // Upload 0x1000:00 → expedited, 4 bytes: 0x43, the ESI's default 0x00000192.
    let r = exchange(&mut c, 128, &[0x00, 0x20, 0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(sdo(&r), [0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x00, 0x00]);
    // Download 0x6060:00 = 8 (1 byte: 0x2F), then upload: 0x4F (3 bytes unused).
    let r = exchange(&mut c, 128, &[0x00, 0x20, 0x2F, 0x60, 0x60, 0x00, 8, 0, 0, 0]);
    assert_eq!(sdo(&r), [0x60, 0x60, 0x60, 0x00, 0, 0, 0, 0]);
    let r = exchange(&mut c, 128, &[0x00, 0x20, 0x40, 0x60, 0x60, 0x00, 0, 0, 0, 0]);
    assert_eq!(sdo(&r), [0x4F, 0x60, 0x60, 0x00, 8, 0, 0, 0]);
    // Abort codes: 0x1000 is read-only (0x06010002), 0x5FFE does not exist (0x06020000),
    // 0x1018:09 does not (0x06090011).
    let r = exchange(&mut c, 128, &[0x00, 0x20, 0x23, 0x00, 0x10, 0x00, 1, 0, 0, 0]);
    assert_eq!(abort(&r), [0x80, 0x00, 0x10, 0x00, 0x02, 0x00, 0x01, 0x06]);
    let r = exchange(&mut c, 128, &[0x00, 0x20, 0x40, 0xFE, 0x5F, 0x00, 0, 0, 0, 0]);
    assert_eq!(abort(&r), [0x80, 0xFE, 0x5F, 0x00, 0x00, 0x00, 0x02, 0x06]);
    let r = exchange(&mut c, 128, &[0x00, 0x20, 0x40, 0x18, 0x10, 0x09, 0, 0, 0, 0]);
    assert_eq!(abort(&r), [0x80, 0x18, 0x10, 0x09, 0x11, 0x00, 0x09, 0x06]);
}

#[test]
fn normal_and_segmented_transfers() {
    let mut c = pre_op(&servoone(), 34);
    // Normal download (0x21: size indicated, not expedited) of a 2-byte value with its
    // complete size: 0x6040:00 = 0x0006 — then a download of 0x607A:00 in segments: size 4
    // announced, no data in the initiate (a 34-byte mailbox could carry it, but a client may
    // segment), then one last segment of 4 bytes (0x00 | n=3 << 1 | c=1 = 0x07), padded to 7.
    let r = exchange(&mut c, 34, &[0x00, 0x20, 0x21, 0x40, 0x60, 0x00, 2, 0, 0, 0, 0x06, 0x00]);
    assert_eq!(sdo(&r)[..4], [0x60, 0x40, 0x60, 0x00]);
    let r = exchange(&mut c, 34, &[0x00, 0x20, 0x21, 0x7A, 0x60, 0x00, 4, 0, 0, 0]);
    assert_eq!(sdo(&r)[..4], [0x60, 0x7A, 0x60, 0x00]);
    let r = exchange(&mut c, 34, &[0x00, 0x20, 0x07, 0x78, 0x56, 0x34, 0x12, 0, 0, 0]);
    assert_eq!(sdo(&r)[0], 0x20, "download segment response, toggle 0");
    let r = exchange(&mut c, 34, &[0x00, 0x20, 0x40, 0x7A, 0x60, 0x00, 0, 0, 0, 0]);
    assert_eq!(sdo(&r), [0x43, 0x7A, 0x60, 0x00, 0x78, 0x56, 0x34, 0x12]);
    // A wrong toggle bit aborts with 0x05030000.
    exchange(&mut c, 34, &[0x00, 0x20, 0x21, 0x7A, 0x60, 0x00, 4, 0, 0, 0]);
    let r = exchange(&mut c, 34, &[0x00, 0x20, 0x17, 1, 2, 3, 4, 0, 0, 0]);
    assert_eq!(abort(&r)[..4], [0x80, 0x7A, 0x60, 0x00]);
    assert_eq!(abort(&r)[4..], [0x00, 0x00, 0x03, 0x05]);

    // Segmented upload of a 31-byte string through a 34-byte mailbox: the initiate
    // response (0x41: size indicated, normal) carries the size 31 and 34 − 6 − 2 − 8 = 18
    // bytes; the upload segment (request 0x60, toggle 0) brings the other 13 with c = 1
    // (0x01), no unused-byte count (13 ≥ 7).
    let name = "ServoOne simulated from its ESI";
    c.devices_mut()[0]
        .dictionary_mut()
        .set(0x1008, 0, odc::VisibleString::<32>::new(name).unwrap())
        .unwrap();
    let r = exchange(&mut c, 34, &[0x00, 0x20, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(u16::from_le_bytes([r[0], r[1]]), 28);
    let s = sdo(&r);
    assert_eq!(s[..8], [0x41, 0x08, 0x10, 0x00, 31, 0, 0, 0]);
    assert_eq!(&s[8..], &name.as_bytes()[..18]);
    let r = exchange(&mut c, 34, &[0x00, 0x20, 0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(u16::from_le_bytes([r[0], r[1]]), 3 + 13);
    let s = sdo(&r);
    assert_eq!(s[0], 0x01);
    assert_eq!(&s[1..], &name.as_bytes()[18..]);
}

#[test]
fn complete_access_where_the_esi_allows_it() {
    // esi/servoone.xml says CompleteAccess="false": the device refuses it (0x06010000).
    let mut c = pre_op(&servoone(), 128);
    let r = exchange(&mut c, 128, &[0x00, 0x20, 0x50, 0x18, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(abort(&r), [0x80, 0x18, 0x10, 0x00, 0x00, 0x00, 0x01, 0x06]);
    // The same device as if its ESI allowed complete access: 0x1018 from sub-index 0 is
    // sub-index 0 padded to 16 bits, then the four UNSIGNED32 (ETG.1000.6 §5.6.2.1.1): 18
    // bytes, a normal upload (0x51: size indicated, complete access).
    let mut device = servoone();
    let coe = device.ethercat.as_mut().unwrap().mailbox.as_mut().unwrap().coe.as_mut().unwrap();
    coe.complete_access = true;
    let mut c = pre_op(&device, 128);
    let r = exchange(&mut c, 128, &[0x00, 0x20, 0x50, 0x18, 0x10, 0x00, 0, 0, 0, 0]);
    let s = sdo(&r);
    assert_eq!(s[..8], [0x51, 0x18, 0x10, 0x00, 18, 0, 0, 0]);
    assert_eq!(s[8..10], [4, 0]);
    assert_eq!(s.len(), 8 + 18);
    // A complete-access download of 0x1C12 from sub-index 0 (0x31: complete access, size
    // indicated, normal): count 1 and padding, then 0x1600 — the assignment reads back.
    let r =
        exchange(&mut c, 128, &[0x00, 0x20, 0x31, 0x12, 0x1C, 0x00, 4, 0, 0, 0, 1, 0, 0x00, 0x16]);
    assert_eq!(sdo(&r)[0], 0x60, "{r:02X?}");
    let r = exchange(&mut c, 128, &[0x00, 0x20, 0x40, 0x12, 0x1C, 0x01, 0, 0, 0, 0]);
    assert_eq!(sdo(&r), [0x4B, 0x12, 0x1C, 0x01, 0x00, 0x16, 0, 0]);
}

#[test]
fn other_mailbox_protocols_get_a_mailbox_error() {
    let mut c = pre_op(&servoone(), 128);
    // Type 4 (FoE) is not served: mailbox error (type 0), service 1, detail 2.
    let mut m = vec![4, 0, 0, 0, 0, 0x14, 0, 0, 0, 0];
    m.resize(128, 0);
    datagram(&mut c, FPWR, ADDR, 0x1000, &m);
    let (r, _) = datagram(&mut c, FPRD, ADDR, 0x1080, &[0; 128]);
    assert_eq!(r[5] & 0x0F, 0);
    assert_eq!(r[6..10], [0x01, 0x00, 0x02, 0x00]);
}

/// An SDO Information request (CoE service 8, ETG.1000.6 §5.6.3): opcode, reserved,
/// fragments left 0, then the data.
fn info_request(opcode: u8, data: &[u8]) -> Vec<u8> {
    let mut r = vec![0x00, 0x80, opcode, 0, 0, 0];
    r.extend(data);
    r
}

#[test]
fn sdo_information_descriptions() {
    let mut c = pre_op(&servoone(), 128);
    // Get OD (opcode 3) of 0x1018: response opcode 4, index, data type, max sub-index,
    // object code 9 (RECORD), the ESI's name.
    let r = exchange(&mut c, 128, &info_request(0x03, &[0x18, 0x10]));
    assert_eq!(r[7] >> 4, 8, "SDO Information");
    assert_eq!(r[8..12], [0x04, 0, 0, 0]);
    assert_eq!(r[12..14], [0x18, 0x10]);
    assert_eq!(r[16..18], [4, 9]);
    assert_eq!(&r[18..], b"Identity_Object");
    // Get ED (opcode 5) of 0x1018:01: UNSIGNED32 (0x0007), 32 bits, read-only in every
    // state (access bits 0–2), name "Vendor ID".
    let r = exchange(&mut c, 128, &info_request(0x05, &[0x18, 0x10, 0x01, 0x00]));
    assert_eq!(r[8], 0x06);
    assert_eq!(r[12..16], [0x18, 0x10, 0x01, 0x00]);
    assert_eq!(r[16..18], [0x07, 0x00]);
    assert_eq!(r[18..20], [32, 0]);
    assert_eq!(r[20..22], [0x07, 0x00]);
    assert_eq!(&r[22..], b"Vendor ID");
    // An object that does not exist: SDO Information error (opcode 7) with 0x06020000.
    let r = exchange(&mut c, 128, &info_request(0x03, &[0xFE, 0x5F]));
    assert_eq!(r[8], 0x07);
    assert_eq!(r[12..16], [0x00, 0x00, 0x02, 0x06]);
}

#[test]
fn sdo_information_list_in_fragments() {
    let device = servoone();
    let all: Vec<u16> = device.objects.keys().copied().collect();
    let mut c = pre_op(&device, 34);
    // A 34-byte mailbox carries 34 − 6 − 2 − 4 = 22 bytes of list a fragment; the list type
    // (1: all objects) comes first in the first one only.
    let mut got = Vec::new();
    let first = exchange(&mut c, 34, &info_request(0x01, &[0x01, 0x00]));
    let mut left = u16::from_le_bytes([first[10], first[11]]);
    assert_eq!(first[8], 0x82, "response opcode 2, incomplete");
    assert_eq!(first[12..14], [0x01, 0x00]);
    got.extend_from_slice(&first[14..]);
    while left > 0 {
        // The next fragment follows once the master has read the previous one.
        assert_eq!(datagram(&mut c, FPRD, ADDR, 0x080D, &[0]).0[0] & 0x08, 0x08);
        let (m, _) = datagram(&mut c, FPRD, ADDR, 0x1080, &[0; 34]);
        let len = usize::from(u16::from_le_bytes([m[0], m[1]]));
        let next = u16::from_le_bytes([m[10], m[11]]);
        assert_eq!(next, left - 1);
        assert_eq!(m[8] & 0x80 != 0, next > 0, "incomplete flag until the last");
        got.extend_from_slice(&m[12..6 + len]);
        left = next;
    }
    let list: Vec<u16> = got.chunks(2).map(|b| u16::from_le_bytes([b[0], b[1]])).collect();
    assert_eq!(list, all);
}

/// A device whose assignment objects default empty starts with the assignment its ESI gives
/// (#31: SOEM's default bring-up read the empty 0x1C12 and met 0x001D at SAFE-OP). The
/// ServoOne's ESI, with `Sm` attributes added to its second RxPDO and first TxPDO here; the
/// ESI front-end fills the objects (note F231), the simulator serves the model.
#[test]
fn empty_assignment_objects_start_with_the_esi_assignment() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../esi/servoone.xml");
    let xml = std::fs::read_to_string(path).unwrap();
    let xml = xml
        .replacen(
            "<RxPdo>\n\t\t\t\t\t<Index>#x1601</Index>",
            "<RxPdo Sm=\"2\">\n\t\t\t\t\t<Index>#x1601</Index>",
            1,
        )
        .replacen(
            "<TxPdo>\n\t\t\t\t\t<Index>#x1A00</Index>",
            "<TxPdo Sm=\"3\">\n\t\t\t\t\t<Index>#x1A00</Index>",
            1,
        );
    let parsed = odc_esi::parse(&mut odc_model::Sources::new(), "servoone.xml", xml.as_bytes());
    let device = parsed.devices.into_iter().next().unwrap();
    assert_eq!(device.pdos.iter().filter(|p| p.sync_manager.is_some()).count(), 2);
    let sim = SubDevice::new(&device).unwrap();
    let read = |index, sub| stored(&sim, index, sub);
    assert_eq!((read(0x1C12, 0), read(0x1C12, 1)), (vec![1], vec![0x01, 0x16]));
    assert_eq!((read(0x1C13, 0), read(0x1C13, 1)), (vec![1], vec![0x00, 0x1A]));
    // The ESI as it is (no `Sm` on its PDOs): the empty defaults stay.
    let sim = SubDevice::new(&servoone()).unwrap();
    let mut b = [0u8; 1];
    assert_eq!(sim.dictionary().read(0x1C12, 0, &mut b), Ok(1));
    assert_eq!(b, [0]);
}

/// A CoE device whose ESI's dictionary lists only the mapped objects: its firmware still has
/// what a master reads before it maps the process data (SOEM's config_map: 0x1C00, then
/// 0x1C12/0x1C13, then each assigned PDO's mapping object), from the ESI's `Sm` elements and
/// PDOs, and the mapping object of every PDO of the ESI: the ESI front-end synthesises them
/// into the model (`Origin::CoeImplied`), the simulator adds nothing. Values from this ESI
/// text.
#[test]
fn a_coe_device_has_the_assignment_and_mapping_its_esi_gives() {
    const ESI: &str = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>#x00000099</Id><Name>V</Name></Vendor>
  <Descriptions>
    <Groups><Group><Type>IO</Type><Name>IO</Name></Group></Groups>
    <Devices>
      <Device Physics="YY">
        <Type ProductCode="#x00000001" RevisionNo="#x00000001">T1</Type>
        <Name LcId="1033">Test terminal</Name>
        <GroupType>IO</GroupType>
        <Profile><Dictionary>
          <DataTypes>
            <DataType><Name>USINT</Name><BitSize>8</BitSize></DataType>
            <DataType><Name>UINT</Name><BitSize>16</BitSize></DataType>
          </DataTypes>
          <Objects>
            <Object><Index>#x6000</Index><Name>I</Name><Type>UINT</Type><BitSize>16</BitSize><Flags><Access>ro</Access><PdoMapping>T</PdoMapping></Flags></Object>
            <Object><Index>#x7000</Index><Name>O</Name><Type>USINT</Type><BitSize>8</BitSize><Flags><Access>rw</Access><PdoMapping>R</PdoMapping></Flags></Object>
          </Objects>
        </Dictionary></Profile>
        <Fmmu>Outputs</Fmmu><Fmmu>Inputs</Fmmu>
        <Sm MinSize="34" MaxSize="128" DefaultSize="128" StartAddress="#x1000" ControlByte="#x26" Enable="1">MBoxOut</Sm>
        <Sm MinSize="34" MaxSize="128" DefaultSize="128" StartAddress="#x1080" ControlByte="#x22" Enable="1">MBoxIn</Sm>
        <Sm StartAddress="#x1100" ControlByte="#x64" Enable="1">Outputs</Sm>
        <Sm StartAddress="#x1180" ControlByte="#x20" Enable="1">Inputs</Sm>
        <RxPdo Fixed="1" Sm="2"><Index>#x1600</Index><Name>Out</Name>
          <Entry><Index>#x7000</Index><SubIndex>0</SubIndex><BitLen>8</BitLen><Name>O</Name><DataType>USINT</DataType></Entry>
        </RxPdo>
        <RxPdo Fixed="1"><Index>#x1601</Index><Name>Spare</Name>
          <Entry><Index>#x7000</Index><SubIndex>0</SubIndex><BitLen>8</BitLen><Name>O</Name><DataType>USINT</DataType></Entry>
        </RxPdo>
        <TxPdo Fixed="1" Sm="3"><Index>#x1A00</Index><Name>In</Name>
          <Entry><Index>#x6000</Index><SubIndex>0</SubIndex><BitLen>16</BitLen><Name>I</Name><DataType>UINT</DataType></Entry>
        </TxPdo>
        <Mailbox><CoE SdoInfo="false" CompleteAccess="false"/></Mailbox>
        <Eeprom><ByteSize>2048</ByteSize><ConfigData>0800CC0A</ConfigData></Eeprom>
      </Device>
    </Devices>
  </Descriptions>
</EtherCATInfo>"##;
    let p = odc_esi::parse(&mut odc_model::Sources::new(), "t.xml", ESI.as_bytes());
    let origin = p.devices[0].objects.get(&0x1C12).map(|o| o.origin);
    assert_eq!(origin, Some(odc_model::Origin::CoeImplied), "the ESI's dictionary lacks it");
    let sim = SubDevice::new(&p.devices[0]).unwrap();
    let read = |index, sub| stored(&sim, index, sub);
    // 0x1C00: 4 sync managers: mailbox out, mailbox in, outputs, inputs.
    assert_eq!([read(0x1C00, 0), read(0x1C00, 3), read(0x1C00, 4)], [[4], [3], [4]]);
    // SM2 assigns 0x1600, SM3 0x1A00 (their `Sm` attributes).
    assert_eq!((read(0x1C12, 0), read(0x1C12, 1)), (vec![1], vec![0x00, 0x16]));
    assert_eq!((read(0x1C13, 0), read(0x1C13, 1)), (vec![1], vec![0x00, 0x1A]));
    // 0x7000:00, 8 bits; 0x6000:00, 16 bits.
    assert_eq!((read(0x1600, 0), read(0x1600, 1)), (vec![1], vec![0x08, 0x00, 0x00, 0x70]));
    assert_eq!((read(0x1A00, 0), read(0x1A00, 1)), (vec![1], vec![0x10, 0x00, 0x00, 0x60]));
    // 0x1601, which no sync manager assigns by default: its mapping object too, as a master
    // may assign it.
    assert_eq!((read(0x1601, 0), read(0x1601, 1)), (vec![1], vec![0x08, 0x00, 0x00, 0x70]));
}

/// The slave side odc generates for the ServoOne: its `slave::DESCRIPTION` is what a firmware
/// serves SDO Information from.
mod generated {
    odc_macros::include_device!("../../esi/servoone.xml", role = "slave");
}

/// Every answer of SDO Information from the generated `DESCRIPTION` (names in one pool, types
/// and access read from the table's rows) is the answer served from the model (which the
/// tests above and ethercrab's in ethercat_ethercrab.rs check against ETG.1000.6), byte for
/// byte: Get OD of every object, Get ED of every entry and of one that is not there, and the
/// object lists of every type, all fragments.
#[test]
fn generated_description_answers_as_the_model() {
    let device = servoone();
    let mut model = pre_op(&device, 128);
    let firmware = SubDevice::new(&device).unwrap().with_description(generated::slave::DESCRIPTION);
    let mut firmware = pre_op_device(firmware, 128);
    let mut chains = [&mut model, &mut firmware];
    let both = |chains: &mut [&mut Chain; 2], request: Vec<u8>| both_answer(chains, &request);
    let mut entries = 0;
    for (&index, object) in &device.objects {
        let [lo, hi] = index.to_le_bytes();
        let r = both(&mut chains, info_request(0x03, &[lo, hi]));
        assert_eq!(r[8], 0x04, "{index:04X}: a description, not an error");
        for &sub in object.subs.keys() {
            let r = both(&mut chains, info_request(0x05, &[lo, hi, sub, 0]));
            assert_eq!(r[8], 0x06, "{index:04X}:{sub}");
            entries += 1;
        }
        both(&mut chains, info_request(0x05, &[lo, hi, 0xFE, 0]));
    }
    assert_eq!((device.objects.len(), entries), (100, 247));
    // Get OD List of each type: the first fragment here, the rest as the master reads them.
    for list in 0..=5u8 {
        let first = both(&mut chains, info_request(0x01, &[list, 0]));
        let mut left = u16::from_le_bytes([first[10], first[11]]);
        while left > 0 {
            let read = |c: &mut Chain| {
                assert_eq!(datagram(c, FPRD, ADDR, 0x080D, &[0]).0[0] & 0x08, 0x08);
                datagram(c, FPRD, ADDR, 0x1080, &[0; 128]).0
            };
            let [model, firmware] = &mut chains;
            let (a, b) = (read(model), read(firmware));
            assert_eq!(a, b, "list {list}, {left} fragments left");
            left = u16::from_le_bytes([a[10], a[11]]);
        }
    }
}

/// The reply of both chains to `request`, which must be the same.
fn both_answer(chains: &mut [&mut Chain; 2], request: &[u8]) -> Vec<u8> {
    let [model, firmware] = chains;
    let a = exchange(model, 128, request);
    let b = exchange(firmware, 128, request);
    assert_eq!(a, b, "request {request:02X?}");
    a
}

/// The master side odc generates for a CoE device whose ESI lets a master assign and map
/// (`CoE@PdoAssign`, `@PdoConfig`) and whose dictionary leaves out the assignment and mapping
/// objects: its `startup::PLAN` clears 0x1C12/0x1C13, maps 0x1600 and 0x1A00 and assigns them.
mod pdo_config {
    odc_macros::include_device!("tests/fixtures/pdo_config.xml", role = "master");
}

const PDO_CONFIG: &str = include_str!("../fixtures/pdo_config.xml");

/// Every write of `plan` as an expedited SDO download (CiA 301 command 0x23/0x2B/0x2F: 4, 2,
/// 1 bytes); the SDO part of each reply.
fn run_plan(c: &mut Chain, plan: &[odc::plan::SdoWrite]) -> Vec<Vec<u8>> {
    plan.iter()
        .map(|w| {
            let cmd = match w.size {
                1 => 0x2F,
                2 => 0x2B,
                _ => 0x23,
            };
            let [i0, i1] = w.index.to_le_bytes();
            let [d0, d1, d2, d3] = w.value.to_le_bytes();
            exchange(c, 128, &[0x00, 0x20, cmd, i0, i1, w.sub, d0, d1, d2, d3])[8..].to_vec()
        })
        .collect()
}

/// The synthesised assignment and mapping objects are writable in PRE-OP where the ESI says
/// so: the device accepts every write of the generated plan (response 0x60, CiA 301 initiate
/// download response) and holds the plan's mapping and assignment after it. Without
/// `PdoAssign`/`PdoConfig` the same writes meet read-only objects: abort 0x06010002 (CiA 301
/// Table 22, "attempt to write a read only object").
#[test]
fn the_generated_plan_configures_a_device_whose_esi_allows_it() {
    let plan = pdo_config::startup::PLAN.pdo_writes;
    let touched = |i: u16| plan.iter().any(|w| w.index == i);
    assert!(touched(0x1C12) && touched(0x1C13) && touched(0x1600) && touched(0x1A00), "{plan:?}");
    let load = |xml: &str| {
        let p = odc_esi::parse(&mut odc_model::Sources::new(), "pdo_config.xml", xml.as_bytes());
        p.devices.into_iter().next().unwrap()
    };
    let mut c = pre_op(&load(PDO_CONFIG), 128);
    for (w, reply) in plan.iter().zip(run_plan(&mut c, plan)) {
        let [i0, i1] = w.index.to_le_bytes();
        assert_eq!(reply[..4], [0x60, i0, i1, w.sub], "{w:?}: {reply:02X?}");
    }
    let dev = &c.devices()[0];
    let read = |index, sub| stored(dev, index, sub);
    // As the ESI: 0x1C12 = [0x1600], 0x1C13 = [0x1A00]; 0x1A00 = 0x6000:01/16, gap/8.
    assert_eq!((read(0x1C12, 0), read(0x1C12, 1)), (vec![1], vec![0x00, 0x16]));
    assert_eq!((read(0x1C13, 0), read(0x1C13, 1)), (vec![1], vec![0x00, 0x1A]));
    assert_eq!(read(0x1A00, 0), [2]);
    assert_eq!((read(0x1A00, 1), read(0x1A00, 2)), (vec![0x10, 1, 0, 0x60], vec![8, 0, 0, 0]));

    let without = PDO_CONFIG.replacen(r#" PdoAssign="1" PdoConfig="1""#, "", 1);
    let mut c = pre_op(&load(&without), 128);
    for (w, reply) in plan.iter().zip(run_plan(&mut c, plan)) {
        let [i0, i1] = w.index.to_le_bytes();
        assert_eq!(reply, [0x80, i0, i1, w.sub, 0x02, 0x00, 0x01, 0x06], "{w:?}");
    }
}
