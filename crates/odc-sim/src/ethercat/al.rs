//! The AL state machine (ETG.1000.6 §6.4, ETG.2000 for the SM checks): INIT, PRE-OP,
//! SAFE-OP, OP (and BOOT, which the simulated device does not have), the transitions a
//! master may request, and the checks a device makes before it enters a state, answered
//! with the AL status codes of ETG.1000.6 Table 11.

use super::esc::{Esc, SmRegs};

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
}

/// What the device knows of one of its sync managers (from its ESI).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SmSpec {
    /// Its number.
    pub number: u8,
    /// Usage: 1 mailbox out (master → device), 2 mailbox in, 3 outputs, 4 inputs (the SII
    /// codes), 0 other.
    pub kind: u8,
    /// `@MinSize` (0 when not given).
    pub min: u16,
    /// `@MaxSize` (the process RAM when not given).
    pub max: u16,
    /// `@ControlByte`.
    pub control: u8,
}

/// Mailbox out, in, outputs, inputs: the SII's codes of SM usage.
pub const MBOX_OUT: u8 = 1;
/// Mailbox in.
pub const MBOX_IN: u8 = 2;
/// Process data outputs.
pub const OUTPUTS: u8 = 3;
/// Process data inputs.
pub const INPUTS: u8 = 4;

/// The state after a request from `current` for `requested` if the transition table allows
/// it (ETG.1000.6 Table 9), else the AL status code. Checks of the configuration come after.
pub fn allowed(current: u8, requested: u8) -> Result<(), u16> {
    use state::*;
    match (current, requested) {
        (_, INIT) => Ok(()),
        (_, BOOT) => Err(code::BOOTSTRAP_NOT_SUPPORTED),
        (c, r) if c == r => Ok(()),
        (INIT, PRE_OP) | (PRE_OP, SAFE_OP) | (SAFE_OP, OP) => Ok(()),
        (SAFE_OP | OP, PRE_OP) | (OP, SAFE_OP) => Ok(()),
        (_, PRE_OP | SAFE_OP | OP) => Err(code::INVALID_STATE_CHANGE),
        _ => Err(code::UNKNOWN_STATE),
    }
}

fn overlaps(a: &SmRegs, b: &SmRegs) -> bool {
    let (a0, a1) = (u32::from(a.start), u32::from(a.start) + u32::from(a.len));
    let (b0, b1) = (u32::from(b.start), u32::from(b.start) + u32::from(b.len));
    a0 < b1 && b0 < a1
}

/// The mailbox sync managers as the master set them, checked against the ESI's (ETG.2000
/// §4.3, as the slave stack code checks them on INIT → PRE-OP): enabled, mailbox mode, the
/// ESI's direction, a length within MinSize..=MaxSize, inside the process RAM, not
/// overlapping each other. Any failure: 0x0016.
pub fn check_mailbox(esc: &Esc, sms: &[SmSpec], ram_end: u32) -> Result<(), u16> {
    let mut set = Vec::new();
    for spec in sms.iter().filter(|s| matches!(s.kind, MBOX_OUT | MBOX_IN)) {
        let sm = esc.sm(spec.number);
        let ok = sm.activate & 1 != 0
            && sm.is_mailbox()
            && sm.master_writes() == (spec.kind == MBOX_OUT)
            && (spec.min..=spec.max).contains(&sm.len)
            && sm.start >= super::registers::PROCESS_RAM
            && u32::from(sm.start) + u32::from(sm.len) <= ram_end;
        if !ok {
            return Err(code::INVALID_MAILBOX_CONFIG);
        }
        set.push(sm);
    }
    match set.as_slice() {
        [a, b] if overlaps(a, b) => Err(code::INVALID_MAILBOX_CONFIG),
        _ => Ok(()),
    }
}

/// The process data sync managers against the sizes the current PDO assignment and mapping
/// give (ETG.2000 §4.4, on PRE-OP → SAFE-OP): a sync manager with data must be enabled,
/// buffered, in the ESI's direction, exactly as long as its PDOs; one without data must be
/// disabled or empty. Failures: 0x001D for outputs, 0x001E for inputs.
pub fn check_process_data(
    esc: &Esc,
    sms: &[SmSpec],
    bytes_of: impl Fn(u8) -> u16,
) -> Result<(), u16> {
    for spec in sms.iter().filter(|s| matches!(s.kind, OUTPUTS | INPUTS)) {
        let sm = esc.sm(spec.number);
        let want = bytes_of(spec.number);
        let err = match spec.kind {
            OUTPUTS => code::INVALID_OUTPUT_CONFIG,
            _ => code::INVALID_INPUT_CONFIG,
        };
        let enabled = sm.activate & 1 != 0;
        let ok = match (want, enabled) {
            (0, false) => true,
            (0, true) => sm.len == 0,
            (_, false) => false,
            (n, true) => {
                sm.len == n && !sm.is_mailbox() && sm.master_writes() == (spec.kind == OUTPUTS)
            }
        };
        if !ok {
            return Err(err);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::state::*;
    use super::*;

    #[test]
    fn transitions_of_etg1000_6_table_9() {
        assert_eq!(allowed(INIT, PRE_OP), Ok(()));
        assert_eq!(allowed(PRE_OP, SAFE_OP), Ok(()));
        assert_eq!(allowed(SAFE_OP, OP), Ok(()));
        assert_eq!(allowed(OP, INIT), Ok(()));
        assert_eq!(allowed(OP, SAFE_OP), Ok(()));
        // Skipping a state is refused with 0x0011.
        assert_eq!(allowed(INIT, SAFE_OP), Err(0x0011));
        assert_eq!(allowed(INIT, OP), Err(0x0011));
        assert_eq!(allowed(PRE_OP, OP), Err(0x0011));
        // 5, 6, 7, 9…: unknown states, 0x0012; BOOT without bootstrap, 0x0013.
        assert_eq!(allowed(INIT, 5), Err(0x0012));
        assert_eq!(allowed(INIT, BOOT), Err(0x0013));
    }
}
