//! The dictionary's PDO mapping objects against the `<RxPdo>`/`<TxPdo>` entries (T622, T623).
//!
//! An ESI with a dictionary states a PDO's default mapping twice: as the `<Entry>` elements of
//! the PDO, and as the default values 0xIIIISSLL of the mapping object (0x1600–0x17FF,
//! 0x1A00–0x1BFF) with their count in sub 0. A device starts with its dictionary's defaults; a
//! master that reads the mapping over CoE takes those, one that takes the ESI the entries.

use super::*;

/// The `0xIIIISSLL` words a mapping object lists by default, by sub-index from 1 on, whatever
/// sub 0 counts; with the span of each value. A zero word (no object, no bits) is no entry.
fn listed(o: &odc_model::Object) -> Vec<(u8, u32, Span)> {
    o.subs
        .range(1..)
        .filter_map(|(&sub, s)| {
            let v = s.initial_value()?;
            let word = v.value.as_u64().and_then(|w| u32::try_from(w).ok())?;
            (word != 0).then(|| (sub, word, first_span([v.span, s.span, o.span])))
        })
        .collect()
}

/// An entry as its mapping word.
fn word(e: &odc_model::PdoEntry) -> u32 {
    u32::from(e.index) << 16 | u32::from(e.sub) << 8 | u32::from(e.bits & 0xFF)
}

/// The words with runs of gaps joined into one (four 1-bit gaps map the bits one 4-bit gap
/// does).
fn layout(words: &[u32]) -> Vec<u32> {
    let mut out: Vec<u32> = Vec::with_capacity(words.len());
    for &w in words {
        match out.last_mut() {
            Some(last) if *last >> 16 == 0 && w >> 16 == 0 => *last += w & 0xFF,
            _ => out.push(w),
        }
    }
    out
}

/// `0x7000:00/16` (a gap: `gap/4`).
fn show_word(w: u32) -> String {
    let (index, sub, bits) = (w >> 16, (w >> 8) & 0xFF, w & 0xFF);
    if index == 0 { format!("gap/{bits}") } else { format!("0x{index:04X}:{sub:02X}/{bits}") }
}

/// The device's PDOs with the mapping object of its dictionary, when the file describes both:
/// not an object whose defaults odc filled from the entries (`EtherCat::esi_defaults`, the
/// file gives it none: nothing to compare).
fn mapped_pdos(dev: &Device) -> impl Iterator<Item = (&Pdo, &odc_model::Object)> {
    let check = ec(dev).is_some_and(|e| !is_modular(e)) && has_dictionary(dev);
    dev.pdos
        .iter()
        .filter(move |p| check && dev.esi_default(p.mapping_index).is_none())
        .filter_map(|p| Some((p, crate::util::object(dev, p.mapping_index)?)))
}

rule!(
    T622,
    "T622",
    "esi-pdo-mapping-default",
    "etg",
    Warning,
    Warn,
    pdo_mapping_default,
    "a PDO mapping object's default differs from the PDO's entries",
    "The default values of a mapping object (0x1600–0x17FF, 0x1A00–0x1BFF: subs 1..n, each \
     0xIIIISSLL = index, sub-index, bit length; ETG.1000.6 §5.6.7.4.7) and the <Entry> \
     elements of the <RxPdo>/<TxPdo> of that index describe the same default mapping. A device \
     starts with its dictionary's values; a master that reads the mapping over CoE (SOEM's \
     default bring-up does) sizes the process image from them, one that takes the ESI from the \
     entries, and the two disagree on the bytes and their meaning. Modular devices are not \
     checked. Fix: make the mapping object's DefaultData equal the entries, in order."
);

pub(super) fn pdo_mapping_default(dev: &Device, ctx: &mut Ctx) {
    for (p, o) in mapped_pdos(dev) {
        let list = listed(o);
        if list.is_empty() && initial_u64(dev, o.index, 0).is_none() {
            // The dictionary gives the object no default at all: nothing to compare.
            continue;
        }
        let entries: Vec<u32> = p.entries.iter().map(word).collect();
        let words: Vec<u32> = list.iter().map(|l| l.1).collect();
        if layout(&words) == layout(&entries) {
            continue;
        }
        let at = words.iter().zip(&entries).position(|(a, b)| a != b);
        let (span, what) = match at {
            Some(k) => (
                list[k].2,
                format!(
                    "sub {} is {} where entry {} of the {} is {}",
                    list[k].0,
                    show_word(words[k]),
                    k + 1,
                    pdo_kind(p),
                    show_word(entries[k])
                ),
            ),
            None => (
                first_span([o.span, p.span]),
                format!(
                    "it lists {} entries, the {} has {}",
                    words.len(),
                    pdo_kind(p),
                    entries.len()
                ),
            ),
        };
        ctx.report(
            o.index,
            None,
            span,
            format!("{} defaults to another mapping than {}: {what}", idx(o.index), pdo_name(p)),
        )
        .labels
        .push(Label { span: p.span, message: "the PDO's entries".into(), primary: false });
    }
}

rule!(
    T623,
    "T623",
    "esi-pdo-mapping-count",
    "etg",
    Warning,
    Warn,
    pdo_mapping_count,
    "a PDO mapping object's sub 0 counts fewer entries than it lists",
    "Sub 0 of a mapping object is the number of mapped entries; the device maps subs 1..=sub 0 \
     and nothing after them (ETG.1000.6 §5.6.7.4.7, as CiA 301 §7.5.2.36). A default of sub 0 \
     below the entries the object lists leaves the last of them out of the device's process \
     image, while the PDO's <Entry> elements (and a master that takes the ESI) include them: \
     master and device disagree on the PDO's length (AL status 0x001D/0x001E in SAFE-OP). \
     Fix: set sub 0's DefaultData to the number of entries."
);

pub(super) fn pdo_mapping_count(dev: &Device, ctx: &mut Ctx) {
    for (p, o) in mapped_pdos(dev) {
        let Some(count) = initial_u64(dev, o.index, 0) else { continue };
        let beyond: Vec<u8> =
            listed(o).iter().filter(|l| u64::from(l.0) > count).map(|l| l.0).collect();
        let Some(&last) = beyond.last() else { continue };
        let span = o.sub(0).map_or(o.span, |s| {
            first_span([s.initial_value().map_or(Span::DUMMY, |v| v.span), s.span, o.span])
        });
        ctx.report(
            o.index,
            Some(0),
            span,
            format!(
                "{}:00 defaults to {count}, but the object lists entries up to sub {last} (the \
                 {} has {})",
                idx(o.index),
                pdo_kind(p),
                p.entries.len()
            ),
        );
    }
}
