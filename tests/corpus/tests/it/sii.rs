//! SII images (ETG.2010) of every device of every corpus ESI file (`odc_sii::write`), checked
//! without the writer's help: the ESI's `ConfigData`, `BootStrap` and vendor categories at their
//! places (byte offsets from ETG.2010), the checksum by a CRC-8 written here from the standard's
//! definition, and the image read back against the ESI's identity, mailbox, SMs and PDOs.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::BTreeMap;

use odc_model::ethercat::{EtherCat, SmUsage};
use odc_model::{Device, Direction, Sources};
use odc_sii::{Note, Omission};

/// ETG.2010: CRC-8 of words 0–6, generator x⁸ + x² + x + 1, register preset to 0xFF, bits fed
/// most significant first, no final inversion. Done as polynomial long division on the message
/// bits, one bit at a time.
fn crc8_etg(bytes: &[u8]) -> u8 {
    let mut reg: u16 = 0xFF;
    for &b in bytes {
        for bit in (0..8).rev() {
            let top = (reg >> 7) & 1;
            let input = u16::from((b >> bit) & 1);
            reg = (reg << 1) & 0xFF;
            if top ^ input == 1 {
                reg ^= 0x07;
            }
        }
    }
    reg as u8
}

/// The categories of an image, walked here: (type, data).
fn walk(image: &[u8]) -> Vec<(u16, &[u8])> {
    let mut out = Vec::new();
    let mut at = 128;
    while at + 2 <= image.len() {
        let t = u16::from_le_bytes([image[at], image[at + 1]]);
        if t == 0xFFFF {
            break;
        }
        let len = 2 * usize::from(u16::from_le_bytes([image[at + 2], image[at + 3]]));
        out.push((t, &image[at + 4..at + 4 + len]));
        at += 4 + len;
    }
    out
}

#[derive(Default)]
struct Tally {
    checks: BTreeMap<&'static str, (usize, usize)>,
    mismatches: Vec<String>,
}

impl Tally {
    fn check(&mut self, what: &'static str, ok: bool, context: impl FnOnce() -> String) {
        let e = self.checks.entry(what).or_default();
        if ok {
            e.0 += 1;
        } else {
            e.1 += 1;
            if self.mismatches.len() < 40 {
                self.mismatches.push(format!("{what}: {}", context()));
            }
        }
    }
}

fn sm_type(u: &SmUsage) -> u8 {
    match u {
        SmUsage::MBoxOut => 1,
        SmUsage::MBoxIn => 2,
        SmUsage::Outputs => 3,
        SmUsage::Inputs => 4,
        _ => 0,
    }
}

/// What a written image leaves out or takes from the ESI as given, from its notes.
#[derive(Default)]
struct Written {
    left_out: Vec<Omission>,
    esi_categories: Vec<u16>,
}

impl Written {
    fn from(notes: &[Note]) -> Written {
        let mut w = Written::default();
        for n in notes {
            match n {
                Note::LeftOut { omitted, .. } => {
                    w.left_out = omitted.iter().map(|(o, _)| *o).collect()
                }
                Note::EsiCategory { cat_no, .. } => w.esi_categories.push(*cat_no),
                _ => {}
            }
        }
        w
    }

    /// Whether the generated category of `kind` is in the image (neither left out nor
    /// replaced by the ESI's own).
    fn generated(&self, kind: u16, omission: Omission) -> bool {
        !self.left_out.contains(&omission) && !self.esi_categories.contains(&kind)
    }
}

fn check_device(dev: &Device, ec: &EtherCat, image: &[u8], w: &Written, t: &mut Tally, who: &str) {
    let ee = ec.eeprom.as_ref();
    if let Some(ee) = ee.filter(|e| e.data.is_empty() || !e.config_data.is_empty()) {
        if !ee.config_data.is_empty() {
            let n = ee.config_data.len().min(14);
            t.check("ConfigData at bytes 0..", image[..n] == ee.config_data[..n], || who.into());
        }
        if !ee.boot_strap.is_empty() {
            t.check("BootStrap at words 0x14-0x17", image[0x28..0x30] == ee.boot_strap[..], || {
                who.into()
            });
        }
        let cats = walk(image);
        for c in &ee.categories {
            let found = cats.iter().any(|(kind, data)| {
                *kind == c.cat_no
                    && data.len() == c.data.len().div_ceil(2) * 2
                    && data[..c.data.len()] == c.data[..]
            });
            t.check("vendor category verbatim", found, || format!("{who}: CatNo {}", c.cat_no));
        }
        if let Some(size) = ee.byte_size {
            t.check("image length = ByteSize", image.len() == size as usize, || who.into());
        }
    }
    t.check("checksum (CRC-8 of words 0-6) at word 7", image[14] == crc8_etg(&image[..14]), || {
        who.into()
    });

    let sii = match odc_sii::read(image) {
        Ok(s) => s,
        Err(e) => {
            t.check("image reads back", false, || format!("{who}: {e}"));
            return;
        }
    };
    t.check("image reads back", true, String::new);
    let i = &sii.info;
    let identity = (i.vendor_id, i.product_code, i.revision, i.serial)
        == (
            ec.vendor_id.unwrap_or(0),
            ec.product_code.unwrap_or(0),
            ec.revision.unwrap_or(0),
            ec.serial_no.unwrap_or(0),
        );
    t.check("identity", identity, || who.into());
    // The standard mailbox: the SMs the ESI marks MBoxOut (master -> device) and MBoxIn.
    let mbox = |u: SmUsage| {
        ec.sync_managers.iter().find(|s| s.usage == u).map_or((0, 0), |s| {
            (
                s.start_address.as_deref().copied().unwrap_or(0),
                s.default_size.or(s.min_size).unwrap_or(0) as u16,
            )
        })
    };
    let std_mbox = (i.standard.receive_offset, i.standard.receive_size) == mbox(SmUsage::MBoxOut)
        && (i.standard.send_offset, i.standard.send_size) == mbox(SmUsage::MBoxIn);
    t.check("standard mailbox", std_mbox, || who.into());
    let mb = ec.mailbox.clone().unwrap_or_default();
    let protocols = [
        (0x01, mb.aoe),
        (0x02, mb.eoe),
        (0x04, mb.coe.is_some()),
        (0x08, mb.foe),
        (0x10, mb.soe.is_some()),
        (0x20, mb.voe),
    ]
    .iter()
    .all(|&(bit, on)| (i.mailbox_protocols & bit != 0) == on);
    t.check("mailbox protocols", protocols, || who.into());
    if !w.generated(41, Omission::SyncManagers) {
        return;
    }
    let sms = sii.sync_managers.len() == ec.sync_managers.len()
        && sii.sync_managers.iter().zip(&ec.sync_managers).all(|(s, e)| {
            s.start_address == e.start_address.as_deref().copied().unwrap_or(0)
                && s.control == e.control_byte.as_deref().copied().unwrap_or(0)
                && s.kind == sm_type(&e.usage)
                && (s.enable & 1 == 1) == e.enable
                && u32::from(s.length) == e.default_size.unwrap_or(0)
        });
    t.check("sync managers", sms, || who.into());
    let names = !w.left_out.contains(&Omission::OtherNames) && !w.esi_categories.contains(&10);
    for (dir, kind, got) in [(Direction::Tx, 50, &sii.tx_pdos), (Direction::Rx, 51, &sii.rx_pdos)] {
        if !w.generated(kind, Omission::Pdos) {
            continue;
        }
        let want: Vec<_> = dev.pdos.iter().filter(|p| p.direction == dir).collect();
        let same = got.len() == want.len()
            && got.iter().zip(&want).all(|(g, p)| {
                g.index == p.mapping_index
                    && g.sync_manager == p.sync_manager.unwrap_or(0xFF)
                    && (!names || sii.string(g.name).unwrap_or("") == p.name.trim())
                    && g.entries.len() == p.entries.len()
                    && g.entries.iter().zip(&p.entries).all(|(a, b)| {
                        a.index == b.index && a.sub == b.sub && u16::from(a.bits) == b.bits
                    })
            });
        t.check("PDOs (index, SM, name, entries)", same, || format!("{who} {dir:?}"));
    }
}

/// Compares odc's image with a whole image the ESI gives (`Eeprom/Data`), word by word over the
/// info area: (agreeing words, differing words with their values).
fn compare_with_esi_image(odc: &[u8], esi: &[u8]) -> (usize, Vec<String>) {
    let (mut same, mut diff) = (0, Vec::new());
    for w in 0..64 {
        let a = odc.get(2 * w..2 * w + 2);
        let b = esi.get(2 * w..2 * w + 2);
        if a == b {
            same += 1;
        } else {
            diff.push(format!("word 0x{w:02X}: odc {a:02X?} ESI {b:02X?}"));
        }
    }
    (same, diff)
}

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn corpus_sii_images() {
    let dir = odc_tests_corpus::dir();
    let (mut devices, mut with_eeprom_parts, mut checked) = (0, 0, 0);
    // The outcome of every ESI device: an image as described, one with optional parts left
    // out (which), or none (why).
    let (mut whole, mut fits, mut grown_elsewhere) = (0, 0, 0);
    let mut omitted = BTreeMap::<String, usize>::new();
    let mut by_last_step = BTreeMap::<String, Vec<String>>::new();
    let mut pdos_without_coe = 0;
    let mut esi_standard = BTreeMap::<u16, usize>::new();
    let mut failures = BTreeMap::<String, Vec<String>>::new();
    let mut tally = Tally::default();
    let mut whole_images = Vec::new();
    let mut notes = BTreeMap::<String, usize>::new();
    for f in odc_tests_corpus::files(&["esi"]) {
        let bytes = std::fs::read(dir.join(&f)).unwrap();
        let parsed = odc_esi::parse(&mut Sources::new(), &f, &bytes);
        for (n, dev) in parsed.devices.iter().enumerate() {
            let Some(ec) = dev.ethercat.as_deref() else { continue };
            devices += 1;
            let who = format!("{f} #{n} ({})", dev.name());
            let ee = ec.eeprom.as_ref();
            let carries = ee.is_some_and(|e| {
                !e.config_data.is_empty() || !e.boot_strap.is_empty() || !e.categories.is_empty()
            });
            with_eeprom_parts += usize::from(carries);
            let gives_whole = ee.is_some_and(|e| !e.data.is_empty() && e.config_data.is_empty());
            match odc_sii::write_with_notes(dev) {
                Ok((image, image_notes)) => {
                    for n in &image_notes {
                        let kind = format!("{n:?}");
                        let kind = kind.split([' ', '(', '{']).next().unwrap_or("").to_string();
                        *notes.entry(kind).or_default() += 1;
                    }
                    let written = Written::from(&image_notes);
                    for c in &written.esi_categories {
                        *esi_standard.entry(*c).or_default() += 1;
                    }
                    if gives_whole {
                        whole += 1;
                    } else if written.left_out.is_empty() {
                        fits += 1;
                    } else {
                        for o in &written.left_out {
                            *omitted.entry(format!("{o:?}")).or_default() += 1;
                        }
                        let last = written.left_out.last().map(|o| format!("{o:?}"));
                        by_last_step.entry(last.unwrap_or_default()).or_default().push(who.clone());
                        let coe = ec.mailbox.as_ref().is_some_and(|m| m.coe.is_some());
                        pdos_without_coe +=
                            usize::from(written.left_out.contains(&Omission::Pdos) && !coe);
                    }
                    if carries {
                        checked += 1;
                    }
                    check_device(dev, ec, &image, &written, &mut tally, &who);
                    // The ESI's own whole image against odc's, built from the description.
                    if let Some(data) = ee.map(|e| &e.data).filter(|d| !d.is_empty())
                        && let Ok((built, _)) = odc_sii::write_from_description(dev)
                    {
                        whole_images.push((who, compare_with_esi_image(&built, data)));
                    }
                }
                Err(e) => {
                    let reason = match &e {
                        odc_sii::Error::DoesNotFit { byte_size, .. } => {
                            // With a larger EEPROM allowed (`odc sii --grow`, `-W S701`).
                            let grow = odc_sii::Options::default().fit(odc_sii::Fit::Grow);
                            grown_elsewhere += usize::from(odc_sii::write_with(dev, &grow).is_ok());
                            format!(
                                "S701: larger than ByteSize {byte_size} with every optional part left out"
                            )
                        }
                        other => other.to_string(),
                    };
                    failures.entry(reason).or_default().push(who);
                }
            }
        }
    }
    let refused: usize = failures.values().map(Vec::len).sum();
    let with_omissions: usize = by_last_step.values().map(Vec::len).sum();
    eprintln!(
        "{devices} ESI devices: {} with an SII image ({fits} as described, {with_omissions} with \
         optional parts left out, {whole} the ESI's whole Eeprom/Data), {refused} refused \
         ({grown_elsewhere} of them written for a larger EEPROM with --grow)",
        fits + with_omissions + whole
    );
    eprintln!("  left out, devices per step: {omitted:?}");
    for (step, who) in &by_last_step {
        eprintln!("  left out up to {step}: {} devices, e.g. {}", who.len(), who[0]);
    }
    eprintln!("  PDO categories left out of {pdos_without_coe} devices without CoE");
    eprintln!(
        "  the ESI's own standard categories written as given (CatNo: devices): {esi_standard:?}"
    );
    eprintln!(
        "  {with_eeprom_parts} carry ConfigData/BootStrap/categories, {checked} of them with an image"
    );
    for (reason, who) in &failures {
        eprintln!("  refused ({} devices): {reason}; e.g. {}", who.len(), who[0]);
    }
    for (what, (ok, bad)) in &tally.checks {
        eprintln!("  {what}: {ok} agree, {bad} differ");
    }
    eprintln!("notes on the images written: {notes:?}");
    eprintln!("{} devices give a whole Eeprom/Data image", whole_images.len());
    for (who, (same, diff)) in &whole_images {
        eprintln!("  {who}: {same}/64 info-area words agree; {}", diff.join("; "));
    }
    assert!(tally.mismatches.is_empty(), "{:#?}", tally.mismatches);
    assert!(fits + with_omissions > 0);
    // A device gets no image only for a reason the ESI itself gives (its own categories
    // larger than the EEPROM it declares, or a part that does not fit its SII field).
    for reason in failures.keys() {
        assert!(
            reason.starts_with("S701") || reason.contains('`'),
            "unexpected failure kind: {reason}"
        );
    }
}

/// A value siitool prints as `Label: ...... 0x1234` (the `nth` such line).
fn siitool_value(text: &str, label: &str, nth: usize) -> Option<u32> {
    let line = text.lines().filter(|l| l.trim_start().starts_with(label)).nth(nth)?;
    let v = line.rsplit(' ').next()?;
    match v.strip_prefix("0x") {
        Some(hex) => u32::from_str_radix(hex, 16).ok(),
        None => v.parse().ok(),
    }
}

/// siitool (synapticon, C; build it from github.com/synapticon/siitool and point ODC_SIITOOL at
/// the binary) reads odc's images of every 25th corpus device with an image and of every
/// device whose image left out optional parts: its checksum verdict, identity, standard
/// mailbox, EEPROM size and the standard categories it finds, in order, must be the ESI's and
/// the image's. (An image of the info area alone, a 128-byte EEPROM, has no category list:
/// siitool reads zeros past the file's end there, so its categories are not compared.)
#[test]
#[ignore = "needs siitool: build it, set ODC_SIITOOL to the binary and ODC_CORPUS, run with --ignored"]
fn siitool_reads_odc_images() {
    let tool = std::env::var_os("ODC_SIITOOL").expect("ODC_SIITOOL: path of the siitool binary");
    let dir = odc_tests_corpus::dir();
    let tmp = std::env::temp_dir().join(format!("odc-sii-{}.bin", std::process::id()));
    let (mut n, mut read, mut fitted) = (0usize, 0usize, 0usize);
    let mut problems = Vec::new();
    for f in odc_tests_corpus::files(&["esi"]) {
        let bytes = std::fs::read(dir.join(&f)).unwrap();
        let parsed = odc_esi::parse(&mut Sources::new(), &f, &bytes);
        for dev in &parsed.devices {
            let Ok((image, notes)) = odc_sii::write_with_notes(dev) else { continue };
            n += 1;
            let left_out = !Written::from(&notes).left_out.is_empty();
            if n % 25 != 1 && !left_out {
                continue;
            }
            fitted += usize::from(left_out);
            let ec = dev.ethercat.as_deref().unwrap();
            std::fs::write(&tmp, &image).unwrap();
            let out = std::process::Command::new(&tool).arg("-p").arg(&tmp).output().unwrap();
            let text = String::from_utf8_lossy(&out.stdout);
            read += 1;
            let mbox = ec.sync_managers.iter().find(|s| s.usage == SmUsage::MBoxOut);
            let want = [
                ("Vendor ID", 0, ec.vendor_id.unwrap_or(0)),
                ("Product ID", 0, ec.product_code.unwrap_or(0)),
                ("Revision ID", 0, ec.revision.unwrap_or(0)),
                (
                    "Received Mailbox Offset",
                    1,
                    mbox.and_then(|s| s.start_address.as_deref().copied()).map_or(0, u32::from),
                ),
            ];
            for (label, nth, value) in want {
                if siitool_value(&text, label, nth) != Some(value) {
                    problems.push(format!(
                        "{f} {}: {label} siitool {:?}, ESI {value:#x}",
                        dev.name(),
                        siitool_value(&text, label, nth)
                    ));
                }
            }
            if !text.lines().any(|l| l.contains("Checksum of Preamble") && l.contains("(ok)")) {
                problems.push(format!("{f} {}: siitool does not find the checksum ok", dev.name()));
            }
            let size = format!("EEPROM size: ................ {} bytes", image.len());
            if !text.contains(&size) {
                problems.push(format!("{f} {}: siitool does not say `{size}`", dev.name()));
            }
            if image.len() > 128 {
                // `Print Categorie: SyncManager (0x29)`: the standard types siitool knows.
                let found: Vec<u16> = text
                    .lines()
                    .filter_map(|l| l.strip_prefix("Print Categorie: "))
                    .filter_map(|l| l.rsplit_once("(0x")?.1.strip_suffix(')'))
                    .filter_map(|h| u16::from_str_radix(h, 16).ok())
                    .collect();
                let standard = [10, 20, 30, 40, 41, 50, 51, 60];
                let written: Vec<u16> = walk(&image)
                    .into_iter()
                    .map(|(kind, _)| kind)
                    .filter(|kind| standard.contains(kind))
                    .collect();
                if found != written {
                    problems.push(format!(
                        "{f} {}: siitool finds categories {found:?}, the image has {written:?}",
                        dev.name()
                    ));
                }
            }
        }
    }
    let _ = std::fs::remove_file(&tmp);
    eprintln!(
        "siitool read {read} of odc's {n} corpus images ({fitted} with parts left out); {} problems",
        problems.len()
    );
    assert!(read > 0);
    assert!(problems.is_empty(), "{problems:#?}");
}
