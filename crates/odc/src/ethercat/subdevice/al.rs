//! The AL state machine (ETG.1000.6 §6.4, ETG.2000 for the SM checks): INIT, PRE-OP,
//! SAFE-OP, OP and BOOT, the transitions a master may request, and the checks a device makes
//! on its sync managers before it enters a state, answered with the AL status codes of
//! ETG.1000.6 Table 11.

use super::{Esc, SmSpec, register};

/// AL states (AL control/status bits 0–3).
pub mod state {
    /// INIT.
    pub const INIT: u8 = 1;
    /// PRE-OPERATIONAL.
    pub const PRE_OP: u8 = 2;
    /// BOOTSTRAP.
    pub const BOOT: u8 = 3;
    /// SAFE-OPERATIONAL.
    pub const SAFE_OP: u8 = 4;
    /// OPERATIONAL.
    pub const OP: u8 = 8;
}

/// AL status codes (ETG.1000.6 Table 11).
pub mod code {
    /// No error.
    pub const NONE: u16 = 0x0000;
    /// Invalid requested state change.
    pub const INVALID_STATE_CHANGE: u16 = 0x0011;
    /// Unknown requested state.
    pub const UNKNOWN_STATE: u16 = 0x0012;
    /// Bootstrap not supported.
    pub const BOOTSTRAP_NOT_SUPPORTED: u16 = 0x0013;
    /// Invalid mailbox configuration (BOOT).
    pub const INVALID_MAILBOX_CONFIG_BOOT: u16 = 0x0015;
    /// Invalid mailbox configuration (PRE-OP).
    pub const INVALID_MAILBOX_CONFIG: u16 = 0x0016;
    /// Invalid sync manager configuration.
    pub const INVALID_SM_CONFIG: u16 = 0x0017;
    /// Invalid output configuration.
    pub const INVALID_OUTPUT_CONFIG: u16 = 0x001D;
    /// Invalid input configuration.
    pub const INVALID_INPUT_CONFIG: u16 = 0x001E;
    /// Invalid input mapping: the TxPDO mapping names what the device cannot map.
    pub const INVALID_INPUT_MAPPING: u16 = 0x0024;
    /// Invalid output mapping: the RxPDO mapping names what the device cannot map.
    pub const INVALID_OUTPUT_MAPPING: u16 = 0x0025;
}

/// Usage of a sync manager, by the SII's codes: mailbox out (master → device).
pub const MBOX_OUT: u8 = 1;
/// Mailbox in (device → master).
pub const MBOX_IN: u8 = 2;
/// Process data outputs.
pub const OUTPUTS: u8 = 3;
/// Process data inputs.
pub const INPUTS: u8 = 4;

/// Whether the transition table allows a request from `current` for `requested`
/// (ETG.1000.6 Table 9), else the AL status code; `boot`: the device has a bootstrap mode.
/// Checks of the configuration come after.
///
/// # Errors
///
/// 0x0011 for a transition the table does not have, 0x0012 for an unknown state, 0x0013 for
/// BOOT on a device without it.
pub fn allowed(current: u8, requested: u8, boot: bool) -> Result<(), u16> {
    use state::{BOOT, INIT, OP, PRE_OP, SAFE_OP};
    match (current, requested) {
        (_, INIT) => Ok(()),
        (_, BOOT) if !boot => Err(code::BOOTSTRAP_NOT_SUPPORTED),
        (INIT | BOOT, BOOT) => Ok(()),
        (c, r) if c == r => Ok(()),
        (BOOT, PRE_OP | SAFE_OP | OP) => Err(code::INVALID_STATE_CHANGE),
        (INIT, PRE_OP) | (PRE_OP, SAFE_OP) | (SAFE_OP, OP) => Ok(()),
        (SAFE_OP | OP, PRE_OP) | (OP, SAFE_OP) => Ok(()),
        (_, PRE_OP | SAFE_OP | OP | BOOT) => Err(code::INVALID_STATE_CHANGE),
        _ => Err(code::UNKNOWN_STATE),
    }
}

/// A sync manager's registers (0x0800 + 8n).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SmRegs {
    /// Physical start address.
    pub start: u16,
    /// Length in bytes.
    pub len: u16,
    /// Control: bits 0–1 mode (0 buffered, 2 mailbox), bits 2–3 direction (0 the master
    /// reads, 1 the master writes).
    pub control: u8,
    /// Status: bit 3 mailbox full.
    pub status: u8,
    /// Activate: bit 0 enable.
    pub activate: u8,
    /// PDI control: bit 0 deactivated by the application.
    pub pdi_control: u8,
}

/// Bit 3 of an SM status: mailbox full.
pub const SM_FULL: u8 = 0x08;

impl SmRegs {
    /// Reads sync manager `n`'s registers.
    ///
    /// # Errors
    ///
    /// The ESC access's.
    #[inline(never)]
    pub fn read<E: Esc + ?Sized>(esc: &mut E, n: u8) -> Result<Self, E::Error> {
        let mut b = [0u8; 8];
        esc.read(register::SM + 8 * u16::from(n), &mut b)?;
        Ok(Self::from_bytes(b))
    }
    /// The registers from their 8 bytes as the ESC holds them (little-endian words).
    pub const fn from_bytes(b: [u8; 8]) -> Self {
        Self {
            start: u16::from_le_bytes([b[0], b[1]]),
            len: u16::from_le_bytes([b[2], b[3]]),
            control: b[4],
            status: b[5],
            activate: b[6],
            pdi_control: b[7],
        }
    }
    /// A mailbox (mode 2), else buffered.
    pub fn is_mailbox(&self) -> bool {
        self.control & 0x03 == 0x02
    }
    /// The master writes it.
    pub fn master_writes(&self) -> bool {
        self.control & 0x0C == 0x04
    }
    /// Enabled by the master.
    pub fn enabled(&self) -> bool {
        self.activate & 1 != 0
    }
    /// Enabled by the master and not deactivated by the application (what the ESC acts on).
    pub fn active(&self) -> bool {
        self.enabled() && self.pdi_control & 1 == 0
    }
    fn overlaps(&self, other: &SmRegs) -> bool {
        let (a0, a1) = (u32::from(self.start), u32::from(self.start) + u32::from(self.len));
        let (b0, b1) = (u32::from(other.start), u32::from(other.start) + u32::from(other.len));
        a0 < b1 && b0 < a1
    }
}

/// The mailbox sync managers as the master set them, checked against the ESI's (ETG.2000
/// §4.3, as the slave stack code checks them on INIT → PRE-OP): enabled, mailbox mode, the
/// ESI's direction, a length within MinSize..=MaxSize, inside the process RAM (its size read
/// from the ESC, register 0x0006), not overlapping each other. Any failure: 0x0016.
///
/// # Errors
///
/// `Ok(Err(code))` for a refused configuration; `Err` the ESC access's error.
pub fn check_mailbox<E: Esc + ?Sized>(
    esc: &mut E,
    sms: &[SmSpec],
) -> Result<Result<(), u16>, E::Error> {
    let mut kib = [0u8; 1];
    esc.read(register::RAM_SIZE, &mut kib)?;
    let ram_end = u32::from(register::PROCESS_RAM) + u32::from(kib[0]) * 1024;
    let mut set: [Option<SmRegs>; 2] = [None, None];
    for spec in sms.iter().filter(|s| matches!(s.kind, MBOX_OUT | MBOX_IN)) {
        let sm = SmRegs::read(esc, spec.number)?;
        let ok = sm.enabled()
            && sm.is_mailbox()
            && sm.master_writes() == (spec.kind == MBOX_OUT)
            && (spec.min..=spec.max).contains(&sm.len)
            && sm.start >= register::PROCESS_RAM
            && u32::from(sm.start) + u32::from(sm.len) <= ram_end;
        if !ok {
            return Ok(Err(code::INVALID_MAILBOX_CONFIG));
        }
        if let Some(slot) = set.iter_mut().find(|s| s.is_none()) {
            *slot = Some(sm);
        }
    }
    Ok(match set {
        [Some(a), Some(b)] if a.overlaps(&b) => Err(code::INVALID_MAILBOX_CONFIG),
        _ => Ok(()),
    })
}

/// The process data sync managers against the sizes the current PDO assignment and mapping
/// give (ETG.2000 §4.4, on PRE-OP → SAFE-OP): a sync manager with data must be enabled,
/// exactly as long as its PDOs, with the mode and direction of the ESI's `ControlByte`
/// (as SOES compares them with its own settings; ETG.1000.4 allows process data in one
/// buffer, mode 2, which SoE drives use for their inputs), or buffered in its kind's direction
/// where the ESI gives none; one without data must be disabled or empty. Failures: 0x001D for
/// outputs, 0x001E for inputs.
///
/// # Errors
///
/// `Ok(Err(code))` for a refused configuration; `Err` the ESC access's error.
pub fn check_process_data<E: Esc + ?Sized>(
    esc: &mut E,
    sms: &[SmSpec],
    bytes_of: impl Fn(u8) -> u16,
) -> Result<Result<(), u16>, E::Error> {
    for spec in sms.iter().filter(|s| matches!(s.kind, OUTPUTS | INPUTS)) {
        let sm = SmRegs::read(esc, spec.number)?;
        let want = bytes_of(spec.number);
        let err = match spec.kind {
            OUTPUTS => code::INVALID_OUTPUT_CONFIG,
            _ => code::INVALID_INPUT_CONFIG,
        };
        let ok = match (want, sm.enabled()) {
            (0, false) => true,
            (0, true) => sm.len == 0,
            (_, false) => false,
            (n, true) if spec.control != 0 => {
                sm.len == n && sm.control & 0x0E == spec.control & 0x0E
            }
            (n, true) => {
                sm.len == n && !sm.is_mailbox() && sm.master_writes() == (spec.kind == OUTPUTS)
            }
        };
        if !ok {
            return Ok(Err(err));
        }
    }
    Ok(Ok(()))
}

#[cfg(test)]
mod tests {
    use super::state::*;
    use super::*;

    #[test]
    fn transitions_of_etg1000_6_table_9() {
        assert_eq!(allowed(INIT, PRE_OP, false), Ok(()));
        assert_eq!(allowed(PRE_OP, SAFE_OP, false), Ok(()));
        assert_eq!(allowed(SAFE_OP, OP, false), Ok(()));
        assert_eq!(allowed(OP, INIT, false), Ok(()));
        assert_eq!(allowed(OP, SAFE_OP, false), Ok(()));
        // Skipping a state is refused with 0x0011.
        assert_eq!(allowed(INIT, SAFE_OP, false), Err(0x0011));
        assert_eq!(allowed(INIT, OP, false), Err(0x0011));
        assert_eq!(allowed(PRE_OP, OP, false), Err(0x0011));
        // 5, 6, 7, 9…: unknown states, 0x0012; BOOT without bootstrap, 0x0013.
        assert_eq!(allowed(INIT, 5, false), Err(0x0012));
        assert_eq!(allowed(INIT, BOOT, false), Err(0x0013));
        // With bootstrap: INIT ↔ BOOT only.
        assert_eq!(allowed(INIT, BOOT, true), Ok(()));
        assert_eq!(allowed(PRE_OP, BOOT, true), Err(0x0011));
        assert_eq!(allowed(BOOT, PRE_OP, true), Err(0x0011));
        assert_eq!(allowed(BOOT, INIT, true), Ok(()));
    }
}
