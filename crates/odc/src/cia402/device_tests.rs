//! The device-side state machine against CiA 402-2 §6.2 (IEC 61800-7-201): the transition
//! table, the controlword commands of its table "device control commands", and the state
//! coding of the statusword (mask 0x6F: bits 0–3, 5, 6).

use super::*;
use crate::time::Duration;

/// The objects of a drive, as plain fields.
#[derive(Debug, Default)]
struct Objects {
    cw: Controlword,
    sw: Statusword,
    mode: Option<ModeOfOperation>,
    display: Option<ModeOfOperation>,
    target: i32,
    target_velocity: i32,
    profile_velocity: u32,
    position: i32,
    velocity: i32,
    homing_method: i8,
    homing_speed: u32,
    home_offset: i32,
    target_torque: i16,
    torque: i16,
}

impl DriveObjects for Objects {
    fn controlword(&self) -> Controlword {
        self.cw
    }
    fn set_statusword(&mut self, sw: Statusword) {
        self.sw = sw;
    }
    fn modes_of_operation(&self) -> Option<ModeOfOperation> {
        self.mode
    }
    fn set_modes_of_operation_display(&mut self, mode: ModeOfOperation) {
        self.display = Some(mode);
    }
    fn target_position(&self) -> Option<i32> {
        Some(self.target)
    }
    fn target_velocity(&self) -> Option<i32> {
        Some(self.target_velocity)
    }
    fn profile_velocity(&self) -> Option<u32> {
        Some(self.profile_velocity)
    }
    fn set_position_actual_value(&mut self, position: i32) {
        self.position = position;
    }
    fn set_velocity_actual_value(&mut self, velocity: i32) {
        self.velocity = velocity;
    }
    fn homing_method(&self) -> Option<i8> {
        Some(self.homing_method)
    }
    fn homing_speed(&self) -> Option<u32> {
        Some(self.homing_speed)
    }
    fn home_offset(&self) -> Option<i32> {
        Some(self.home_offset)
    }
    fn target_torque(&self) -> Option<i16> {
        Some(self.target_torque)
    }
    fn set_torque_actual_value(&mut self, torque: i16) {
        self.torque = torque;
    }
}

// The commands, CiA 402-2 table "device control commands" (bits 7, 3, 2, 1, 0).
const SHUTDOWN: u16 = 0b0_0110;
const SWITCH_ON: u16 = 0b0_0111;
const DISABLE_VOLTAGE: u16 = 0b0_0000;
const QUICK_STOP: u16 = 0b0_0010;
const DISABLE_OPERATION: u16 = 0b0_0111;
const ENABLE_OPERATION: u16 = 0b0_1111;
const FAULT_RESET: u16 = 0b1000_0000;

// The state coding, CiA 402-2 table "statusword state coding", under mask 0x6F (bit 5 of
// "fault" and "fault reaction active" is "x" in the standard; these are masked with 0x4F).
const NOT_READY: u16 = 0x00;
const SWITCH_ON_DISABLED: u16 = 0x40;
const READY_TO_SWITCH_ON: u16 = 0x21;
const SWITCHED_ON: u16 = 0x23;
const OPERATION_ENABLED: u16 = 0x27;
const QUICK_STOP_ACTIVE: u16 = 0x07;
const FAULT_REACTION_ACTIVE: u16 = 0x0F;
const FAULT: u16 = 0x08;

fn coded(sw: Statusword, expected: u16) -> bool {
    let mask = if matches!(expected, FAULT | FAULT_REACTION_ACTIVE) { 0x4F } else { 0x6F };
    sw.bits() & mask == expected
}

/// A started drive and its objects, after the controlwords of `path`.
fn after(path: &[u16], quick_stop_option: i16) -> (Drive, Objects) {
    let mut od = Objects::default();
    let control = DeviceControl::new().with_quick_stop_option(quick_stop_option);
    let mut drive = Drive::new().with_control(control);
    assert!(coded(od.sw, NOT_READY));
    drive.start(&mut od);
    for &cw in path {
        od.cw = Controlword(cw);
        drive.update(&mut od);
    }
    (drive, od)
}

#[test]
fn transition_table_of_cia402() {
    // (path to the start state, command, transition number, statusword state coding after).
    let rows: &[(&[u16], u16, u8, u16)] = &[
        (&[], SHUTDOWN, 2, READY_TO_SWITCH_ON),
        (&[SHUTDOWN], SWITCH_ON, 3, SWITCHED_ON),
        (&[SHUTDOWN, SWITCH_ON], ENABLE_OPERATION, 4, OPERATION_ENABLED),
        (&[SHUTDOWN, SWITCH_ON, ENABLE_OPERATION], DISABLE_OPERATION, 5, SWITCHED_ON),
        (&[SHUTDOWN, SWITCH_ON], SHUTDOWN, 6, READY_TO_SWITCH_ON),
        (&[SHUTDOWN], DISABLE_VOLTAGE, 7, SWITCH_ON_DISABLED),
        (&[SHUTDOWN], QUICK_STOP, 7, SWITCH_ON_DISABLED),
        (&[SHUTDOWN, SWITCH_ON, ENABLE_OPERATION], SHUTDOWN, 8, READY_TO_SWITCH_ON),
        (&[SHUTDOWN, SWITCH_ON, ENABLE_OPERATION], DISABLE_VOLTAGE, 9, SWITCH_ON_DISABLED),
        (&[SHUTDOWN, SWITCH_ON], DISABLE_VOLTAGE, 10, SWITCH_ON_DISABLED),
        (&[SHUTDOWN, SWITCH_ON], QUICK_STOP, 10, SWITCH_ON_DISABLED),
        (&[SHUTDOWN, SWITCH_ON, ENABLE_OPERATION], QUICK_STOP, 11, QUICK_STOP_ACTIVE),
        (
            &[SHUTDOWN, SWITCH_ON, ENABLE_OPERATION, QUICK_STOP],
            DISABLE_VOLTAGE,
            12,
            SWITCH_ON_DISABLED,
        ),
    ];
    for (i, &(path, cw, number, coding)) in rows.iter().enumerate() {
        let (mut drive, mut od) = after(path, 2);
        od.cw = Controlword(cw);
        assert_eq!(drive.update(&mut od), Some(number), "row {i}: {path:?} then {cw:#06x}");
        assert!(coded(od.sw, coding), "row {i}: statusword {:#06x}, want {coding:#04x}", od.sw.0);
        assert_eq!(od.sw.state(), Some(drive.control().state()), "row {i}");
    }
}

#[test]
fn commands_without_a_transition_change_nothing() {
    // Switch on in "switch on disabled", enable operation there, quick stop in "switch on
    // disabled": no transition (the table has none).
    for cw in [SWITCH_ON, ENABLE_OPERATION, QUICK_STOP, DISABLE_VOLTAGE] {
        let (mut drive, mut od) = after(&[], 2);
        od.cw = Controlword(cw);
        assert_eq!(drive.update(&mut od), None, "{cw:#06x}");
        assert!(coded(od.sw, SWITCH_ON_DISABLED));
    }
    // A repeated controlword takes no second transition.
    let (mut drive, mut od) = after(&[SHUTDOWN], 2);
    assert_eq!(drive.update(&mut od), None);
    assert!(coded(od.sw, READY_TO_SWITCH_ON));
}

#[test]
fn quick_stop_ends_by_its_option_code() {
    let enabled = [SHUTDOWN, SWITCH_ON, ENABLE_OPERATION, QUICK_STOP];
    // Option code 2 (the default of 0x605A): stop on the ramp, then "switch on disabled"
    // (transition 12) without a command.
    let (mut drive, mut od) = after(&enabled, 2);
    assert!(coded(od.sw, QUICK_STOP_ACTIVE));
    assert_eq!(drive.step(&mut od, Duration::from_millis(10)), Some(12));
    assert!(coded(od.sw, SWITCH_ON_DISABLED));
    // Option code 6: stay in "quick stop active"; enable operation goes back (16).
    let (mut drive, mut od) = after(&enabled, 6);
    assert_eq!(drive.step(&mut od, Duration::from_millis(10)), None);
    assert!(coded(od.sw, QUICK_STOP_ACTIVE));
    od.cw = Controlword(ENABLE_OPERATION);
    assert_eq!(drive.update(&mut od), Some(16));
    assert!(coded(od.sw, OPERATION_ENABLED));
    // Transition 16 does not exist for option code 2.
    let (mut drive, mut od) = after(&enabled, 2);
    od.cw = Controlword(ENABLE_OPERATION);
    assert_eq!(drive.update(&mut od), None);
    assert!(coded(od.sw, QUICK_STOP_ACTIVE));
}

#[test]
fn fault_reaction_fault_and_reset() {
    let (mut drive, mut od) = after(&[SHUTDOWN, SWITCH_ON, ENABLE_OPERATION], 2);
    assert_eq!(drive.fault(&mut od), Some(13));
    assert!(coded(od.sw, FAULT_REACTION_ACTIVE));
    assert!(od.sw.fault());
    assert_eq!(drive.step(&mut od, Duration::from_millis(1)), Some(14));
    assert!(coded(od.sw, FAULT));
    // Commands do nothing in "fault"; fault reset acts on the rising edge of bit 7 (15).
    od.cw = Controlword(ENABLE_OPERATION);
    assert_eq!(drive.update(&mut od), None);
    od.cw = Controlword(FAULT_RESET);
    assert_eq!(drive.update(&mut od), Some(15));
    assert!(coded(od.sw, SWITCH_ON_DISABLED));
    // A fault from "fault" again is no transition; bit 7 held high resets nothing twice.
    assert_eq!(drive.fault(&mut od), Some(13));
    assert_eq!(drive.step(&mut od, Duration::from_millis(1)), Some(14));
    assert_eq!(drive.fault(&mut od), None);
    assert_eq!(drive.update(&mut od), None, "bit 7 still set: no edge");
    od.cw = Controlword(0);
    drive.update(&mut od);
    od.cw = Controlword(FAULT_RESET);
    assert_eq!(drive.update(&mut od), Some(15));
}

#[test]
fn a_lost_connection_does_what_the_abort_connection_option_code_says() {
    let enabled = [SHUTDOWN, SWITCH_ON, ENABLE_OPERATION];
    // 0 and manufacturer-specific codes: no action here.
    for code in [0, -1] {
        let (mut drive, mut od) = after(&enabled, 2);
        assert_eq!(drive.connection_lost(&mut od, code), None, "code {code}");
        assert!(coded(od.sw, OPERATION_ENABLED));
    }
    // 1: fault (13, then 14).
    let (mut drive, mut od) = after(&enabled, 2);
    assert_eq!(drive.connection_lost(&mut od, 1), Some(13));
    assert!(coded(od.sw, FAULT_REACTION_ACTIVE));
    // 2: disable voltage (9); the stale "enable operation" in the controlword is held.
    let (mut drive, mut od) = after(&enabled, 2);
    assert_eq!(drive.connection_lost(&mut od, 2), Some(9));
    assert!(coded(od.sw, SWITCH_ON_DISABLED));
    assert_eq!(drive.update(&mut od), None);
    // A new command from the master acts again.
    od.cw = Controlword(SHUTDOWN);
    assert_eq!(drive.update(&mut od), Some(2));
    // 3: quick stop (11), ending by the quick stop option code (2: transition 12).
    let (mut drive, mut od) = after(&enabled, 2);
    assert_eq!(drive.connection_lost(&mut od, 3), Some(11));
    assert!(coded(od.sw, QUICK_STOP_ACTIVE));
    assert_eq!(drive.step(&mut od, Duration::from_millis(10)), Some(12));
    // With option code 6 the drive stays in "quick stop active", and the held "enable
    // operation" does not take transition 16; the master's next command does.
    let (mut drive, mut od) = after(&enabled, 6);
    assert_eq!(drive.connection_lost(&mut od, 3), Some(11));
    assert_eq!(drive.step(&mut od, Duration::from_millis(10)), None);
    assert_eq!(drive.update(&mut od), None);
    assert!(coded(od.sw, QUICK_STOP_ACTIVE));
    od.cw = Controlword(DISABLE_OPERATION);
    assert_eq!(drive.update(&mut od), None);
    od.cw = Controlword(ENABLE_OPERATION);
    assert_eq!(drive.update(&mut od), Some(16));
}

#[test]
fn statusword_values_of_a_controlword_sequence() {
    // Whole statuswords: state coding, voltage enabled (bit 4) with the power stage on,
    // remote (bit 9), target reached (bit 10) with no mode running.
    let (mut drive, mut od) = after(&[], 2);
    let mut seen = [od.sw.0; 6];
    for (i, cw) in
        [SHUTDOWN, SWITCH_ON, ENABLE_OPERATION, QUICK_STOP, DISABLE_VOLTAGE].into_iter().enumerate()
    {
        od.cw = Controlword(cw);
        drive.update(&mut od);
        seen[i + 1] = od.sw.0;
    }
    assert_eq!(seen, [0x0640, 0x0631, 0x0633, 0x0637, 0x0617, 0x0640]);
}

#[test]
fn profile_position_moves_to_the_target() {
    let (mut drive, mut od) = after(&[], 2);
    od.mode = Some(ModeOfOperation::ProfilePosition);
    od.profile_velocity = 2000;
    for cw in [SHUTDOWN, SWITCH_ON, ENABLE_OPERATION] {
        od.cw = Controlword(cw);
        drive.update(&mut od);
    }
    assert_eq!(od.display, Some(ModeOfOperation::ProfilePosition));
    od.target = -500;
    od.cw = Controlword(ENABLE_OPERATION).with_new_setpoint(true);
    drive.update(&mut od);
    assert!(od.sw.setpoint_ack() && !od.sw.target_reached());
    drive.step(&mut od, Duration::from_millis(100));
    assert_eq!((od.position, od.velocity), (-200, -2000));
    drive.step(&mut od, Duration::from_millis(1000));
    assert_eq!((od.position, od.velocity), (-500, 0));
    assert!(od.sw.target_reached());
    // Relative (bit 6): 100 more from here.
    od.cw = Controlword(ENABLE_OPERATION);
    drive.update(&mut od);
    assert!(!od.sw.setpoint_ack());
    od.target = 100;
    od.cw = Controlword(ENABLE_OPERATION).with_new_setpoint(true).with_relative(true);
    drive.update(&mut od);
    drive.step(&mut od, Duration::from_millis(1000));
    assert_eq!(od.position, -400);
    // No motion outside "operation enabled".
    od.cw = Controlword(ENABLE_OPERATION);
    drive.update(&mut od);
    od.target = 0;
    od.cw = Controlword(SWITCH_ON).with_new_setpoint(true);
    drive.update(&mut od);
    drive.step(&mut od, Duration::from_millis(1000));
    assert_eq!(od.position, -400);
}

#[test]
fn profile_velocity_follows_the_target_velocity() {
    let (mut drive, mut od) = after(&[SHUTDOWN, SWITCH_ON, ENABLE_OPERATION], 2);
    od.mode = Some(ModeOfOperation::ProfileVelocity);
    od.target_velocity = 300;
    drive.update(&mut od);
    assert!(!od.sw.setpoint_ack(), "bit 12 in pv: speed is not zero");
    drive.step(&mut od, Duration::from_millis(500));
    assert_eq!((od.position, od.velocity), (150, 300));
    // Halt (bit 8) stops it; speed zero (bit 12) set.
    od.cw = Controlword(ENABLE_OPERATION).with_halt(true);
    drive.update(&mut od);
    drive.step(&mut od, Duration::from_millis(500));
    assert_eq!((od.position, od.velocity), (150, 0));
    assert!(od.sw.setpoint_ack());
}

/// A drive in "operation enabled" in `mode`.
fn enabled_in(mode: ModeOfOperation) -> (Drive, Objects) {
    let mut od = Objects { mode: Some(mode), ..Objects::default() };
    let mut drive = Drive::new();
    drive.start(&mut od);
    for cw in [SHUTDOWN, SWITCH_ON, ENABLE_OPERATION] {
        od.cw = Controlword(cw);
        drive.update(&mut od);
    }
    assert_eq!(od.sw.state(), Some(State::OperationEnabled));
    (drive, od)
}

const START_HOMING: u16 = ENABLE_OPERATION | 1 << 4;

/// CiA 402-2 homing mode, methods 35 and 37 ("homing on current position"): controlword bit
/// 4 starts it, the current position becomes the home position, whose position actual value
/// is the home offset (0x607C); statusword bits 12 (homing attained) and 10 (target reached).
#[test]
fn homing_on_the_current_position() {
    for method in [35, 37] {
        let (mut drive, mut od) = enabled_in(ModeOfOperation::Homing);
        od.homing_method = method;
        od.home_offset = 500;
        assert!(!od.sw.homing_attained());
        od.cw = Controlword(START_HOMING);
        drive.update(&mut od);
        assert_eq!(od.position, 500, "method {method}");
        assert!(od.sw.homing_attained() && od.sw.target_reached() && !od.sw.homing_error());
        drive.step(&mut od, Duration::from_millis(100));
        assert_eq!((od.position, od.velocity), (500, 0));
    }
}

/// CiA 402-2 homing mode, method 19 (positive home switch, no index pulse): the home switch
/// is inactive at power-on (below `HOME_SWITCH`), so the axis moves in the positive
/// direction at the search speed (0x6099:01) until it becomes active; that edge is the home
/// position. Until then bits 10 and 12 are clear.
#[test]
fn homing_on_the_home_switch() {
    let (mut drive, mut od) = enabled_in(ModeOfOperation::Homing);
    od.homing_method = 19;
    od.homing_speed = 500; // units per second
    od.home_offset = -20;
    od.cw = Controlword(START_HOMING);
    drive.update(&mut od);
    drive.step(&mut od, Duration::from_millis(1000));
    assert_eq!((od.position, od.velocity), (500, 500));
    assert!(!od.sw.homing_attained() && !od.sw.target_reached());
    // Bit 4 cleared: interrupted, the axis stands.
    od.cw = Controlword(ENABLE_OPERATION);
    drive.update(&mut od);
    drive.step(&mut od, Duration::from_millis(500));
    assert_eq!((od.position, od.velocity), (500, 0));
    assert!(!od.sw.homing_attained() && od.sw.target_reached());
    // Started again: 500 units more to the switch at mechanical position 1000.
    assert_eq!(HOME_SWITCH, 1000);
    od.cw = Controlword(START_HOMING);
    drive.update(&mut od);
    drive.step(&mut od, Duration::from_millis(600));
    assert_eq!((od.position, od.velocity), (800, 500));
    drive.step(&mut od, Duration::from_millis(500));
    assert_eq!(od.position, -20, "the home position reads as the home offset");
    assert!(od.sw.homing_attained() && od.sw.target_reached());
}

/// A method the simulated axis cannot perform (1: negative limit switch and index pulse)
/// ends in statusword bit 13, homing error; so does method 19 without a speed.
#[test]
fn homing_error_for_what_the_axis_cannot_do() {
    for (method, speed) in [(1, 100), (19, 0)] {
        let (mut drive, mut od) = enabled_in(ModeOfOperation::Homing);
        od.homing_method = method;
        od.homing_speed = speed;
        od.cw = Controlword(START_HOMING);
        drive.update(&mut od);
        assert!(od.sw.homing_error() && !od.sw.homing_attained(), "method {method}");
    }
}

/// CiA 402-2 cyclic synchronous velocity and torque modes: the drive follows the target of
/// each cycle (0x60FF, 0x6071) and says so in statusword bit 12; CSV integrates it.
#[test]
fn cyclic_synchronous_modes_follow_their_targets() {
    let (mut drive, mut od) = enabled_in(ModeOfOperation::CyclicSyncVelocity);
    od.target_velocity = -300;
    drive.update(&mut od);
    drive.step(&mut od, Duration::from_millis(1000));
    assert_eq!((od.position, od.velocity), (-300, -300));
    assert!(od.sw.setpoint_ack(), "bit 12: following the command value");
    let (mut drive, mut od) = enabled_in(ModeOfOperation::CyclicSyncTorque);
    od.target_torque = 250;
    drive.update(&mut od);
    assert_eq!(od.torque, 250);
    od.target_torque = -40;
    drive.step(&mut od, Duration::from_millis(1));
    assert_eq!((od.torque, od.position), (-40, 0));
    od.cw = Controlword(DISABLE_OPERATION);
    drive.update(&mut od);
    assert_eq!(od.torque, 0, "no torque out of operation enabled");
    let (mut drive, mut od) = enabled_in(ModeOfOperation::CyclicSyncPosition);
    od.target = 1234;
    drive.update(&mut od);
    drive.step(&mut od, Duration::from_millis(1));
    assert_eq!(od.position, 1234);
}
