//! ESI elements the process image and start-up need beyond PDOs: oversampling and `Virtual`
//! on PDOs, Beckhoff's `AlternativeSmMapping`, DC op-modes with their own assignment, the
//! init commands of every mailbox protocol, and the diagnostics for malformed ones.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc_model::{Severity, Sources};

const ESI: &str = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>2</Id><Name>Test</Name></Vendor>
  <Descriptions><Groups><Group><Type>T</Type><Name>T</Name></Group></Groups>
  <Devices><Device>
    <Type ProductCode="#x1" RevisionNo="#x1">T1</Type>
    <Name>T1</Name>
    <Info><VendorSpecific><TwinCAT>
      <AlternativeSmMapping Default="1"><Name>Standard</Name>
        <Sm No="3"><Pdo>#x1a00</Pdo><Pdo>#x1a01</Pdo></Sm></AlternativeSmMapping>
      <AlternativeSmMapping Default=""><Name>Short</Name>
        <Sm No="2"><Pdo/></Sm><Sm No="3"><Pdo>#x1a00</Pdo></Sm></AlternativeSmMapping>
    </TwinCAT></VendorSpecific></Info>
    <GroupType>T</GroupType>
    <Sm StartAddress="#x1100" ControlByte="#x64" Enable="1">Outputs</Sm>
    <Sm StartAddress="#x0910" Virtual="true">Inputs</Sm>
    <TxPdo Sm="3" OSFac="10" OSMin="1" OSMax="50" OSIndexInc="16"><Index>#x1a00</Index><Name>A</Name>
      <Entry><Index>#x6000</Index><SubIndex>1</SubIndex><BitLen>16</BitLen><DataType>INT</DataType></Entry></TxPdo>
    <TxPdo Virtual="true"><Index>#x1a01</Index><Name>B</Name>
      <Entry><Index>#x1d09</Index><SubIndex>#x98</SubIndex><BitLen>32</BitLen><DataType>UDINT</DataType></Entry></TxPdo>
    <Mailbox>
      <CoE>
        <InitCmd><Transition>PS</Transition><Transition>XX</Transition><Index>#x8000</Index><SubIndex>1</SubIndex><Data>01</Data></InitCmd>
        <InitCmd><Index>#x8000</Index><SubIndex>2</SubIndex><Data>02</Data></InitCmd>
      </CoE>
      <EoE><InitCmd><Transition>PS</Transition><Type>3</Type><Data>0a0b</Data></InitCmd></EoE>
      <AoE><InitCmd><Transition>IP</Transition><Data>ff</Data></InitCmd></AoE>
    </Mailbox>
    <Dc><OpMode><Name>DcSync</Name><AssignActivate>#x700</AssignActivate>
      <CycleTimeSync0 Factor="1">0</CycleTimeSync0><ShiftTimeSync1 Factor="-1">250</ShiftTimeSync1>
      <Sm No="3"><SyncType>1</SyncType><Pdo OSFac="2">#x1a00</Pdo></Sm></OpMode></Dc>
  </Device></Devices></Descriptions>
</EtherCATInfo>"##;

#[test]
fn pdo_attributes_alternative_mappings_dc_and_init_cmds() {
    let mut sources = Sources::new();
    let parsed = odc_esi::parse(&mut sources, "t.xml", ESI.as_bytes());
    let dev = &parsed.devices[0];
    let ec = dev.ethercat.as_ref().unwrap();

    assert_eq!(ec.pdo_attributes.len(), 2);
    let a = &ec.pdo_attributes[0];
    assert_eq!((a.index, a.rx, a.virtual_pdo), (0x1A00, false, false));
    assert_eq!(
        (a.os_fac, a.os_min, a.os_max, a.os_index_inc),
        (Some(10), Some(1), Some(50), Some(16))
    );
    assert!(ec.pdo_attributes[1].virtual_pdo);
    assert!(ec.sync_managers[1].virtual_sm);

    let alt = &ec.alternative_sm_mappings;
    assert_eq!(alt.len(), 2);
    assert_eq!((alt[0].name.as_str(), alt[0].default), ("Standard", true));
    assert_eq!(alt[0].sms[0].pdos, [(0x1A00, None), (0x1A01, None)]);
    // `Default=""` is not the default; `<Pdo/>` leaves SM 2 empty.
    assert!(!alt[1].default);
    assert_eq!((alt[1].sms[0].number, alt[1].sms[0].pdos.len()), (2, 0));

    let mode = &ec.dc.as_ref().unwrap().op_modes[0];
    assert_eq!(mode.assign_activate, Some(0x700));
    assert_eq!((mode.shift_time_sync1, mode.shift_time_sync1_factor), (Some(250), Some(-1)));
    assert_eq!(mode.sms[0].number, 3);
    assert_eq!(mode.sms[0].sync_type, Some(1));
    assert_eq!(mode.sms[0].pdos, [(0x1A00, Some(2))]);

    let mb = ec.mailbox.as_ref().unwrap();
    assert_eq!(mb.eoe_init_cmds[0].index, Some(3));
    assert_eq!(mb.eoe_init_cmds[0].data, [0x0A, 0x0B]);
    assert_eq!(mb.aoe_init_cmds[0].transitions, ["IP"]);
    assert_eq!(mb.aoe_init_cmds[0].data, [0xFF]);

    // `XX` is kept but reported; the command without any Transition is reported missing it.
    let coe = mb.coe.as_ref().unwrap();
    assert_eq!(coe.init_cmds[0].transitions, ["PS", "XX"]);
    let codes: Vec<(&str, Severity)> =
        parsed.diagnostics.iter().map(|d| (d.code, d.severity)).collect();
    assert!(codes.contains(&("F230", Severity::Warning)), "{codes:?}");
    assert!(codes.contains(&("F209", Severity::Error)), "{codes:?}");
    assert_eq!(codes.len(), 2, "{codes:?}");
}
