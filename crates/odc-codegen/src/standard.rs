//! Which object keeps a name that several objects of a file share.
//!
//! Files often give a vendor object the name of a standard one (a manufacturer "Position
//! actual value" beside 0x6064), or mark a profile object's internal twin with a star
//! (Lexium's 0x6063 "Position actual value*" beside 0x6064 "Position actual value"). The
//! generated names then collide, and the object a user looks for first, the standard one,
//! should keep the plain name: `od::POSITION_ACTUAL_VALUE` is 0x6064. [`rank`] orders the
//! claims: the object CiA 301/402 gives that very name, then any object of the standard
//! areas, then the others.

use crate::names::words;

/// The CiA 301 communication objects and the CiA 402 drive objects by their standard names
/// (CiA 301 §7.5, CiA 402-2 §6–§16). Profile indexes are those of the first axis.
const STANDARD_NAMES: &[(u16, &str)] = &[
    (0x1000, "Device type"),
    (0x1001, "Error register"),
    (0x1002, "Manufacturer status register"),
    (0x1003, "Pre-defined error field"),
    (0x1005, "COB-ID SYNC"),
    (0x1006, "Communication cycle period"),
    (0x1007, "Synchronous window length"),
    (0x1008, "Manufacturer device name"),
    (0x1009, "Manufacturer hardware version"),
    (0x100A, "Manufacturer software version"),
    (0x100C, "Guard time"),
    (0x100D, "Life time factor"),
    (0x1010, "Store parameters"),
    (0x1011, "Restore default parameters"),
    (0x1012, "COB-ID time stamp"),
    (0x1013, "High resolution time stamp"),
    (0x1014, "COB-ID EMCY"),
    (0x1015, "Inhibit time EMCY"),
    (0x1016, "Consumer heartbeat time"),
    (0x1017, "Producer heartbeat time"),
    (0x1018, "Identity object"),
    (0x1019, "Synchronous counter overflow value"),
    (0x1020, "Verify configuration"),
    (0x1029, "Error behavior"),
    (0x603F, "Error code"),
    (0x6040, "Controlword"),
    (0x6041, "Statusword"),
    (0x605A, "Quick stop option code"),
    (0x605B, "Shutdown option code"),
    (0x605C, "Disable operation option code"),
    (0x605D, "Halt option code"),
    (0x605E, "Fault reaction option code"),
    (0x6060, "Modes of operation"),
    (0x6061, "Modes of operation display"),
    (0x6062, "Position demand value"),
    (0x6063, "Position actual internal value"),
    (0x6064, "Position actual value"),
    (0x6065, "Following error window"),
    (0x6066, "Following error time out"),
    (0x6067, "Position window"),
    (0x6068, "Position window time"),
    (0x6069, "Velocity sensor actual value"),
    (0x606A, "Sensor selection code"),
    (0x606B, "Velocity demand value"),
    (0x606C, "Velocity actual value"),
    (0x606D, "Velocity window"),
    (0x606E, "Velocity window time"),
    (0x606F, "Velocity threshold"),
    (0x6070, "Velocity threshold time"),
    (0x6071, "Target torque"),
    (0x6072, "Max torque"),
    (0x6073, "Max current"),
    (0x6074, "Torque demand"),
    (0x6075, "Motor rated current"),
    (0x6076, "Motor rated torque"),
    (0x6077, "Torque actual value"),
    (0x6078, "Current actual value"),
    (0x6079, "DC link circuit voltage"),
    (0x607A, "Target position"),
    (0x607B, "Position range limit"),
    (0x607C, "Home offset"),
    (0x607D, "Software position limit"),
    (0x607E, "Polarity"),
    (0x607F, "Max profile velocity"),
    (0x6080, "Max motor speed"),
    (0x6081, "Profile velocity"),
    (0x6082, "End velocity"),
    (0x6083, "Profile acceleration"),
    (0x6084, "Profile deceleration"),
    (0x6085, "Quick stop deceleration"),
    (0x6086, "Motion profile type"),
    (0x6087, "Torque slope"),
    (0x6088, "Torque profile type"),
    (0x608F, "Position encoder resolution"),
    (0x6090, "Velocity encoder resolution"),
    (0x6091, "Gear ratio"),
    (0x6092, "Feed constant"),
    (0x6098, "Homing method"),
    (0x6099, "Homing speeds"),
    (0x609A, "Homing acceleration"),
    (0x60B0, "Position offset"),
    (0x60B1, "Velocity offset"),
    (0x60B2, "Torque offset"),
    (0x60B8, "Touch probe function"),
    (0x60B9, "Touch probe status"),
    (0x60C0, "Interpolation sub mode select"),
    (0x60C1, "Interpolation data record"),
    (0x60C2, "Interpolation time period"),
    (0x60C5, "Max acceleration"),
    (0x60C6, "Max deceleration"),
    (0x60F2, "Positioning option code"),
    (0x60F4, "Following error actual value"),
    (0x60FA, "Control effort"),
    (0x60FC, "Position demand internal value"),
    (0x60FD, "Digital inputs"),
    (0x60FE, "Digital outputs"),
    (0x60FF, "Target velocity"),
    (0x6402, "Motor type"),
    (0x6502, "Supported drive modes"),
];

/// Whether `index` is in a standard area: the CiA 301 communication objects
/// (0x1000–0x1FFF) or the device profile (0x6000–0x9FFF, eight logical devices or axes).
pub fn is_standard_area(index: u16) -> bool {
    matches!(index, 0x1000..=0x1FFF | 0x6000..=0x9FFF)
}

/// The claim of object `index`, named `name` in the file, on a name it shares with others:
/// 2 when CiA 301/402 gives the object that name (compared word by word, so case and
/// punctuation do not matter), 1 for another object of a standard area, 0 for the others.
pub fn rank(index: u16, name: &str) -> u8 {
    if !is_standard_area(index) {
        return 0;
    }
    // Axis n of a multi-axis drive repeats the profile at 0x6000 + n·0x800.
    let first_axis = if index >= 0x6000 { 0x6000 + (index - 0x6000) % 0x800 } else { index };
    let standard = STANDARD_NAMES
        .binary_search_by_key(&first_axis, |&(i, _)| i)
        .ok()
        .and_then(|p| STANDARD_NAMES.get(p))
        .is_some_and(|&(_, standard)| words(standard) == words(name));
    if standard { 2 } else { 1 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_sorted() {
        assert!(STANDARD_NAMES.windows(2).all(|w| w[0].0 < w[1].0));
    }

    #[test]
    fn ranks() {
        assert_eq!(rank(0x6064, "Position actual value"), 2);
        assert_eq!(rank(0x6064, "position actual VALUE"), 2);
        assert_eq!(rank(0x6864, "Position actual value"), 2);
        assert_eq!(rank(0x6063, "Position actual value*"), 1);
        assert_eq!(rank(0x1017, "Producer Heartbeat Time"), 2);
        assert_eq!(rank(0x1A00, "Transmit PDO mapping"), 1);
        assert_eq!(rank(0x2064, "Position actual value"), 0);
        assert_eq!(rank(0x5FFF, "Controlword"), 0);
        assert_eq!(rank(0xA000, "Controlword"), 0);
    }
}
