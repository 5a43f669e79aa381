//! The ESC registers a master uses (ETG.1000.4 §6, the register map of the Beckhoff ESC
//! datasheets section II), and which of them the EtherCAT side may write.

/// Type (1 byte).
pub const TYPE: u16 = 0x0000;
/// Revision (1 byte).
pub const REVISION: u16 = 0x0001;
/// Build (2 bytes).
pub const BUILD: u16 = 0x0002;
/// FMMUs supported (1 byte).
pub const FMMU_COUNT: u16 = 0x0004;
/// Sync managers supported (1 byte).
pub const SM_COUNT: u16 = 0x0005;
/// Process RAM in KiB (1 byte).
pub const RAM_SIZE: u16 = 0x0006;
/// Port descriptor: 2 bits a port, 00 not implemented, 01 not configured, 10 EBUS, 11 MII.
pub const PORT_DESCRIPTOR: u16 = 0x0007;
/// ESC features supported (2 bytes): bit 2 distributed clocks, bit 3 64-bit system time.
pub const FEATURES: u16 = 0x0008;
/// Configured station address (2 bytes).
pub const STATION_ADDRESS: u16 = 0x0010;
/// Configured station alias (2 bytes), loaded from SII word 4.
pub const STATION_ALIAS: u16 = 0x0012;
/// DL control (4 bytes).
pub const DL_CONTROL: u16 = 0x0100;
/// DL status (2 bytes).
pub const DL_STATUS: u16 = 0x0110;
/// AL control (2 bytes).
pub const AL_CONTROL: u16 = 0x0120;
/// AL status (2 bytes).
pub const AL_STATUS: u16 = 0x0130;
/// AL status code (2 bytes).
pub const AL_STATUS_CODE: u16 = 0x0134;
/// AL event request (4 bytes): bit 0 AL control written, bit 8 + n sync manager n.
pub const AL_EVENT: u16 = 0x0220;
/// PDI control (1 byte), from SII word 0.
pub const PDI_CONTROL: u16 = 0x0140;
/// PDI configuration (2 bytes), from SII word 1.
pub const PDI_CONFIG: u16 = 0x0150;
/// Watchdog divider (2 bytes).
pub const WATCHDOG_DIVIDER: u16 = 0x0400;
/// Watchdog time PDI (2 bytes).
pub const WATCHDOG_PDI: u16 = 0x0410;
/// Watchdog time process data (2 bytes).
pub const WATCHDOG_PD: u16 = 0x0420;
/// Watchdog status process data (2 bytes): bit 0 = 1 while not expired.
pub const WATCHDOG_STATUS: u16 = 0x0440;
/// SII EEPROM configuration (2 bytes).
pub const SII_CONFIG: u16 = 0x0500;
/// SII EEPROM control/status (2 bytes).
pub const SII_CONTROL: u16 = 0x0502;
/// SII EEPROM address (4 bytes, in words).
pub const SII_ADDRESS: u16 = 0x0504;
/// SII EEPROM data (8 bytes).
pub const SII_DATA: u16 = 0x0508;
/// FMMU 0 (16 bytes each).
pub const FMMU: u16 = 0x0600;
/// Sync manager 0 (8 bytes each).
pub const SM: u16 = 0x0800;
/// Receive time port 0 (4 bytes; ports 1–3 follow). A write to it latches all four.
pub const DC_RECEIVE_TIME_PORT0: u16 = 0x0900;
/// System time (8 bytes).
pub const DC_SYSTEM_TIME: u16 = 0x0910;
/// Receive time of the ECAT processing unit (8 bytes).
pub const DC_RECEIVE_TIME_EPU: u16 = 0x0918;
/// System time offset (8 bytes).
pub const DC_SYSTEM_TIME_OFFSET: u16 = 0x0920;
/// System time delay (4 bytes).
pub const DC_SYSTEM_TIME_DELAY: u16 = 0x0928;
/// System time difference (4 bytes, sign and magnitude).
pub const DC_SYSTEM_TIME_DIFFERENCE: u16 = 0x092C;
/// Start of the process data RAM.
pub const PROCESS_RAM: u16 = 0x1000;

/// FMMUs the simulated ESC has.
pub const FMMUS: u8 = 8;
/// Sync managers the simulated ESC has.
pub const SMS: u8 = 8;
/// Process RAM in KiB, unless the device needs more (ET1100: 8 KiB).
pub const RAM_KIB: u8 = 8;
/// The most process RAM an ESC has (Beckhoff's ESC IP core: 60 KiB, 0x1000–0xFFFF, the whole
/// 16-bit physical address space above the registers).
pub const MAX_RAM_KIB: u8 = 60;
/// Bytes of the address space the simulated ESC implements by default (registers and process
/// RAM).
pub const MEMORY: usize = PROCESS_RAM as usize + RAM_KIB as usize * 1024;

/// Whether the EtherCAT side may write the byte at `addr` (a write to another register byte
/// is ignored, the working counter still counts it, as an ESC does). Registers with a write
/// action that stores nothing (0x0900 latches, 0x0910 compares) are not writable here: the
/// ESC handles their writes itself.
pub fn ecat_writable(addr: u16) -> bool {
    match addr {
        0x0010..=0x0011 // station address
        | 0x0100..=0x0103 // DL control
        | 0x0108..=0x0109 // physical read/write offset
        | 0x0120..=0x0121 // AL control
        | 0x0138..=0x0139 // LED override
        | 0x0200..=0x0201 // ECAT event mask
        | 0x0300..=0x0313 // error counters (a write clears them)
        | 0x0400..=0x0401 // watchdog divider
        | 0x0410..=0x0411 // watchdog PDI
        | 0x0420..=0x0421 // watchdog process data
        | 0x0442..=0x0443 // watchdog counters
        | 0x0500 // SII: EEPROM offered to the PDI, forced ECAT access
        | 0x0502..=0x050F // SII control, address, data
        | 0x0600..=0x06FF // FMMUs
        | 0x0920..=0x092B // system time offset and delay
        | 0x0930..=0x0935 // speed counter start, filter depths
        | 0x0980..=0x0981 // cyclic unit control, activation
        | 0x0990..=0x0997 // start time cyclic operation
        | 0x09A0..=0x09A7 // SYNC0/SYNC1 cycle times
        | 0x0F00..=0x0F03 // digital outputs
        | 0x0F80..=0x0FFF // user RAM
        => true,
        // Sync managers: all but the status byte (5) and the PDI control byte (7).
        0x0800..=0x087F => !matches!(addr % 8, 5 | 7),
        _ => addr >= PROCESS_RAM,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn read_only_registers_are_not_writable() {
        // Type, AL status, AL status code, DL status: read-only for the master (ETG.1000.4).
        for addr in [TYPE, AL_STATUS, AL_STATUS_CODE, DL_STATUS, STATION_ALIAS] {
            assert!(!ecat_writable(addr), "{addr:#06x}");
        }
        for addr in [STATION_ADDRESS, AL_CONTROL, SII_CONTROL, FMMU + 12, SM, SM + 6] {
            assert!(ecat_writable(addr), "{addr:#06x}");
        }
        // SM status (byte 5) is the ESC's.
        assert!(!ecat_writable(SM + 5) && !ecat_writable(SM + 8 + 5));
    }
}
