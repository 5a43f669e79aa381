//! T601–T602: EtherCAT (ETG.2000 ESI) PDO entries against the dictionary.

use odc_model::{Device, SubObject};

use super::rule;
use crate::Ctx;
use crate::util::{first_span, idx, is_esi};

rule!(
    T601,
    "T601",
    "esi-pdo-entry-not-in-dictionary",
    "etg",
    Warning,
    Warn,
    pdo_entry_not_in_dictionary,
    "an ESI PDO entry names an object the dictionary does not have",
    "An <Entry> of an <RxPdo>/<TxPdo> maps object Index:SubIndex of the device's CoE \
     dictionary (ETG.2000 PdoType). When the ESI has a dictionary (<Profile><Dictionary>) but \
     not that object, a master that configures the mapping over CoE (0x1600/0x1A00 writes) gets \
     an SDO abort, and generated code cannot type the entry from the dictionary. Devices without \
     a dictionary are not checked (their objects are synthesised from the PDO entries). Fix: add \
     the object to the dictionary or correct the entry."
);

fn pdo_entry_not_in_dictionary(dev: &Device, ctx: &mut Ctx) {
    if !is_esi(dev) || dev.objects.values().all(|o| o.origin == odc_model::Origin::PdoEntry) {
        return;
    }
    for p in &dev.pdos {
        for e in p.entries.iter().filter(|e| !e.is_gap()) {
            if dev.sub(e.index, e.sub).is_none() {
                ctx.report(
                    p.mapping_index,
                    None,
                    first_span([e.span, p.span]),
                    format!(
                        "PDO {} maps 0x{:04X}:{:02X}, which the dictionary does not have",
                        idx(p.mapping_index),
                        e.index,
                        e.sub
                    ),
                );
            }
        }
    }
}

rule!(
    T602,
    "T602",
    "esi-pdo-entry-bit-length",
    "etg",
    Warning,
    Warn,
    pdo_entry_bit_length,
    "an ESI PDO entry's BitLen differs from the dictionary object's size",
    "The BitLen of a PDO <Entry> must equal the BitSize of the object it maps (ETG.2000; \
     ETG.1000.6 PDO mapping). When they differ, the process image the master computes from the \
     ESI and the one the device builds from its dictionary disagree, and every later entry of \
     the PDO is read at the wrong offset. Fix: correct BitLen or the object's BitSize."
);

fn pdo_entry_bit_length(dev: &Device, ctx: &mut Ctx) {
    if !is_esi(dev) {
        return;
    }
    for p in &dev.pdos {
        for e in p.entries.iter().filter(|e| !e.is_gap()) {
            let Some(bits) = dev.sub(e.index, e.sub).and_then(SubObject::bits) else { continue };
            if u32::from(e.bits) != bits {
                ctx.report(
                    p.mapping_index,
                    None,
                    first_span([e.span, p.span]),
                    format!(
                        "PDO {} maps 0x{:04X}:{:02X} with BitLen {} but the object has {bits} bits",
                        idx(p.mapping_index),
                        e.index,
                        e.sub,
                        e.bits
                    ),
                );
            }
        }
    }
}
