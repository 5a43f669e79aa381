//! The default process image of every device of every corpus ESI file (`odc_analysis::image`):
//! computed for each, its sync-manager lengths against the ESI's `Sm@DefaultSize`, and every
//! entry's bit offset against an independent computation (`etg2000_offsets`, below).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::BTreeMap;

use odc_analysis::image::{self, Image};
use odc_model::ethercat::SmUsage;
use odc_model::{Device, Direction, Sources, Value};

/// Bit offsets of the default process data, computed from ETG.2000 alone (not from
/// `odc_analysis::image` nor `odc-layout`): a PDO's `Sm` attribute is the sync manager it is
/// assigned to by default (ETG.2000 `PdoType@Sm`); a master appends the
/// sync managers of one direction in ascending number, and in each the PDOs in the order the
/// ESI lists them and their entries one after another with their `BitLen` (padding entries,
/// index 0, take their length too); a sync manager's length is whole bytes (ETG.1000.4:
/// the length register, 0x0802 for SM0, counts bytes). A sync manager marked `Virtual` (ETG.2000
/// `Sm@Virtual`) is no sync manager of the ESC and carries no segment. Of two PDOs that
/// `Exclude` each other only the one listed first is assigned. Keyed by (direction,
/// PDO index, entry number).
fn etg2000_offsets(dev: &Device) -> BTreeMap<(bool, u16, usize), u32> {
    let mut out = BTreeMap::new();
    let ec = dev.ethercat.as_ref().unwrap();
    let virtual_sm = |n: u8| ec.sync_managers.iter().any(|s| s.number == n && s.virtual_sm);
    // The PDOs a master assigns by default: `Sm` given, not excluded by an earlier one.
    let mut assigned: Vec<&odc_model::Pdo> = Vec::new();
    for p in dev.pdos.iter().filter(|p| p.sync_manager.is_some()) {
        let excluded = assigned.iter().any(|a| {
            a.excludes.contains(&p.mapping_index) || p.excludes.contains(&a.mapping_index)
        });
        if !excluded {
            assigned.push(p);
        }
    }
    for rx in [true, false] {
        let mut sms: Vec<u8> = assigned
            .iter()
            .filter(|p| (p.direction == Direction::Rx) == rx)
            .filter_map(|p| p.sync_manager)
            .filter(|&n| !virtual_sm(n))
            .collect();
        sms.sort_unstable();
        sms.dedup();
        let mut start = 0u32;
        for sm in sms {
            let mut bit = start;
            for p in assigned.iter().filter(|p| (p.direction == Direction::Rx) == rx) {
                if p.sync_manager != Some(sm) {
                    continue;
                }
                for (i, e) in p.entries.iter().enumerate() {
                    out.insert((rx, p.mapping_index, i), bit);
                    bit += u32::from(e.bits);
                }
            }
            // Round the sync manager up to a byte boundary.
            start = bit.div_ceil(8) * 8;
        }
    }
    out
}

/// The dictionary's default assignment of sync manager `sm` (0x1C10 + sm, sub-index 0 the
/// count, 1.. the PDO indexes), when the ESI gives every value: what a device starts with.
fn dictionary_assignment(dev: &Device, sm: u8) -> Option<Vec<u16>> {
    let object = dev.objects.get(&(0x1C10 + u16::from(sm)))?;
    let number = |sub: u8| match &object.sub(sub)?.initial_value()?.value {
        Value::Unsigned(v) => Some(*v),
        Value::Signed(v) => u64::try_from(*v).ok(),
        _ => None,
    };
    let count = number(0)?;
    (1..=count).map(|i| number(u8::try_from(i).ok()?).and_then(|v| u16::try_from(v).ok())).collect()
}

fn placed(dev: &Device, img: &Image) -> BTreeMap<(bool, u16, usize), u32> {
    let rx = img.direction == Direction::Rx;
    img.segments
        .iter()
        .flat_map(|s| s.entries.iter())
        .map(|p| ((rx, dev.pdos[p.pdo].mapping_index, p.entry), p.range.offset))
        .collect()
}

#[test]
#[cfg_attr(
    odc_no_corpus,
    ignore = "needs the real-world corpus: set ODC_CORPUS to its directory (README, Tests)"
)]
fn corpus_default_process_images() {
    let dir = odc_tests_corpus::dir();
    let files = odc_tests_corpus::files(&["esi"]);
    let (mut devices, mut with_image, mut nonempty, mut entries) = (0usize, 0, 0, 0usize);
    let (mut size_agree, mut size_disagree) = (0usize, 0usize);
    let mut size_kinds = BTreeMap::<&str, usize>::new();
    let (mut dict_agree, mut dict_disagree) = (0usize, Vec::new());
    let (mut offset_agree, mut offset_disagree) = (0usize, Vec::new());
    let mut mandatory_only = 0usize;
    let (mut variant_images, mut variant_failures) = (0usize, Vec::new());
    let mut skipped_reasons = BTreeMap::<String, usize>::new();
    let mut failures = Vec::new();
    let mut disagreements = Vec::new();
    for f in &files {
        let bytes = std::fs::read(dir.join(f)).unwrap();
        let mut sources = Sources::new();
        let parsed = odc_esi::parse(&mut sources, f, &bytes);
        for dev in &parsed.devices {
            devices += 1;
            let (outputs, inputs) = match image::default_images(dev) {
                Ok(i) => i,
                Err(e) => {
                    failures.push(format!("{f} {}: {e:?}", dev.name()));
                    continue;
                }
            };
            with_image += 1;
            if !outputs.is_empty() || !inputs.is_empty() {
                nonempty += 1;
            }
            let (variants, skipped) = image::variants(dev);
            for v in &variants {
                let rx = image::image(dev, &v.assignment, Direction::Rx);
                let tx = image::image(dev, &v.assignment, Direction::Tx);
                match (rx, tx) {
                    (Ok(_), Ok(_)) => variant_images += 1,
                    (r, t) => variant_failures.push(format!(
                        "{f} {} `{}`: {:?} {:?}",
                        dev.name(),
                        v.name,
                        r.err(),
                        t.err()
                    )),
                }
            }
            for s in skipped {
                // The reason without its numbers and names: "PDO 0x1A01 is oversampled 2
                // times" counts as "oversampled".
                let kind = ["oversampled", "not declared", "virtual", "as the default", "as `"]
                    .into_iter()
                    .find(|k| s.reason.contains(k))
                    .unwrap_or(&s.reason)
                    .to_string();
                *skipped_reasons.entry(kind).or_default() += 1;
            }
            let reference = etg2000_offsets(dev);
            let mut mine = placed(dev, &outputs);
            mine.extend(placed(dev, &inputs));
            entries += mine.len();
            // Entries only `Mandatory` assigns (no `Sm`): the reference does not know them.
            let extra = mine.keys().filter(|k| !reference.contains_key(k)).count();
            if extra > 0 {
                mandatory_only += 1;
            }
            for (k, bit) in &reference {
                match mine.get(k) {
                    Some(b) if b == bit => offset_agree += 1,
                    other => offset_disagree.push(format!(
                        "{f} {}: PDO {:#06x} entry {}: reference bit {bit}, image {other:?}",
                        dev.name(),
                        k.1,
                        k.2
                    )),
                }
            }
            let ec = dev.ethercat.as_ref().unwrap();
            for sm in &ec.sync_managers {
                let img = match sm.usage {
                    SmUsage::Outputs => &outputs,
                    SmUsage::Inputs => &inputs,
                    _ => continue,
                };
                if !sm.virtual_sm {
                    let assigned = image::default_assignment(dev).remove(&sm.number);
                    if let Some(dict) = dictionary_assignment(dev, sm.number) {
                        if assigned.clone().unwrap_or_default() == dict {
                            dict_agree += 1;
                        } else {
                            let assign = ec
                                .mailbox
                                .as_ref()
                                .and_then(|m| m.coe.as_ref())
                                .is_some_and(|c| c.pdo_assign);
                            dict_disagree.push(format!(
                                "{f} {}: SM{} 0x1C1x default {dict:04X?}, Sm attributes {:04X?}{}",
                                dev.name(),
                                sm.number,
                                assigned.unwrap_or_default(),
                                if assign { "" } else { " (no PdoAssign)" }
                            ));
                        }
                    }
                }
                let Some(default) = sm.default_size.filter(|_| !sm.virtual_sm) else { continue };
                let bytes = img.segments.iter().find(|s| s.sm == sm.number).map_or(0, |s| s.bytes);
                if bytes == default {
                    size_agree += 1;
                } else {
                    size_disagree += 1;
                    // Who sides with whom: the ESI's own 0x1C1x defaults, where it gives them.
                    let assigned =
                        image::default_assignment(dev).remove(&sm.number).unwrap_or_default();
                    let kind = match dictionary_assignment(dev, sm.number) {
                        _ if bytes == 0 => "no PDO assigned to the SM",
                        Some(d) if d == assigned => "0x1C1x defaults give the image's PDOs",
                        Some(d) => {
                            // The size those PDOs would take: does DefaultSize follow them?
                            let dict_assignment = [(sm.number, d)].into();
                            let dir = if sm.usage == SmUsage::Outputs {
                                Direction::Rx
                            } else {
                                Direction::Tx
                            };
                            match image::image(dev, &dict_assignment, dir) {
                                Ok(i) if i.len() == default as usize => {
                                    "0x1C1x defaults give other PDOs, of DefaultSize"
                                }
                                _ => "0x1C1x defaults give other PDOs, not of DefaultSize",
                            }
                        }
                        None => "no 0x1C1x defaults",
                    };
                    *size_kinds.entry(kind).or_default() += 1;
                    disagreements.push(format!(
                        "{f} {} ({:?}): SM{} DefaultSize {default}, image {bytes}: {kind}",
                        dev.name(),
                        ec.product_code,
                        sm.number
                    ));
                }
            }
        }
    }
    println!(
        "ESI corpus: {} files, {devices} devices, {with_image} with a default process image \
         ({nonempty} not empty, {entries} entries placed)",
        files.len()
    );
    println!(
        "SM DefaultSize vs image: {size_agree} agree, {size_disagree} disagree {size_kinds:?}"
    );
    for d in &disagreements {
        println!("  {d}");
    }
    println!(
        "default assignment vs the dictionary's 0x1C1x defaults: {dict_agree} agree, {} disagree",
        dict_disagree.len()
    );
    for d in &dict_disagree {
        println!("  {d}");
    }
    println!(
        "entry bit offsets vs ETG.2000 reference: {offset_agree} agree, {} disagree; \
         {mandatory_only} devices with Mandatory PDOs without Sm",
        offset_disagree.len()
    );
    println!(
        "DC op-mode / alternative-mapping images: {variant_images}; left out: {skipped_reasons:?}"
    );
    assert!(failures.is_empty(), "no image: {failures:#?}");
    assert!(variant_failures.is_empty(), "no variant image: {variant_failures:#?}");
    assert!(offset_disagree.is_empty(), "offsets differ: {offset_disagree:#?}");
    assert_eq!(with_image, devices);
}
