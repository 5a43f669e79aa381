//! Faults of odc that the ethercrab sweep of the corpus found (tests/ethercat-sweep/ethercrab.md),
//! each as the smallest ESI that shows it, driven by datagrams as a master sends them
//! (ETG.1000.4 Table 6 layout, registers of ETG.1000.4 §6: SM 0x0800 + 8n, AL control 0x0120,
//! AL status 0x0130, AL status code 0x0134).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc_model::Sources;
use odc_sim::ethercat::{Chain, SubDevice};

use super::frames::{ADDR, APWR, FPRD, FPWR, datagram, sm};

fn device(esi: &str) -> Chain {
    let p = odc_esi::parse(&mut Sources::new(), "t.xml", esi.as_bytes());
    assert!(!p.diagnostics.iter().any(|d| d.is_error()), "{:?}", p.diagnostics);
    Chain::new(vec![SubDevice::new(&p.devices[0]).unwrap()])
}

/// Requests `state` and returns (AL status, AL status code).
fn request(c: &mut Chain, state: u8) -> (u8, u16) {
    datagram(c, FPWR, ADDR, 0x0120, &[state, 0]);
    let status = datagram(c, FPRD, ADDR, 0x0130, &[0, 0]).0[0];
    let code = datagram(c, FPRD, ADDR, 0x0134, &[0, 0]).0;
    (status, u16::from_le_bytes([code[0], code[1]]))
}

/// An SoE drive as Beckhoff's AX5103 describes itself (corpus
/// `beckhoff__Beckhoff_AX5xxx.xml`): no CoE, PDOs whose `Index` and entries are SoE IDNs
/// (the AT S-0-0016 and MDT S-0-0024 telegrams, entries S-0-0134 and so on), not dictionary
/// objects. `{INPUTS}` is its inputs' SM control byte (the AX5103's: 0x22).
const SOE_DRIVE: &str = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>#x00000002</Id><Name>V</Name></Vendor>
  <Descriptions>
    <Groups><Group><Type>Drive</Type><Name>Drive</Name></Group></Groups>
    <Devices>
      <Device Physics="YY">
        <Type ProductCode="#x13ef6012" RevisionNo="#x00CA0000">AX5103-0000-0202</Type>
        <Name LcId="1033">SoE drive</Name>
        <GroupType>Drive</GroupType>
        <Fmmu>Outputs</Fmmu><Fmmu>Inputs</Fmmu><Fmmu>MBoxState</Fmmu>
        <Sm MinSize="128" MaxSize="128" DefaultSize="128" StartAddress="#x1800" ControlByte="#x26" Enable="1">MBoxOut</Sm>
        <Sm MinSize="128" MaxSize="128" DefaultSize="128" StartAddress="#x1a00" ControlByte="#x22" Enable="1">MBoxIn</Sm>
        <Sm StartAddress="#x1000" ControlByte="#x24" Enable="1">Outputs</Sm>
        <Sm StartAddress="#x1100" ControlByte="#x{INPUTS}" Enable="1">Inputs</Sm>
        <RxPdo Mandatory="1" Sm="2"><Index>24</Index><Name>MDT</Name>
          <Entry><Index>134</Index><BitLen>16</BitLen><Name>Master control word</Name><DataType>UINT</DataType></Entry>
          <Entry><Index>47</Index><BitLen>32</BitLen><Name>Position command value</Name><DataType>DINT</DataType></Entry>
        </RxPdo>
        <TxPdo Mandatory="1" Sm="3"><Index>16</Index><Name>AT</Name>
          <Entry><Index>135</Index><BitLen>16</BitLen><Name>Drive status word</Name><DataType>UINT</DataType></Entry>
          <Entry><Index>51</Index><BitLen>32</BitLen><Name>Position feedback 1 value</Name><DataType>DINT</DataType></Entry>
        </TxPdo>
        <Mailbox DataLinkLayer="true"><SoE/></Mailbox>
        <Eeprom><ByteSize>2048</ByteSize><ConfigData>080C0000</ConfigData></Eeprom>
      </Device>
    </Devices>
  </Descriptions>
</EtherCATInfo>"##;

/// A device without CoE has no assignment or mapping objects a master could read or change:
/// its process data is what its SII's PDO categories say (ETG.2010), as a master sizes it. An
/// SoE drive's PDO indices are IDNs; odc's model gives them assignment objects (0x1C12 →
/// 0x0018), and the stack laid out SM2 from those, found no object 0x0086 and refused
/// SAFE-OP with 0x0025 (invalid output mapping). It now takes the ESI's fixed PDOs.
#[test]
fn a_device_without_coe_runs_the_pdos_of_its_esi() {
    // Inputs buffered (0x20) here: the AX5103's single buffer is the next test's.
    let mut c = device(&SOE_DRIVE.replace("{INPUTS}", "20"));
    datagram(&mut c, APWR, 0, 0x0010, &ADDR.to_le_bytes());
    datagram(&mut c, FPWR, ADDR, 0x0800, &sm(0x1800, 128, 0x26));
    datagram(&mut c, FPWR, ADDR, 0x0808, &sm(0x1A00, 128, 0x22));
    assert_eq!(request(&mut c, 2), (0x02, 0));
    // MDT: 16 + 32 bits; AT: 16 + 32 bits (the ESI's entries).
    datagram(&mut c, FPWR, ADDR, 0x0810, &sm(0x1000, 6, 0x24));
    datagram(&mut c, FPWR, ADDR, 0x0818, &sm(0x1100, 6, 0x20));
    assert_eq!(request(&mut c, 4), (0x04, 0));
    assert_eq!(request(&mut c, 8), (0x08, 0));
}

/// Process data in one buffer: the AX5103's inputs SM has `ControlByte` 0x22 (mode 2, the
/// master reads), which ETG.1000.4 allows for process data and masters set from the SII. The
/// stack wanted every process data SM buffered and refused SAFE-OP with 0x001E (invalid input
/// configuration); it now wants the mode and direction the ESI gives, and still refuses
/// another.
#[test]
fn process_data_in_the_single_buffer_mode_its_esi_gives() {
    let to_pre_op = || {
        let mut c = device(&SOE_DRIVE.replace("{INPUTS}", "22"));
        datagram(&mut c, APWR, 0, 0x0010, &ADDR.to_le_bytes());
        datagram(&mut c, FPWR, ADDR, 0x0800, &sm(0x1800, 128, 0x26));
        datagram(&mut c, FPWR, ADDR, 0x0808, &sm(0x1A00, 128, 0x22));
        assert_eq!(request(&mut c, 2), (0x02, 0));
        datagram(&mut c, FPWR, ADDR, 0x0810, &sm(0x1000, 6, 0x24));
        c
    };
    let mut c = to_pre_op();
    datagram(&mut c, FPWR, ADDR, 0x0818, &sm(0x1100, 6, 0x22));
    assert_eq!(request(&mut c, 4), (0x04, 0));
    assert_eq!(request(&mut c, 8), (0x08, 0));
    // Buffered where the ESI says one buffer: not what the device is built for.
    let mut c = to_pre_op();
    datagram(&mut c, FPWR, ADDR, 0x0818, &sm(0x1100, 6, 0x20));
    assert_eq!(request(&mut c, 4), (0x12, 0x001E));
    // The master writing the inputs: refused too.
    let mut c = to_pre_op();
    datagram(&mut c, FPWR, ADDR, 0x0818, &sm(0x1100, 6, 0x26));
    assert_eq!(request(&mut c, 4), (0x12, 0x001E));
}

/// A coupler without a microcontroller, as Beckhoff's EK1101 describes itself (corpus
/// `beckhoff__Beckhoff_EKxxxx.xml`): `ConfigData` 0401… puts PDI control 0x04 (digital I/O)
/// and ESC configuration 0x01 (device emulation) in registers 0x0140/0x0141, its one sync
/// manager is disabled (`Enable="0"`), and its ID switch is a 16-bit input at 0x1000.
const COUPLER: &str = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>#x00000002</Id><Name>V</Name></Vendor>
  <Descriptions>
    <Groups><Group><Type>Coupler</Type><Name>Coupler</Name></Group></Groups>
    <Devices>
      <Device Physics="YY">
        <Type ProductCode="#x044d2c52" RevisionNo="#x00100000">EK1101</Type>
        <Name LcId="1033">Coupler with ID switch</Name>
        <GroupType>Coupler</GroupType>
        <Fmmu>Inputs</Fmmu>
        <Sm StartAddress="#x1000" ControlByte="0" Enable="0">Inputs</Sm>
        <TxPdo Fixed="1" Sm="0"><Index>#x1a00</Index><Name>ID</Name>
          <Entry><Index>#x6000</Index><SubIndex>1</SubIndex><BitLen>16</BitLen><Name>ID</Name><DataType>UINT</DataType></Entry>
        </TxPdo>
        <Eeprom><ByteSize>2048</ByteSize><ConfigData>040100000000c000</ConfigData></Eeprom>
      </Device>
    </Devices>
  </Descriptions>
</EtherCATInfo>"##;

/// ESC datasheets (register 0x0141 bit 0, device emulation): AL status is set to what the
/// master writes to AL control, by the ESC; there is no firmware to check sync managers.
/// The simulated device ran the firmware stack's checks anyway and refused SAFE-OP with
/// 0x001E (its only SM disabled while a PDO is assigned to it). It now follows AL control,
/// and its inputs reach the master through the FMMU.
#[test]
fn an_esc_without_a_microcontroller_follows_al_control() {
    let mut c = device(COUPLER);
    // The ID switch at 0x0123 (the dictionary stands for the pins; the entry is read-only
    // to a master, so set as the hardware sets it).
    let id = c.devices_mut()[0].dictionary_mut().raw_mut(0x6000, 1).unwrap();
    id.copy_from_slice(&[0x23, 0x01]);
    datagram(&mut c, APWR, 0, 0x0010, &ADDR.to_le_bytes());
    assert_eq!(request(&mut c, 2), (0x02, 0));
    // SM0 as the SII gives it: 2 bytes, disabled; an FMMU reads them to logical 0.
    datagram(&mut c, FPWR, ADDR, 0x0800, &[0x00, 0x10, 2, 0, 0x00, 0, 0, 0]);
    let fmmu = [0u8, 0, 0, 0, 2, 0, 0, 7, 0x00, 0x10, 0, 1, 1, 0, 0, 0];
    datagram(&mut c, FPWR, ADDR, 0x0600, &fmmu);
    assert_eq!(request(&mut c, 4), (0x04, 0));
    assert_eq!(request(&mut c, 8), (0x08, 0));
    assert_eq!(c.devices()[0].al_state(), 8);
    // LRD of logical 0, 2 bytes: the ID, working counter 1.
    assert_eq!(datagram(&mut c, 10, 0, 0, &[0, 0]), (vec![0x23, 0x01], 1));
}

/// A CoE device whose ESI has no dictionary and only input PDOs, as NI's 9144 chassis
/// (corpus `ni__NI9144.xml`, device 1): odc synthesises its dictionary from the PDOs, with
/// 0x1C13 but no 0x1C12, though it declares an outputs sync manager. ethercrab reads 0x1C12:00
/// of every CoE device with one (0x1C10 + n, ETG.1000.6 Table 67) and stopped at the abort
/// 0x06020000 (object does not exist). The simulated firmware now has it, empty.
#[test]
fn a_coe_device_has_an_assignment_object_for_each_process_data_sm() {
    use odc::slave::ObjectDictionary;
    let esi = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>#x00001DC5</Id><Name>V</Name></Vendor>
  <Descriptions>
    <Groups><Group><Type>Chassis</Type><Name>Chassis</Name></Group></Groups>
    <Devices>
      <Device Physics="YY">
        <Type ProductCode="#x23b8" RevisionNo="#x2">NI 9144</Type>
        <Name LcId="1033">Chassis</Name>
        <GroupType>Chassis</GroupType>
        <Fmmu>Outputs</Fmmu><Fmmu>Inputs</Fmmu>
        <Sm StartAddress="#x1F00" DefaultSize="#x100" MinSize="#x40" MaxSize="#x100" ControlByte="#x26" Enable="1">MBoxOut</Sm>
        <Sm StartAddress="#x1C00" DefaultSize="#x300" MinSize="#x40" MaxSize="#x300" ControlByte="#x22" Enable="1">MBoxIn</Sm>
        <Sm StartAddress="#x1000" DefaultSize="#x200" MinSize="#x0" MaxSize="#x200" ControlByte="#x64" Enable="1">Outputs</Sm>
        <Sm StartAddress="#x1600" DefaultSize="#x200" MinSize="#x0" MaxSize="#x200" ControlByte="#x20" Enable="1">Inputs</Sm>
        <TxPdo Fixed="1" Sm="3"><Index>#x1a00</Index><Name>Status</Name>
          <Entry><Index>#x6000</Index><SubIndex>1</SubIndex><BitLen>16</BitLen><Name>Status</Name><DataType>UINT</DataType></Entry>
        </TxPdo>
        <Mailbox><CoE SdoInfo="1" CompleteAccess="1" PdoAssign="1"/></Mailbox>
        <Eeprom><ByteSize>2048</ByteSize><ConfigData>080C0000</ConfigData></Eeprom>
      </Device>
    </Devices>
  </Descriptions>
</EtherCATInfo>"##;
    let c = device(esi);
    let od = c.devices()[0].dictionary();
    let read = |index: u16, sub: u8| {
        let mut b = [0u8; 4];
        od.read(index, sub, &mut b).map(|n| b[..n].to_vec())
    };
    // SM2 (outputs): nothing assigned; SM3 (inputs): the ESI's TxPDO.
    assert_eq!(read(0x1C12, 0), Ok(vec![0]));
    assert_eq!(read(0x1C13, 0), Ok(vec![1]));
    assert_eq!(read(0x1C13, 1), Ok(vec![0x00, 0x1A]));
    // 0x1C00, the sync manager types of the four SMs (ETG.1000.6: 1, 2, 3, 4).
    assert_eq!(read(0x1C00, 0), Ok(vec![4]));
    assert_eq!((1..=4).map(|s| read(0x1C00, s).unwrap()[0]).collect::<Vec<_>>(), [1, 2, 3, 4]);
}

/// Device emulation with a mailbox (pollen-robotics' Orbita devices, corpus
/// `pollen-robotics__Orbita3d.xml`: `ConfigData` 8003…, an on-chip-bus PDI with device
/// emulation set, and CoE): a microcontroller serves the mailbox, so its firmware still runs.
/// After the previous fix the simulated device had none and never answered (ethercrab:
/// `Timeout(MailboxResponse)`); its firmware's checks and answers are back.
#[test]
fn device_emulation_with_a_mailbox_still_runs_the_firmware() {
    let esi = SOE_DRIVE.replace("{INPUTS}", "20").replace("080C0000", "8003006EFF00FF000000");
    let mut c = device(&esi);
    datagram(&mut c, APWR, 0, 0x0010, &ADDR.to_le_bytes());
    // A write mailbox shorter than MinSize (128): the firmware refuses PRE-OP (0x0016); an
    // ESC alone would have copied the state.
    datagram(&mut c, FPWR, ADDR, 0x0800, &sm(0x1800, 16, 0x26));
    datagram(&mut c, FPWR, ADDR, 0x0808, &sm(0x1A00, 128, 0x22));
    assert_eq!(request(&mut c, 2), (0x11, 0x0016));
    datagram(&mut c, FPWR, ADDR, 0x0800, &sm(0x1800, 128, 0x26));
    assert_eq!(request(&mut c, 0x12), (0x02, 0));
}

/// Inputs beyond an ET1100's 8 KiB of process RAM, as Beckhoff's EL6695 bridge terminals
/// place them (corpus `beckhoff__Beckhoff_EL66xx.xml`: `<Sm DefaultSize="2"
/// StartAddress="#x8E00" ControlByte="#x20">Inputs</Sm>`; their ESC has the RAM). The
/// emulated ESC had 8 KiB (0x1000–0x2FFF) for every device: the firmware's inputs at 0x8E00
/// went nowhere and the FMMU reading them counted nothing, so ethercrab saw working counter 0
/// (expected 1) from the first cycle in OP. The ESC now has the RAM the ESI's sync managers
/// need (register 0x0006, process RAM size in KiB) and the LRD counts 1 (ETG.1000.4 Table 7).
#[test]
fn inputs_where_the_esi_places_them_beyond_8_kib() {
    let esi = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>#x00000002</Id><Name>V</Name></Vendor>
  <Descriptions>
    <Groups><Group><Type>Bridge</Type><Name>Bridge</Name></Group></Groups>
    <Devices>
      <Device Physics="YY">
        <Type ProductCode="#x1a273052" RevisionNo="#x00010000">EL6695</Type>
        <Name LcId="1033">Bridge</Name>
        <GroupType>Bridge</GroupType>
        <Fmmu>Outputs</Fmmu><Fmmu>Inputs</Fmmu>
        <Sm DefaultSize="0" StartAddress="#x1C00" ControlByte="#x64" Enable="1">Outputs</Sm>
        <Sm DefaultSize="2" StartAddress="#x8E00" ControlByte="#x20" Enable="1">Inputs</Sm>
        <TxPdo Fixed="1" Sm="1"><Index>#x1a01</Index><Name>Status</Name>
          <Entry><Index>#x6000</Index><SubIndex>1</SubIndex><BitLen>16</BitLen><Name>Status</Name><DataType>UINT</DataType></Entry>
        </TxPdo>
        <Eeprom><ByteSize>2048</ByteSize><ConfigData>080C0000</ConfigData></Eeprom>
      </Device>
    </Devices>
  </Descriptions>
</EtherCATInfo>"##;
    let mut c = device(esi);
    let status = c.devices_mut()[0].dictionary_mut().raw_mut(0x6000, 1).unwrap();
    status.copy_from_slice(&[0x95, 0x66]);
    datagram(&mut c, APWR, 0, 0x0010, &ADDR.to_le_bytes());
    // 0x8E02 - 0x1000 bytes of process RAM: 32 KiB.
    assert_eq!(datagram(&mut c, FPRD, ADDR, 0x0006, &[0]), (vec![32], 1));
    assert_eq!(request(&mut c, 2), (0x02, 0));
    datagram(&mut c, FPWR, ADDR, 0x0808, &sm(0x8E00, 2, 0x20));
    // FMMU 0: logical 0, 2 bytes, bits 0–7, physical 0x8E00, read, enabled.
    let fmmu = [0u8, 0, 0, 0, 2, 0, 0, 7, 0x00, 0x8E, 0, 1, 1, 0, 0, 0];
    datagram(&mut c, FPWR, ADDR, 0x0600, &fmmu);
    assert_eq!(request(&mut c, 4), (0x04, 0));
    assert_eq!(request(&mut c, 8), (0x08, 0));
    // LRD of logical 0, 2 bytes: the status, working counter 1.
    assert_eq!(datagram(&mut c, 10, 0, 0, &[0, 0]), (vec![0x95, 0x66], 1));
    // A device whose sync managers sit in 8 KiB keeps an ET1100's RAM.
    let mut c = device(COUPLER);
    datagram(&mut c, APWR, 0, 0x0010, &ADDR.to_le_bytes());
    assert_eq!(datagram(&mut c, FPRD, ADDR, 0x0006, &[0]), (vec![8], 1));
}

/// Inputs of an ESC without a microcontroller in a one-buffer sync manager, as Beckhoff's
/// EL1252 has them (corpus `beckhoff__etc-Beckhoff_EL1xxx.xml`: `ConfigData` 0401…, device
/// emulation with the digital I/O PDI; `<Sm DefaultSize="1" StartAddress="#x1000"
/// ControlByte="#x22">Inputs</Sm>`, mode 2: one buffer, the master reads). In that mode the
/// master reads the buffer only once the PDI has written it (ESC datasheets, section I, sync
/// manager one-buffer mode). The simulated digital I/O PDI put the pins into the RAM without
/// the sync manager seeing a write, so the buffer stayed empty, the read was refused and SOEM
/// counted working counter 0 in every cycle. The pins now go in through the PDI.
#[test]
fn digital_inputs_fill_a_one_buffer_sync_manager() {
    let esi = COUPLER
        .replace(
            r#"ControlByte="0" Enable="0""#,
            r##"DefaultSize="1" ControlByte="#x22" Enable="1""##,
        )
        .replace("<BitLen>16</BitLen>", "<BitLen>8</BitLen>")
        .replace("<DataType>UINT</DataType>", "<DataType>USINT</DataType>");
    let mut c = device(&esi);
    c.devices_mut()[0].dictionary_mut().raw_mut(0x6000, 1).unwrap().copy_from_slice(&[0x5A]);
    datagram(&mut c, APWR, 0, 0x0010, &ADDR.to_le_bytes());
    assert_eq!(request(&mut c, 2), (0x02, 0));
    datagram(&mut c, FPWR, ADDR, 0x0800, &sm(0x1000, 1, 0x22));
    let fmmu = [0u8, 0, 0, 0, 1, 0, 0, 7, 0x00, 0x10, 0, 1, 1, 0, 0, 0];
    datagram(&mut c, FPWR, ADDR, 0x0600, &fmmu);
    assert_eq!(request(&mut c, 4), (0x04, 0));
    assert_eq!(request(&mut c, 8), (0x08, 0));
    // LRD of logical 0: the inputs and working counter 1, cycle after cycle (each read
    // empties the buffer, the next sample fills it).
    for _ in 0..3 {
        assert_eq!(datagram(&mut c, 10, 0, 0, &[0]), (vec![0x5A], 1));
    }
}

/// A mapping object without a default, as Weidmüller's UR20-FBC-EC declares 0x16FF (corpus
/// `weidmueller__Weidmueller_UR20_FBC.xml`: `<Object>` with `Type` and `BitSize` and no
/// `Info`), while its `<RxPdo>` of that index lists the entries: the simulated firmware mapped
/// nothing (sub 0 = 0), SOEM sized SM 2 from the SII and the device refused SAFE-OP with 0x001D
/// (invalid output configuration). It now starts with the mapping its ESI's PDO gives; a
/// mapping object with a default keeps it.
#[test]
fn a_mapping_object_without_a_default_starts_with_its_pdo() {
    use odc::slave::ObjectDictionary;
    let esi = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>#x00000230</Id><Name>V</Name></Vendor>
  <Descriptions>
    <Groups><Group><Type>Coupler</Type><Name>Coupler</Name></Group></Groups>
    <Devices>
      <Device Physics="YY">
        <Type ProductCode="#x4F911C30" RevisionNo="#x1">UR20-FBC-EC</Type>
        <Name LcId="1033">Coupler</Name>
        <GroupType>Coupler</GroupType>
        <Profile><Dictionary>
          <DataTypes>
            <DataType><Name>USINT</Name><BitSize>8</BitSize></DataType>
            <DataType><Name>UINT</Name><BitSize>16</BitSize></DataType>
            <DataType><Name>UDINT</Name><BitSize>32</BitSize></DataType>
            <DataType><Name>DT16FF</Name><BitSize>80</BitSize>
              <SubItem><SubIdx>0</SubIdx><Name>SubIndex 000</Name><Type>USINT</Type><BitSize>8</BitSize><BitOffs>0</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
              <SubItem><SubIdx>1</SubIdx><Name>SubIndex 001</Name><Type>UDINT</Type><BitSize>32</BitSize><BitOffs>16</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
              <SubItem><SubIdx>2</SubIdx><Name>SubIndex 002</Name><Type>UDINT</Type><BitSize>32</BitSize><BitOffs>48</BitOffs><Flags><Access>ro</Access></Flags></SubItem>
            </DataType>
          </DataTypes>
          <Objects>
            <Object><Index>#x16FF</Index><Name>Device Control PDO</Name><Type>DT16FF</Type><BitSize>80</BitSize></Object>
            <Object><Index>#x16FE</Index><Name>Other PDO</Name><Type>DT16FF</Type><BitSize>80</BitSize>
              <Info><SubItem><Name>SubIndex 000</Name><Info><DefaultData>00</DefaultData></Info></SubItem></Info></Object>
            <Object><Index>#xF200</Index><Name>Control</Name><Type>UINT</Type><BitSize>16</BitSize><Flags><Access>rw</Access><PdoMapping>R</PdoMapping></Flags></Object>
          </Objects>
        </Dictionary></Profile>
        <Fmmu>Outputs</Fmmu>
        <Sm StartAddress="#x1000" DefaultSize="#x100" MinSize="#x40" MaxSize="#x100" ControlByte="#x26" Enable="1">MBoxOut</Sm>
        <Sm StartAddress="#x1400" DefaultSize="#x100" MinSize="#x40" MaxSize="#x100" ControlByte="#x22" Enable="1">MBoxIn</Sm>
        <Sm StartAddress="#x1800" ControlByte="#x64" Enable="1">Outputs</Sm>
        <RxPdo Fixed="1" Mandatory="1" Sm="2"><Index>#x16FF</Index><Name>Device Control</Name>
          <Entry><Index>#xF200</Index><SubIndex>0</SubIndex><BitLen>16</BitLen><Name>Control</Name><DataType>UINT</DataType></Entry>
        </RxPdo>
        <RxPdo><Index>#x16FE</Index><Name>Other</Name>
          <Entry><Index>#xF200</Index><SubIndex>0</SubIndex><BitLen>16</BitLen><Name>Control</Name><DataType>UINT</DataType></Entry>
        </RxPdo>
        <Mailbox><CoE SdoInfo="1" PdoAssign="1"/></Mailbox>
        <Eeprom><ByteSize>2048</ByteSize><ConfigData>080C0000</ConfigData></Eeprom>
      </Device>
    </Devices>
  </Descriptions>
</EtherCATInfo>"##;
    let p = odc_esi::parse(&mut Sources::new(), "t.xml", esi.as_bytes());
    assert!(!p.diagnostics.iter().any(|d| d.is_error()), "{:?}", p.diagnostics);
    let sim = SubDevice::new(&p.devices[0]).unwrap();
    let od = sim.dictionary();
    let read = |index: u16, sub: u8| {
        let mut b = [0u8; 4];
        od.read(index, sub, &mut b).map(|n| b[..n].to_vec())
    };
    // 0x16FF: one entry, 0xF200:00 of 16 bits (index << 16 | sub << 8 | bits).
    assert_eq!(read(0x16FF, 0), Ok(vec![1]));
    assert_eq!(read(0x16FF, 1), Ok(0xF200_0010u32.to_le_bytes().to_vec()));
    // 0x16FE's default (no entries) stands.
    assert_eq!(read(0x16FE, 0), Ok(vec![0]));
}
