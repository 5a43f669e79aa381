//! T601–T628: EtherCAT devices (ETG.2000 ESI, ETG.1000 data link and application layer).
//!
//! The PDO rules mirror the CANopen ones (C301–C303) on the `<RxPdo>`/`<TxPdo>` elements; the
//! others check what only an ESI has: sync managers (`<Sm>`), the default PDO assignment (the
//! PDOs' `Sm` attributes and the objects 0x1C10–0x1C2F), `Exclude` relations, the mailbox and
//! the distributed-clock operation modes (`<Dc><OpMode>`). They run only on devices read from
//! an ESI.
//!
//! Sync manager n is the n-th `<Sm>` element; its assignment object is 0x1C10 + n (0x1C12 for
//! SM 2, 0x1C13 for SM 3). The default PDO set of a sync manager is the PDOs whose `Sm`
//! attribute names it (ETG.2000: "if set, the PDO is included in the process image").

use std::collections::BTreeSet;

use odc_layout::{BitRange, Cursor};
use odc_model::ethercat::{EtherCat, SmUsage, SyncManager};
use odc_model::{Device, Direction, Label, Origin, Pdo, Span, SubObject};

use super::rule;
use crate::Ctx;
use crate::util::{first_span, idx, initial_u64, is_esi};

mod assignment;
mod data_types;
mod entries;
mod identity;
mod mailbox_dc;
mod mapping;
mod sync_managers;

pub(crate) use assignment::*;
pub(crate) use data_types::*;
pub(crate) use entries::*;
pub(crate) use identity::*;
pub(crate) use mailbox_dc::*;
pub(crate) use mapping::*;
pub(crate) use sync_managers::*;

/// The EtherCAT part of an ESI device.
fn ec(dev: &Device) -> Option<&EtherCat> {
    if is_esi(dev) { dev.ethercat.as_deref() } else { None }
}

/// Whether the ESI has a dictionary of its own (not one synthesised from the PDO entries).
fn has_dictionary(dev: &Device) -> bool {
    is_esi(dev) && dev.objects.values().any(|o| o.origin == Origin::File)
}

fn pdo_kind(p: &Pdo) -> &'static str {
    match p.direction {
        Direction::Rx => "RxPdo",
        Direction::Tx => "TxPdo",
    }
}

/// `RxPdo 0x1600`.
fn pdo_name(p: &Pdo) -> String {
    format!("{} {}", pdo_kind(p), idx(p.mapping_index))
}

/// The sync-manager type that carries PDOs of a direction.
fn usage_for(dir: Direction) -> SmUsage {
    match dir {
        Direction::Rx => SmUsage::Outputs,
        Direction::Tx => SmUsage::Inputs,
    }
}

/// The PDO direction a sync manager carries, if it carries process data.
fn direction_of(usage: &SmUsage) -> Option<Direction> {
    match usage {
        SmUsage::Outputs => Some(Direction::Rx),
        SmUsage::Inputs => Some(Direction::Tx),
        _ => None,
    }
}

fn usage_name(u: &SmUsage) -> &str {
    match u.as_str() {
        "" => "(no type)",
        t => t,
    }
}

/// Whether a sync manager can carry PDOs of `dir`: by its type, or, when the type is not one
/// ETG.2000 defines (IgH's `ethercat xml` writes none, some vendors their own names), by the
/// direction bits of its ControlByte (bits 2–3: 01 the master writes, 00 it reads).
fn carries(sm: &SyncManager, dir: Direction) -> bool {
    match (&sm.usage, sm.control_byte.as_ref()) {
        (SmUsage::Other(_), Some(cb)) => (cb.value >> 2) & 0x3 == u8::from(dir == Direction::Rx),
        (SmUsage::Other(_), None) => true,
        (usage, _) => direction_of(usage) == Some(dir),
    }
}

fn is_mailbox(u: &SmUsage) -> bool {
    matches!(u, SmUsage::MBoxOut | SmUsage::MBoxIn)
}

/// The PDOs the device assigns to sync manager `sm` by default, in file order.
fn assigned(dev: &Device, sm: u8) -> impl Iterator<Item = &Pdo> {
    dev.pdos.iter().filter(move |p| p.sync_manager == Some(sm))
}

/// The bytes the default PDOs of `sm` occupy (bit-packed, rounded up to whole bytes).
fn assigned_bytes(dev: &Device, sm: u8) -> u64 {
    assigned(dev, sm).map(|p| u64::from(p.bits())).sum::<u64>().div_ceil(8)
}

/// Every PDO index the file defines: the device's and its modules'.
fn all_pdo_indexes(dev: &Device, ec: &EtherCat) -> BTreeSet<u16> {
    dev.pdos
        .iter()
        .chain(ec.modules.iter().flat_map(|m| m.pdos.iter()))
        .map(|p| p.mapping_index)
        .collect()
}

/// Whether the device has modules or slots: PDO indexes then also come from modules and are
/// shifted per slot, so an index the device does not define may still be right.
fn is_modular(ec: &EtherCat) -> bool {
    ec.slots.is_some() || !ec.modules.is_empty()
}
