//! A small ESI written into an SII image: each field at the place ETG.2010 gives it (offsets
//! from the standard's tables, values from the ESI text), then read back.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use odc_model::Sources;

const ESI: &str = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>#x99</Id><Name>V</Name></Vendor>
  <Descriptions>
    <Groups><Group><Type>Drives</Type><Name>Drives</Name></Group></Groups>
    <Devices>
      <Device Physics="YYK">
        <Type ProductCode="#x12345678" RevisionNo="#x00020001" SerialNo="7">SV1-A</Type>
        <Name LcId="1031">Antrieb</Name>
        <Name LcId="1033">Servo drive</Name>
        <Info><Electrical><EBusCurrent>-250</EBusCurrent></Electrical>
          <IdentificationAdo>#x1000</IdentificationAdo></Info>
        <GroupType>Drives</GroupType>
        <Fmmu>Outputs</Fmmu><Fmmu>Inputs</Fmmu><Fmmu>MBoxState</Fmmu>
        <Sm MinSize="34" MaxSize="256" DefaultSize="128" StartAddress="#x1000" ControlByte="#x26" Enable="1">MBoxOut</Sm>
        <Sm MinSize="34" MaxSize="256" DefaultSize="128" StartAddress="#x1080" ControlByte="#x22" Enable="1">MBoxIn</Sm>
        <Sm StartAddress="#x1100" ControlByte="#x64" Enable="1">Outputs</Sm>
        <Sm DefaultSize="6" StartAddress="#x1400" ControlByte="#x20" Enable="1" OpOnly="1">Inputs</Sm>
        <RxPdo Fixed="1" Mandatory="1" Sm="2"><Index>#x1600</Index><Name>Outputs</Name>
          <Entry><Index>#x6040</Index><SubIndex>0</SubIndex><BitLen>16</BitLen><Name>Controlword</Name><DataType>UINT</DataType></Entry>
          <Entry><Index>#x0</Index><BitLen>8</BitLen></Entry>
        </RxPdo>
        <TxPdo Sm="3"><Index>#x1A00</Index><Name>Inputs</Name>
          <Entry><Index>#x6041</Index><SubIndex>0</SubIndex><BitLen>16</BitLen><Name>Statusword</Name><DataType>UINT</DataType></Entry>
          <Entry><Index>#x6064</Index><SubIndex>0</SubIndex><BitLen>32</BitLen><Name>Position</Name><DataType>DINT</DataType></Entry>
        </TxPdo>
        <TxPdo><Index>#x1A01</Index><Name>Spare</Name></TxPdo>
        <Mailbox DataLinkLayer="true">
          <CoE SdoInfo="true" PdoAssign="true" PdoConfig="false" CompleteAccess="true"/>
          <FoE/>
        </Mailbox>
        <Dc>
          <OpMode><Name>DC</Name><Desc>DC-Synchron</Desc><AssignActivate>#x300</AssignActivate>
            <CycleTimeSync0 Factor="1">0</CycleTimeSync0><ShiftTimeSync0>-1000</ShiftTimeSync0>
            <CycleTimeSync1 Factor="-2">0</CycleTimeSync1><ShiftTimeSync1>500</ShiftTimeSync1></OpMode>
        </Dc>
        <Eeprom>
          <ByteSize>2048</ByteSize>
          <ConfigData>080C0E0C8813</ConfigData>
          <BootStrap>0010F400F410F400</BootStrap>
          <Category><CatNo>1</CatNo><Data>5C120500FF</Data></Category>
        </Eeprom>
      </Device>
    </Devices>
  </Descriptions>
</EtherCATInfo>"##;

fn device(xml: &str) -> odc_model::Device {
    let p = odc_esi::parse(&mut Sources::new(), "t.xml", xml.as_bytes());
    assert!(!p.diagnostics.iter().any(|d| d.is_error()), "{:?}", p.diagnostics);
    p.devices.into_iter().next().unwrap()
}

fn word(image: &[u8], w: usize) -> u16 {
    u16::from_le_bytes([image[2 * w], image[2 * w + 1]])
}

fn dword(image: &[u8], w: usize) -> u32 {
    u32::from(word(image, w)) | u32::from(word(image, w + 1)) << 16
}

/// Finds a category by type: (byte offset of its data, its data).
fn category(image: &[u8], kind: u16) -> Option<&[u8]> {
    let mut at = 128;
    loop {
        let t = u16::from_le_bytes([image[at], image[at + 1]]);
        if t == 0xFFFF {
            return None;
        }
        let len = 2 * usize::from(u16::from_le_bytes([image[at + 2], image[at + 3]]));
        if t == kind {
            return Some(&image[at + 4..at + 4 + len]);
        }
        at += 4 + len;
    }
}

#[test]
fn crc8_check_value() {
    // CRC-8, polynomial 0x07, initial 0xFF, MSB first, over "123456789".
    assert_eq!(odc_sii::crc8(b"123456789"), 0xFB);
}

#[test]
fn info_area_fields() {
    let image = odc_sii::write(&device(ESI)).unwrap();
    assert_eq!(image.len(), 2048, "padded to ByteSize");
    assert_eq!(&image[..6], [0x08, 0x0C, 0x0E, 0x0C, 0x88, 0x13], "ConfigData verbatim");
    assert_eq!(&image[6..14], [0; 8]);
    assert_eq!(word(&image, 7), u16::from(odc_sii::crc8(&image[..14])));
    assert_eq!(dword(&image, 8), 0x99);
    assert_eq!(dword(&image, 0xA), 0x1234_5678);
    assert_eq!(dword(&image, 0xC), 0x0002_0001);
    assert_eq!(dword(&image, 0xE), 7);
    assert_eq!(&image[0x28..0x30], [0x00, 0x10, 0xF4, 0x00, 0xF4, 0x10, 0xF4, 0x00]);
    assert_eq!([word(&image, 0x18), word(&image, 0x19)], [0x1000, 128]);
    assert_eq!([word(&image, 0x1A), word(&image, 0x1B)], [0x1080, 128]);
    assert_eq!(word(&image, 0x1C), 0x04 | 0x08, "CoE and FoE");
    assert_eq!(word(&image, 0x3E), 15, "2048 bytes = 16 KiBit");
    assert_eq!(word(&image, 0x3F), 1);
}

#[test]
fn categories() {
    let image = odc_sii::write(&device(ESI)).unwrap();
    let sii = odc_sii::read(&image).unwrap();
    let g = category(&image, 30).unwrap();
    assert_eq!(g.len(), 32);
    let s = |i: u8| sii.string(i).unwrap_or("");
    assert_eq!((s(g[0]), s(g[2]), s(g[3])), ("Drives", "SV1-A", "Servo drive"));
    assert_eq!(g[1], 0, "no image");
    assert_eq!(g[5], 0x01 | 0x02 | 0x04 | 0x20, "SDO, SDO info, PDO assign, complete access");
    assert_eq!((g[6], g[7]), (1, 0), "FoE, no EoE");
    assert_eq!(g[11], 0x04 | 0x10, "data link layer, IdentPhyM");
    assert_eq!(i16::from_le_bytes([g[12], g[13]]), -250);
    assert_eq!(g[14], g[0]);
    assert_eq!(u16::from_le_bytes([g[16], g[17]]), 0x0311, "ports Y, Y, K");
    assert_eq!(u16::from_le_bytes([g[18], g[19]]), 0x1000);
    assert_eq!(category(&image, 40).unwrap(), [1, 2, 3, 0xFF]);
    let sm = category(&image, 41).unwrap();
    assert_eq!(sm.len(), 32);
    assert_eq!(&sm[..8], [0x00, 0x10, 128, 0, 0x26, 0, 0x01, 1]);
    assert_eq!(&sm[16..24], [0x00, 0x11, 0, 0, 0x64, 0, 0x01, 3], "no DefaultSize: length 0");
    assert_eq!(&sm[24..32], [0x00, 0x14, 6, 0, 0x20, 0, 0x09, 4], "OpOnly = bit 3");
    let rx = category(&image, 51).unwrap();
    assert_eq!(&rx[..5], [0x00, 0x16, 2, 2, 0]);
    assert_eq!(s(rx[5]), "Outputs");
    assert_eq!(u16::from_le_bytes([rx[6], rx[7]]), 0x0013, "mandatory, default, fixed");
    assert_eq!(&rx[8..11], [0x40, 0x60, 0]);
    assert_eq!(s(rx[11]), "Controlword");
    assert_eq!(&rx[12..16], [0x06, 16, 0, 0], "UINT = 0x0006");
    assert_eq!(&rx[16..24], [0, 0, 0, 0, 0, 8, 0, 0], "gap");
    let tx = category(&image, 50).unwrap();
    assert_eq!(tx.len(), 8 + 16 + 8);
    assert_eq!(&tx[24..29], [0x01, 0x1A, 0, 0xFF, 0], "no Sm: 0xFF");
    assert_eq!(u16::from_le_bytes([tx[30], tx[31]]), 0, "not assigned by default");
    let dc = category(&image, 60).unwrap();
    assert_eq!(dc.len(), 24);
    assert_eq!(&dc[..4], [0; 4]);
    assert_eq!(i32::from_le_bytes(dc[4..8].try_into().unwrap()), -1000);
    assert_eq!(u32::from_le_bytes(dc[8..12].try_into().unwrap()), 500);
    assert_eq!(i16::from_le_bytes([dc[12], dc[13]]), -2);
    assert_eq!(u16::from_le_bytes([dc[14], dc[15]]), 0x300);
    assert_eq!(i16::from_le_bytes([dc[16], dc[17]]), 1);
    assert_eq!((s(dc[18]), s(dc[19])), ("DC", "DC-Synchron"));
    assert_eq!(category(&image, 1).unwrap(), [0x5C, 0x12, 0x05, 0x00, 0xFF, 0x00]);
}

#[test]
fn read_back() {
    let image = odc_sii::write(&device(ESI)).unwrap();
    let sii = odc_sii::read(&image).unwrap();
    assert!(sii.info.checksum_ok);
    assert_eq!(sii.info.product_code, 0x1234_5678);
    assert_eq!(sii.info.eeprom_bytes(), 2048);
    assert_eq!(sii.sync_managers.len(), 4);
    assert_eq!(sii.fmmus, [1, 2, 3]);
    assert_eq!(sii.rx_pdos.len(), 1);
    assert_eq!(sii.tx_pdos.iter().map(|p| p.index).collect::<Vec<_>>(), [0x1A00, 0x1A01]);
    assert_eq!(sii.tx_pdos[0].entries[1].bits, 32);
    assert_eq!(sii.dc[0].assign_activate, 0x300);
    let kinds: Vec<u16> = sii.categories.iter().map(|c| c.kind).collect();
    assert_eq!(kinds, [10, 30, 40, 41, 50, 51, 60, 1]);
}

#[test]
fn bad_parts() {
    let long = ESI.replace("080C0E0C8813", "080C0E0C88130000000000000000000000");
    assert!(matches!(odc_sii::write(&device(&long)), Err(odc_sii::Error::Input { .. })));
    let boot = ESI.replace("0010F400F410F400", "0010F400");
    let err = odc_sii::write(&device(&boot)).unwrap_err();
    assert!(err.to_string().contains("BootStrap"), "{err}");
    // 0xFFFF is the end marker, not a category.
    let end = ESI.replace("<CatNo>1</CatNo>", "<CatNo>65535</CatNo>");
    assert!(matches!(odc_sii::write(&device(&end)), Err(odc_sii::Error::Input { .. })));
}

// Sizes of the fixture's image, counted by hand from ETG.2010's layouts (category header 4
// bytes, data padded to a word):
//   info area 128; strings: 11 texts (SV1-A, Servo drive, Drives, Inputs, Statusword,
//   Position, Spare, Outputs, Controlword, DC, DC-Synchron), 1 + 93 = 94 bytes -> 98;
//   General 4 + 32 = 36; FMMU 3 + 1 pad -> 8; SyncManager 4 x 8 -> 36; TxPDO 0x1A00 8 + 2 x 8,
//   0x1A01 8 -> 36; RxPDO 8 + 2 x 8 -> 28; DC 24 -> 28; vendor category 1: 5 + 1 pad -> 10;
//   end marker 2. Total 410.
const FULL: usize = 410;

#[test]
fn what_does_not_fit_is_left_out_in_order() {
    // 256 bytes: entry names (Statusword, Position, Controlword: -32 -> 378), other names
    // (Inputs, Spare, Outputs, DC, DC-Synchron: -36 -> 342), DC (-28 -> 314), FMMU (-8 -> 306),
    // PDOs (-64 -> 242) go; General and SyncManager stay.
    let small = ESI.replace("<ByteSize>2048", "<ByteSize>256");
    let (image, notes) = odc_sii::write_with_notes(&device(&small)).unwrap();
    assert_eq!(image.len(), 256);
    use odc_sii::Omission::*;
    assert_eq!(
        notes,
        [odc_sii::Note::LeftOut {
            full: FULL,
            byte_size: 256,
            omitted: vec![(EntryNames, 3), (OtherNames, 5), (Dc, 1), (Fmmu, 3), (Pdos, 3)]
        }]
    );
    // Strings: 3 texts, 1 + 6 + 12 + 7 = 26 bytes = 13 words; the order code first.
    let mut strings = vec![10, 0, 13, 0, 3, 5];
    strings.extend_from_slice(b"SV1-A\x0bServo drive\x06Drives");
    assert_eq!(&image[128..158], &strings[..]);
    // General: 16 words; group 3, image 0, order 1, name 2.
    assert_eq!(&image[158..166], [30, 0, 16, 0, 3, 0, 1, 2]);
    // SyncManager: 16 words, SM0 as in `categories`.
    assert_eq!(&image[194..206], [41, 0, 16, 0, 0x00, 0x10, 128, 0, 0x26, 0, 0x01, 1]);
    // The ESI's category 1 (3 words), the end marker, then erased bytes.
    assert_eq!(&image[230..242], [1, 0, 3, 0, 0x5C, 0x12, 0x05, 0x00, 0xFF, 0x00, 0xFF, 0xFF]);
    assert!(image[242..].iter().all(|&b| b == 0xFF));
    assert_eq!(word(&image, 0x3E), 1, "256 bytes = 2 KiBit");
    let text = notes[0].to_string();
    assert!(
        text.contains("needs 410 bytes") && text.contains("the names of 3 PDO entries"),
        "{text}"
    );
}

#[test]
fn what_is_left_must_fit_or_the_image_is_refused() {
    // 128 bytes: General (-36, strings -30) and SyncManager (-36) go too, down to 140 bytes:
    // the info area, the ESI's own category (10) and the end marker do not fit.
    let tiny = ESI.replace("<ByteSize>2048", "<ByteSize>128");
    let err = odc_sii::write(&device(&tiny)).unwrap_err();
    assert!(
        matches!(err, odc_sii::Error::DoesNotFit { needed: 140, full: FULL, byte_size: 128, .. }),
        "{err:?}"
    );
    assert!(err.span().is_some(), "points at ByteSize");
    // Without the vendor category: the info area alone, as a 1 KiBit EEPROM holds it (no
    // room for the end marker).
    let start = tiny.find("<Category>").unwrap();
    let end = tiny.find("</Category>").unwrap() + "</Category>".len();
    let bare = format!("{}{}", &tiny[..start], &tiny[end..]);
    let (image, notes) = odc_sii::write_with_notes(&device(&bare)).unwrap();
    assert_eq!(image.len(), 128);
    assert_eq!(word(&image, 0x3E), 0, "1 KiBit");
    assert_eq!(dword(&image, 0xA), 0x1234_5678, "identity kept");
    let odc_sii::Note::LeftOut { omitted, .. } = &notes[0] else { panic!("{notes:?}") };
    let steps: Vec<_> = omitted.iter().map(|(o, _)| *o).collect();
    assert_eq!(steps, odc_sii::Omission::ORDER);
    let sii = odc_sii::read(&image).unwrap();
    assert!(sii.categories.is_empty());
    // Below the info area: refused.
    let below = ESI.replace("<ByteSize>2048", "<ByteSize>64");
    assert!(matches!(odc_sii::write(&device(&below)), Err(odc_sii::Error::DoesNotFit { .. })));
}

#[test]
fn grow_leaves_nothing_out() {
    let small = ESI.replace("<ByteSize>2048", "<ByteSize>256");
    let options = odc_sii::Options::default().fit(odc_sii::Fit::Grow);
    let (image, notes) = odc_sii::write_with(&device(&small), &options).unwrap();
    // 410 bytes: the next power of two is 512 = 4 KiBit.
    assert_eq!(image.len(), 512);
    assert_eq!(word(&image, 0x3E), 3);
    assert_eq!(notes, [odc_sii::Note::Grown { byte_size: 256, size: 512 }]);
    assert_eq!(image[FULL - 2..FULL], [0xFF, 0xFF], "end marker right after the content");
    let kinds: Vec<u16> =
        odc_sii::read(&image).unwrap().categories.iter().map(|c| c.kind).collect();
    assert_eq!(kinds, [10, 30, 40, 41, 50, 51, 60, 1]);
    // Content that fits is written at ByteSize, grow or not.
    let (image, notes) = odc_sii::write_with(&device(ESI), &options).unwrap();
    assert_eq!((image.len(), notes.len()), (2048, 0));
}

#[test]
fn the_esis_own_standard_categories_replace_the_generated_ones() {
    // kickcat's test ESI gives a General category of the text "BootCfg" (7 bytes).
    let general = ESI.replace(
        "<Category><CatNo>1</CatNo><Data>5C120500FF</Data></Category>",
        "<Category><CatNo>30</CatNo><DataString>BootCfg</DataString></Category>\
         <Category><CatNo>1</CatNo><Data>5C120500FF</Data></Category>",
    );
    let (image, notes) = odc_sii::write_with_notes(&device(&general)).unwrap();
    assert_eq!(category(&image, 30).unwrap(), b"BootCfg\0", "as given, padded to a word");
    let sii = odc_sii::read(&image).unwrap();
    let kinds: Vec<u16> = sii.categories.iter().map(|c| c.kind).collect();
    assert_eq!(kinds, [10, 30, 40, 41, 50, 51, 60, 1], "in the General category's place");
    // Of the generated General's strings only the order code is made, string 1 (SOEM's name).
    assert_eq!(sii.strings[..2], ["SV1-A", "Inputs"]);
    assert!(matches!(
        &notes[..],
        [odc_sii::Note::EsiCategory { cat_no: 30, bytes: 7, odd: Some(_) }]
    ));
    // The ESI's own strings: generated categories name none (index 0).
    let strings =
        ESI.replace("<CatNo>1</CatNo><Data>5C120500FF", "<CatNo>10</CatNo><Data>0101410000");
    let (image, notes) = odc_sii::write_with_notes(&device(&strings)).unwrap();
    assert_eq!(category(&image, 10).unwrap(), [0x01, 0x01, 0x41, 0x00, 0x00, 0x00]);
    let g = category(&image, 30).unwrap();
    assert_eq!(&g[..4], [0, 0, 0, 0]);
    assert_eq!(category(&image, 51).unwrap()[5], 0, "no PDO name index");
    assert!(matches!(&notes[..], [odc_sii::Note::EsiCategory { cat_no: 10, odd: None, .. }]));
}

#[test]
fn checksum_given_by_the_esi() {
    // 14 bytes of ConfigData and a wrong checksum: the computed one is written, with a note.
    let given = ESI.replace("080C0E0C8813", "080C0E0C88130000000000000000AA00");
    let (image, notes) = odc_sii::write_with_notes(&device(&given)).unwrap();
    assert_eq!(image[14], odc_sii::crc8(&image[..14]));
    assert!(matches!(notes[..], [odc_sii::Note::ChecksumDiffers { given: 0xAA, .. }]), "{notes:?}");
}

#[test]
fn malformed_images_are_errors() {
    let image = odc_sii::write(&device(ESI)).unwrap();
    assert!(odc_sii::read(&image[..100]).is_err());
    let mut cut = image.clone();
    // The strings category claims more words than the image has.
    cut[130] = 0xFF;
    cut[131] = 0x7F;
    assert!(odc_sii::read(&cut).is_err());
    let mut no_end = image[..200].to_vec();
    no_end.truncate(200);
    assert!(odc_sii::read(&no_end).is_err());
}

#[test]
fn unknown_usages_and_sync1_cycle_time_are_noted() {
    let odd = ESI
        .replace("<Fmmu>MBoxState</Fmmu>", "<Fmmu>OrbitaState</Fmmu>")
        .replace("<CycleTimeSync1 Factor=\"-2\">0<", "<CycleTimeSync1 Factor=\"-2\">1000<");
    let (image, notes) = odc_sii::write_with_notes(&device(&odd)).unwrap();
    assert_eq!(category(&image, 40).unwrap(), [1, 2, 0, 0xFF]);
    assert!(notes.contains(&odc_sii::Note::UnknownUsage {
        element: "Fmmu",
        number: 2,
        text: "OrbitaState".into()
    }));
    assert!(
        notes.contains(&odc_sii::Note::Sync1CycleTimeDropped { op_mode: "DC".into(), value: 1000 }),
        "{notes:?}"
    );
    let (_, notes) = odc_sii::write_with_notes(&device(ESI)).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
}

#[test]
fn a_whole_image_in_the_esi_is_taken_as_it_is() {
    // ETG.2000 `EepromType`: `Data` (the whole image) instead of ByteSize/ConfigData/...
    let mut whole = vec![0u8; 128];
    whole[0x7E] = 1;
    whole.extend_from_slice(&[0xFF, 0xFF]);
    let hex: String = whole.iter().map(|b| format!("{b:02X}")).collect();
    let start = ESI.find("<Eeprom>").unwrap();
    let end = ESI.find("</Eeprom>").unwrap();
    let given = format!("{}<Eeprom><Data>{hex}</Data>{}", &ESI[..start], &ESI[end..]);
    let dev = device(&given);
    assert_eq!(odc_sii::write(&dev).unwrap(), whole);
    // Built from the description instead: the identity the ESI's `Type` gives.
    let (built, _) = odc_sii::write_from_description(&dev).unwrap();
    assert_eq!(odc_sii::read(&built).unwrap().info.product_code, 0x1234_5678);
    let short = given.replace(&hex, "0011");
    assert!(odc_sii::write(&device(&short)).is_err());
}
