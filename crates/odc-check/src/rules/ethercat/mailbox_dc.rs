//! Mailbox and distributed clocks (T612, T613, T616, T617, T624, T628).

use super::*;

/// Whether the device's `<Mailbox>` declares any protocol.
pub(super) fn speaks_mailbox(ec: &EtherCat) -> bool {
    ec.mailbox
        .as_ref()
        .is_some_and(|m| m.coe.is_some() || m.soe.is_some() || m.foe || m.eoe || m.aoe || m.voe)
}

rule!(
    T612,
    "T612",
    "esi-mailbox-sync-managers",
    "etg",
    Error,
    Deny,
    mailbox_sync_managers,
    "a device with a mailbox protocol lacks SM 0 = MBoxOut and SM 1 = MBoxIn",
    "The mailbox (CoE, FoE, EoE, SoE, AoE, VoE) runs over two sync managers: SM 0 carries \
     master→device (type MBoxOut), SM 1 device→master (MBoxIn) (ETG.1000.4 §6.7; ETG.2000). A \
     device whose <Mailbox> declares a protocol but whose first two <Sm> elements are not these \
     cannot be reached: the master sets up SM 0/1 from the ESI and finds no mailbox there \
     (AL status 0x0016 invalid mailbox configuration). Fix: describe SM 0 and SM 1 as the \
     mailbox, or remove the protocols."
);

pub(super) fn mailbox_sync_managers(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    if !speaks_mailbox(ec) {
        return;
    }
    let span = ec.mailbox.as_ref().map_or(Span::DUMMY, |m| m.span);
    for (n, want) in [(0usize, SmUsage::MBoxOut), (1, SmUsage::MBoxIn)] {
        let problem = match ec.sync_managers.get(n) {
            None => format!("the device has a mailbox but no SM {n} ({})", usage_name(&want)),
            Some(sm) if sm.usage != want => format!(
                "the device has a mailbox but SM {n} is of type {}, not {}",
                usage_name(&sm.usage),
                usage_name(&want)
            ),
            Some(_) => continue,
        };
        let at = ec.sync_managers.get(n).map_or(span, |sm| sm.span);
        ctx.report_device(first_span([at, span]), problem);
    }
}

/// The smallest mailbox that carries an expedited SDO: mailbox header (6 bytes), CoE header
/// (2) and the SDO request (8) — ETG.1000.6 §5.6.2.
pub(super) const MIN_COE_MAILBOX: u32 = 16;

rule!(
    T613,
    "T613",
    "esi-mailbox-size",
    "etg",
    Error,
    Deny,
    mailbox_size,
    "a mailbox sync manager has no size, or one too small for CoE",
    "The length of the mailbox sync managers SM 0/SM 1 is the <Sm DefaultSize> (a master \
     writes it to the ESC and to the SII's standard mailbox sizes). A mailbox sync manager \
     without DefaultSize (or MinSize/MaxSize) leaves the length to guesswork; one shorter than \
     16 bytes cannot carry the 6-byte mailbox header, the 2-byte CoE header and an 8-byte \
     expedited SDO (ETG.1000.6 §5.6.2), so no SDO reaches the device. Fix: give DefaultSize \
     (128 or more is usual)."
);

pub(super) fn mailbox_size(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    let coe = ec.mailbox.as_ref().is_some_and(|m| m.coe.is_some());
    for sm in ec.sync_managers.iter().filter(|sm| is_mailbox(&sm.usage)) {
        let n = sm.number;
        let size = sm.default_size.or(sm.max_size).or(sm.min_size);
        let problem = match size {
            None => format!("mailbox SM {n} ({}) has no size", usage_name(&sm.usage)),
            Some(s) if coe && s < MIN_COE_MAILBOX => format!(
                "mailbox SM {n} ({}) is {s} bytes; CoE needs at least {MIN_COE_MAILBOX}",
                usage_name(&sm.usage)
            ),
            Some(_) => continue,
        };
        ctx.report_device(sm.span, problem);
    }
}

rule!(
    T624,
    "T624",
    "esi-mailbox-sm-disabled",
    "etg",
    Warning,
    Warn,
    mailbox_sm_disabled,
    "a mailbox sync manager is declared Enable=\"0\"",
    "Enable of an <Sm> is the sync manager's activation (ESC register 0x0806 bit 0) that the \
     ESI and the SII's sync manager category give the master (ETG.2000; ETG.1000.4 sync \
     manager). A device whose <Mailbox> declares a protocol needs SM 0 and SM 1 enabled from \
     PRE-OP on; masters that program them from the SII (SOEM's default bring-up does) leave \
     them off, and no mailbox request reaches the device (CoE start-up fails, the device \
     stays in INIT or answers AL status 0x0016). Fix: Enable=\"1\" on the mailbox sync \
     managers."
);

pub(super) fn mailbox_sm_disabled(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    if !speaks_mailbox(ec) {
        return;
    }
    for sm in ec.sync_managers.iter().filter(|sm| is_mailbox(&sm.usage) && !sm.enable) {
        ctx.report_device(
            sm.span,
            format!(
                "mailbox SM {} ({}) is not enabled, but the device declares a mailbox protocol",
                sm.number,
                usage_name(&sm.usage)
            ),
        );
    }
}

rule!(
    T628,
    "T628",
    "esi-device-emulation-mailbox",
    "etg",
    Warning,
    Warn,
    device_emulation_mailbox,
    "a device with a mailbox sets ESC device emulation in its ConfigData",
    "The second byte of Eeprom/ConfigData is the ESC configuration register 0x0141 (ETG.2010 SII \
     word 0; ET1100 datasheet, register 0x0141); its bit 0, device emulation, makes the ESC copy \
     every state the master writes to AL control into AL status by itself. That is for devices \
     without a microcontroller (simple I/O terminals). A device with a mailbox has one, and \
     with device emulation its refusals cannot reach the master: AL status reads the requested \
     state while the firmware refused it (an invalid mailbox or process-data configuration), \
     so the master runs in OP against a device that exchanges nothing. Fix: clear bit 0 of \
     ConfigData's second byte."
);

pub(super) fn device_emulation_mailbox(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    let Some(eeprom) = ec.eeprom.as_ref() else { return };
    let Some(&esc_config) = eeprom.config_data.get(1) else { return };
    if esc_config & 0x01 == 0 || !speaks_mailbox(ec) {
        return;
    }
    ctx.report_device(
        eeprom.spans.config_data.unwrap_or(eeprom.span),
        format!(
            "ConfigData sets device emulation (0x0141 = 0x{:02X}, bit 0) on a device with a \
             mailbox, whose firmware then cannot refuse a state",
            esc_config
        ),
    );
}

/// AssignActivate bits (ESC registers 0x0980/0x0981): 0x0100 cyclic operation, 0x0200
/// SYNC0, 0x0400 SYNC1; reserved: 0x0980 bits 1–3 and 6–7.
pub(super) const AA_CYCLIC: u32 = 0x0100;
pub(super) const AA_SYNC: u32 = 0x0600;
pub(super) const AA_RESERVED: u32 = 0x00CE;

rule!(
    T616,
    "T616",
    "esi-dc-assign-activate",
    "etg",
    Error,
    Deny,
    dc_assign_activate,
    "a DC operation mode's AssignActivate is not a valid 0x0980/0x0981 value",
    "AssignActivate of a <Dc><OpMode> is the 16-bit value a master writes to the ESC's DC \
     registers 0x0980 (sync/latch unit assignment) and 0x0981 (activation) (ETG.2000, \
     ETG.1000.4 distributed clocks): 0x0100 starts cyclic operation, 0x0200 SYNC0, 0x0400 \
     SYNC1; #x300 is the usual SYNC0 mode, #x700 SYNC0+SYNC1, 0 free run or SM-synchronous. \
     SYNC0/SYNC1 without cyclic operation never produce a pulse; a value above 0xFFFF does not \
     fit the registers; bits 1–3 and 6–7 of 0x0980 are reserved. Fix: correct AssignActivate."
);

pub(super) fn dc_assign_activate(dev: &Device, ctx: &mut Ctx) {
    let Some(dc) = ec(dev).and_then(|e| e.dc.as_ref()) else { return };
    for m in &dc.op_modes {
        let Some(aa) = m.assign_activate else { continue };
        let why = if aa > 0xFFFF {
            "does not fit the two registers 0x0980/0x0981"
        } else if aa & AA_SYNC != 0 && aa & AA_CYCLIC == 0 {
            "activates SYNC0/SYNC1 without cyclic operation (0x0100)"
        } else if aa & AA_RESERVED != 0 {
            "sets reserved bits of 0x0980"
        } else {
            continue;
        };
        ctx.report_device(
            first_span([m.span, dc.span]),
            format!("DC mode `{}`: AssignActivate 0x{aa:04X} {why}", m.name),
        );
    }
}

rule!(
    T617,
    "T617",
    "esi-dc-op-mode-name",
    "etg",
    Error,
    Deny,
    dc_op_mode_name,
    "a DC operation mode has no name",
    "Masters and configuration tools select a <Dc><OpMode> by its Name (TwinCAT's DC tab, a \
     module's DcOpModeName, ENI files); ETG.2000 makes the Name mandatory. A mode without one \
     cannot be selected. Two modes of one name are not reported: Beckhoff's files give \
     alternative versions of a mode the same name and tell them apart by TwinCAT build \
     numbers (VendorSpecific UseFromBuildNo/IgnoreFromBuildNo). Fix: name the mode."
);

pub(super) fn dc_op_mode_name(dev: &Device, ctx: &mut Ctx) {
    let Some(dc) = ec(dev).and_then(|e| e.dc.as_ref()) else { return };
    for (k, m) in dc.op_modes.iter().enumerate() {
        if m.name.trim().is_empty() {
            ctx.report_device(
                first_span([m.span, dc.span]),
                format!("DC mode {} has no name", k + 1),
            );
        }
    }
}
